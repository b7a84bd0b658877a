// SPDX-License-Identifier: AGPL-3.0-or-later
// One tetrahedral mesh of several labels in which touching labels share
// their interface faces: the labels' smooth interface surface (a multi-label
// surface net, label_interfaces.h), freed of crossings, is meshed by TetGen in
// one run, improved without moving any interface, and checked for conformity.
#pragma once

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "core/conforming/check_conforming_mesh.h"
#include "core/conforming/coarsen_labels.h"
#include "core/conforming/label_interfaces.h"
#include "core/conforming/slide_interface_points.h"
#include "core/conforming/tetrahedralize_interfaces.h"
#include "core/conforming/thick_slices.h"
#include "core/util/run_context.h"
#include "core/volume/label_volume.h"
#include "core/volume_mesh/improve_tet_mesh.h"
#include "core/volume_mesh/tet_mesh.h"
#include "core/volume_mesh/tetrahedralize.h"

namespace labelmesh::conforming {

struct ConformingParams {
  // Voxel faces between labels above which the grid is coarsened
  // (coarsen_labels.h); 0 keeps every grid.
  uint64_t max_interface_faces = kDefaultMaxInterfaceFaces;
  ThickSliceParams thick_slices;
  InterfaceParams interfaces;
  volume_mesh::TetgenParams tetgen;
  volume_mesh::ImproveParams improve;
  // Interface points slide before and after the improvement pass, each no
  // farther from the staircase than it was or than this fraction of the
  // smallest spacing.
  SlideParams slide;
  double slide_reach_voxels = 0.45;
  // The last slide's steps off the interfaces (SlideParams::off_fraction).
  double last_slide_off_fraction = 0.5;
  // Rounds of putting the points of crossing triangles back on the
  // staircase (which never crosses itself) before all of them go back.
  int max_crossing_repairs = 4;
};

// One label's figures: its voxels against its tetrahedra.
struct LabelVolumeFigures {
  int32_t label = 0;
  uint64_t voxels = 0;
  double voxel_volume_mm3 = 0;
  double mesh_volume_mm3 = 0;
  size_t tetrahedra = 0;
  // (mesh - voxels) / voxels.
  double volume_change() const;
};

struct ConformingFigures {
  // The thick axis cut before the interfaces were made, if any; the
  // interfaces' figures are then on the thinner grid.
  // The grid the interfaces were made on: the input's, coarsened when its
  // interfaces were too large, and thick slices cut thinner. The
  // interfaces' figures are on that grid.
  Coarsening coarsening;
  ThickSlices thick_slices;
  double grid_seconds = 0;
  InterfaceFigures interfaces;
  // Repair rounds run and the points put back on the staircase; whether
  // every point had to go back.
  int crossing_repairs = 0;
  size_t restored_points = 0;
  bool staircase_only = false;
  volume_mesh::TetgenFigures tetgen;
  // TetGen's mesh before the slides and the improvement pass.
  quality::QualitySummary tetgen_quality;
  LabelledRegions regions;
  // Both slides together: points moved, tetrahedra below the slide's targets
  // before the first and after the last.
  SlideFigures slide;
  ConformityCheck conformity;
  // Every selected label present in the volume, in label order.
  std::vector<LabelVolumeFigures> labels;
  double seconds = 0;
};

// Meshes `labels` of `volume` (every non-zero label when empty) as one
// conforming mesh, then slides interface points, runs the improvement pass
// when params.improve.target_quality > 0 (`improve` gets its figures; it
// works on tetrahedra below the slides' dihedral target too), and slides
// them again.
// Errors: INVALID_ARGUMENT for parameters out of range or no voxel of any
// selected label; FAILED_PRECONDITION when TetGen refuses the surface or the
// result fails the conformity check (never delivered); RESOURCE_EXHAUSTED;
// CANCELLED; INTERNAL.
absl::StatusOr<volume_mesh::TetMesh> mesh_conforming(const volume::LabelVolume& volume,
                                                     const std::vector<int32_t>& labels,
                                                     const ConformingParams& params,
                                                     const RunContext& context,
                                                     ConformingFigures& figures,
                                                     volume_mesh::ImproveFigures& improve);

// How far labels' volumes are from their voxels': over labels of at least
// `min_voxels` voxels, the median, 90th percentile and largest |volume
// change|, and how many labels that is (all zero when none).
struct VolumeChangeSpread {
  double median = 0;
  double p90 = 0;
  double max = 0;
  size_t labels = 0;
};
VolumeChangeSpread volume_change_spread(const std::vector<LabelVolumeFigures>& labels,
                                        uint64_t min_voxels);

// The figures of each label of `mesh` against its voxel counts.
std::vector<LabelVolumeFigures> label_volume_figures(
    const volume_mesh::TetMesh& mesh, const std::vector<std::pair<int32_t, uint64_t>>& voxels,
    double voxel_volume_mm3);

}  // namespace labelmesh::conforming
