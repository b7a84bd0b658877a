// SPDX-License-Identifier: AGPL-3.0-or-later
// What a run produces: the input's summary, every label's surfaces with
// their figures, the volume mesh, stage times and warnings.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/dicom/dicom_source.h"
#include "core/header/label_description.h"
#include "core/pipeline/label_mixed_meshes.h"
#include "core/pipeline/label_tet_meshes.h"
#include "core/pipeline/surface_fidelity.h"
#include "core/surface/poisson_surface.h"
#include "core/surface/surface_checks.h"
#include "core/surface/surface_repair.h"
#include "core/surface/surface_statistics.h"
#include "core/surface/triangle_mesh.h"
#include "core/util/stage_timer.h"
#include "core/volume/label_statistics.h"
#include "core/volume/label_volume.h"
#include "core/volume/touching_labels.h"

namespace labelmesh {

// The input as read: format, placement and label counts.
struct VolumeSummary {
  volume::ImageFormat format = volume::ImageFormat::kNifti;
  std::string file_voxel_type;
  volume::ImageGeometry geometry;
  // Where the labels were meshed on the grid they were drawn on
  // (volume/drawn_grid.h), the file's own grid; `geometry` and the label
  // counts are then the drawn grid's.
  std::optional<volume::ImageGeometry> file_geometry;
  volume::VolumeStatistics statistics;
  // Runs of equal planes per voxel axis (find_repeated_planes): 3 along z
  // means the segmentation was drawn on every third slice.
  std::array<int, 3> repeated_planes{1, 1, 1};
  volume::LabelDescriptions descriptions;
  // Images the labels were read into: more than 1 when overlapping segments
  // were kept apart (volume::ReadLimits::separate_overlapping).
  uint32_t layers = 1;
  // The file read, without its folder, and the SHA-256 of its bytes.
  std::string file_name;
  std::string sha256;
  // A DICOM SEG input's patient, study and frame of reference, when DICOM
  // output was asked for.
  std::optional<dicom::DicomSource> dicom;
};

// Which connected pieces of a label a surface covers.
struct ComponentCounts {
  uint32_t kept = 0;
  // Components under the size threshold, left out of the surface.
  uint32_t dropped = 0;
  uint64_t dropped_voxels = 0;
  // Voxels removed as strands one voxel thick before splitting.
  uint64_t pruned_voxels = 0;
  // Cavities (enclosed background pockets) under the size threshold, filled.
  uint32_t filled_cavities = 0;
  uint64_t filled_voxels = 0;
};

// One label's surface after one stage. A run keeps every stage's figures (the
// paper's Table 2 columns) but writes files only for the final stage.
struct SurfaceResult {
  int32_t label = 0;
  // Stage that produced the surface: "marching_cubes", "repaired", or the
  // delivery guard's method (method_name: "net", "poisson", ...).
  std::string stage;
  // True for the stage whose surface is the run's output.
  bool is_output = false;
  surface::TriangleMesh mesh;
  surface::SurfaceStatistics statistics;
  // Only for stages after Marching Cubes.
  std::optional<ComponentCounts> components;
  std::optional<surface::RepairCounts> repair;
  std::optional<surface::PoissonFigures> poisson;
  // Only for the output stage, when it is not Marching Cubes itself.
  std::optional<uint64_t> self_intersections;
  // To the Marching Cubes surface of the kept components.
  std::optional<surface::SurfaceDistance> distance_to_marching_cubes;
  // Output stage of the quality surfaces: what the delivery guard tried and
  // measured, and which attempt was delivered.
  std::optional<SurfaceFidelity> fidelity;
  // Share of the area facing along a voxel axis (surface::axis_aligned_share).
  std::optional<double> axis_aligned_share;
  // Why the label has no surface when its stages failed (the run goes on).
  std::optional<std::string> error;
  // Files written for it, relative to the output directory.
  std::vector<std::string> files;
};

// A label delivered outside its tolerance, or not at all, and why.
struct LabelWarning {
  int32_t label = 0;
  std::string reason;
};

struct MeshResult {
  VolumeSummary input;
  std::vector<SurfaceResult> surfaces;
  // When a volume method was asked for: tetrahedra, or mixed elements.
  std::optional<VolumeResult> volume;
  std::optional<MixedVolumeResult> mixed;
  std::vector<StageTiming> stages;
  // Every label delivered outside its tolerance or not at all.
  std::vector<LabelWarning> warnings;
  // Tetrahedra and mixed meshes: selected labels whose voxels share faces,
  // whose separate meshes therefore overlap along their interface.
  std::vector<volume::TouchingLabels> touching_labels;
  // The label volume as read, kept when a scene format writes it.
  std::shared_ptr<const volume::LabelVolume> label_image;
  // Files of the whole job (SceneFormat), relative to the output directory.
  std::vector<std::string> scene_files;
};

}  // namespace labelmesh
