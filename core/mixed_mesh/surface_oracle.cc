// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/mixed_mesh/surface_oracle.h"

#include <cmath>
#include <thread>

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Side_of_triangle_mesh.h>

#include "core/surface/cgal/cgal_mesh.h"

namespace labelmesh::mixed_mesh {

namespace cgal = surface::cgal;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<cgal::Mesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<cgal::Kernel, Primitive>>;
using Side = CGAL::Side_of_triangle_mesh<cgal::Mesh, cgal::Kernel, CGAL::Default, Tree>;

struct SurfaceOracle::Impl {
  cgal::Mesh mesh;
  Tree tree;
  std::unique_ptr<Side> side;
};

absl::StatusOr<SurfaceOracle> SurfaceOracle::build(const surface::TriangleMesh& surface) {
  auto mesh = cgal::to_surface_mesh(surface);
  if (!mesh || !CGAL::is_closed(*mesh)) {
    return absl::InvalidArgumentError("the surface is not a closed, oriented manifold");
  }
  auto impl = std::make_shared<Impl>();
  impl->mesh = std::move(*mesh);
  impl->tree.insert(faces(impl->mesh).first, faces(impl->mesh).second, impl->mesh);
  impl->tree.build();
  impl->tree.accelerate_distance_queries();
  impl->side = std::make_unique<Side>(impl->tree);
  SurfaceOracle oracle;
  oracle.impl_ = std::move(impl);
  return oracle;
}

double SurfaceOracle::depth(const std::array<double, 3>& point) const {
  const cgal::Point p(point[0], point[1], point[2]);
  const double distance = std::sqrt(CGAL::to_double(impl_->tree.squared_distance(p)));
  const CGAL::Bounded_side side = (*impl_->side)(p);
  return side == CGAL::ON_BOUNDED_SIDE ? distance : -distance;
}

std::array<double, 3> SurfaceOracle::closest(const std::array<double, 3>& point) const {
  const cgal::Point p = impl_->tree.closest_point(cgal::Point(point[0], point[1], point[2]));
  return {CGAL::to_double(p.x()), CGAL::to_double(p.y()), CGAL::to_double(p.z())};
}

std::optional<std::array<double, 3>> SurfaceOracle::first_hit(
    const std::array<double, 3>& from, const std::array<double, 3>& direction) const {
  if (direction[0] == 0 && direction[1] == 0 && direction[2] == 0) return std::nullopt;
  const cgal::Kernel::Ray_3 ray(cgal::Point(from[0], from[1], from[2]),
                                cgal::Kernel::Vector_3(direction[0], direction[1], direction[2]));
  const auto hit = impl_->tree.first_intersection(ray);
  if (!hit) return std::nullopt;
  // A ray grazing a triangle meets it in a segment: its nearer end counts.
  cgal::Point point;
  if (const auto* segment = boost::get<cgal::Kernel::Segment_3>(&hit->first)) {
    const bool source_nearer = CGAL::squared_distance(segment->source(), ray.source()) <=
                               CGAL::squared_distance(segment->target(), ray.source());
    point = source_nearer ? segment->source() : segment->target();
  } else if (const auto* single = boost::get<cgal::Point>(&hit->first)) {
    point = *single;
  } else {
    return std::nullopt;
  }
  return std::array<double, 3>{CGAL::to_double(point.x()), CGAL::to_double(point.y()),
                               CGAL::to_double(point.z())};
}

std::vector<double> SurfaceOracle::depths(const std::vector<std::array<double, 3>>& points,
                                          unsigned threads) const {
  std::vector<double> result(points.size());
  threads = std::max(1u, threads);
  std::vector<std::thread> workers;
  for (unsigned t = 0; t < threads; ++t) {
    workers.emplace_back([&, t] {
      for (size_t i = t; i < points.size(); i += threads) result[i] = depth(points[i]);
    });
  }
  for (auto& worker : workers) worker.join();
  return result;
}

}  // namespace labelmesh::mixed_mesh
