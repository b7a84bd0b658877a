// SPDX-License-Identifier: AGPL-3.0-or-later
// The queue of cells that CGAL 5.5's Delaunay refinement inside the Poisson
// solve still has to split, ordered by quality and then by arrival.
//
// CGAL keeps this queue in a Double_map (a bimap of cell handle and quality)
// and inserts each cell with a hint found by the handle, that is by the
// cell's address. Cells of equal quality, common on voxel data, then queue in
// an order that depends on where the heap put them, and the same input gave
// one of two surfaces from run to run (nested-spheres phantom, label 2: 136
// or 137 solver iterations). This specialization, for the Poisson
// triangulation's cell handles only, keeps the same interface and breaks ties
// by arrival, so the refinement depends on the input alone.
#pragma once

#include <cstdint>
#include <map>
#include <utility>

#include <CGAL/Double_map.h>
#include <CGAL/Poisson_reconstruction_function.h>

#include "core/surface/poisson/poisson_kernel.h"

// Every file that can instantiate the Poisson function includes this header
// (through hinted_poisson_evaluator.h or poisson_linear_system.h), so that
// all of them see the same queue.
namespace labelmesh::surface::poisson {
using RefinedCell =
    CGAL::Poisson_reconstruction_function<StopAwareKernel>::Triangulation::Cell_handle;
}  // namespace labelmesh::surface::poisson

namespace CGAL {

template <class Quality, class Direct_compare, class Reverse_compare>
class Double_map<labelmesh::surface::poisson::RefinedCell, Quality, Direct_compare,
                 Reverse_compare> {
 public:
  using Key = labelmesh::surface::poisson::RefinedCell;
  using Data = Quality;

 private:
  // Quality first (Reverse_compare, as CGAL orders it), arrival second.
  struct Place {
    Quality quality;
    uint64_t arrival;
  };
  struct Before {
    bool operator()(const Place& a, const Place& b) const {
      if (Reverse_compare()(a.quality, b.quality)) return true;
      if (Reverse_compare()(b.quality, a.quality)) return false;
      return a.arrival < b.arrival;
    }
  };
  using Queue = std::map<Place, Key, Before>;
  // Found by handle only: this map's order is never read.
  using Places = std::map<Key, typename Queue::iterator, Direct_compare>;

 public:
  using size_type = typename Places::size_type;
  using reverse_iterator = typename Queue::iterator;

  bool empty() const { return places_.empty(); }
  size_type size() const { return places_.size(); }
  void clear() {
    queue_.clear();
    places_.clear();
  }

  // False, and nothing changes, when `key` is queued already.
  bool insert(const Key& key, const Data& quality) {
    if (places_.count(key) != 0) return false;
    auto queued = queue_.emplace(Place{quality, next_arrival_++}, key).first;
    places_.emplace(key, queued);
    return true;
  }

  // The first cell to split: `front()->second`.
  reverse_iterator front() { return queue_.begin(); }

  void pop_front() {
    places_.erase(queue_.begin()->second);
    queue_.erase(queue_.begin());
  }

  bool erase(const Key& key) {
    auto place = places_.find(key);
    if (place == places_.end()) return false;
    queue_.erase(place->second);
    places_.erase(place);
    return true;
  }

 private:
  Queue queue_;
  Places places_;
  uint64_t next_arrival_ = 0;
};

}  // namespace CGAL
