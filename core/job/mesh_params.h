// SPDX-License-Identifier: AGPL-3.0-or-later
// What a caller asks of one meshing run: user intent only, with defaults.
// Values derived from the input (tolerances from voxel size) never live here.
#pragma once

#include <cstdint>
#include <vector>

#include "core/header/label_description.h"
#include "core/header/volume_header.h"
#include "core/job/interface_budget.h"
#include "core/job/poisson_params.h"
#include "core/job/scene_format.h"
#include "core/job/surface_format.h"
#include "core/job/tetgen_params.h"
#include "core/job/volume_format.h"
#include "core/util/coordinate_frame.h"

namespace labelmesh {

enum class SurfaceMethod {
  kMarchingCubes,  // VTK discrete flying edges; staircase surface (paper §2.2).
  kRepaired,       // Marching Cubes repaired with CGAL ("MC improved", Table 2).
  kPoisson,        // Repaired MC per component, then CGAL Poisson (paper §2.3).
  // The labels' shared surface net, smoothed within each voxel cube, judged
  // against the voxels; Poisson for thick labels that touch no other.
  kNet,
};

// The shared surface net (SurfaceMethod::kNet): Taubin rounds of a shrinking
// and an inflating step, each step holding every point within cube_fraction
// of half a voxel of its staircase position along each axis (Frisken's
// constrained smoothing). The pass band, 1 / shrink + 1 / inflate, sets the
// longest ripple removed: the terraces of thick slices are many voxels long.
struct NetOptions {
  int smoothing_rounds = 150;
  double shrink_step = 0.5;
  double inflate_step = -0.505;
  // How far a point may leave its staircase position along each axis, as a
  // fraction of half the voxel: below 1, so on the volume's own grid no
  // voxel centre changes sides (on thinner slices the guard measures it).
  double cube_fraction = 0.95;
  // Give each label back the volume smoothing took from it (thin labels
  // shrink most), from the outside or through its neighbours.
  bool restore_volumes = true;
  // With restore_volumes, the smoothing pauses this many times (0 to 10),
  // evenly spaced, for one round of giving volume back: a label three
  // voxels across then keeps its round cross-section instead of shrinking
  // against the voxels' corners.
  int volume_pauses = 2;
  // An axis whose spacing is at least thick_ratio times the others' is cut
  // into slices about thin_ratio times theirs by shape-based interpolation
  // before the net is made: the net then slopes between the slices instead
  // of stepping a whole slice at once. 0 turns it off.
  double thick_ratio = 2.5;
  double thin_ratio = 1;
  // Between two drawn slices a point of the thinner grid may move across
  // the cut axis up to this fraction of a voxel beyond its box, more the
  // farther it lies from the nearest drawn slice: the interpolated slices'
  // pixel steps would otherwise stay as ridges. At most 0.5.
  double between_drawn_widening = 0.5;
  // A net on thinner slices is smoothed this many times smoothing_rounds:
  // its terraces are a thick slice long, several thin voxels, and the
  // smoothing's reach grows only as the square root of its rounds (the
  // sphere on 1 x 1 x 3 mm slices: normals' 95th percentile 7.9 degrees at
  // 150 rounds, 5.7 at 600).
  int thin_grid_rounds_factor = 4;
  // At most this many voxels on the thinner grid (fewer parts otherwise).
  int64_t max_thin_voxels = 48'000'000;
  // Poisson is tried first on labels touching no other selected label, at
  // least PoissonOptions::min_thickness_voxels thick, on grids whose largest
  // spacing is at most this many times the smallest.
  double poisson_max_anisotropy = 1.5;
};

// Poisson surface settings. Lengths are in voxels (multiples of the cube root
// of the voxel volume), so the same defaults work at any resolution.
// Surface sizing for one label, mm, overriding the defaults (0: keep them).
struct LabelSizing {
  int32_t label = 0;
  double max_edge_mm = 0;
  double max_distance_mm = 0;
};

struct PoissonOptions {
  double min_angle_deg = 30;
  // Longest edge and surface distance, voxels (docs/benchmarks.md has what
  // they give on the liver); halving both follows curvature twice as closely
  // and takes several times as long.
  double max_edge_voxels = 8;
  double max_distance_voxels = 0.5;
  // The same in mm; when set (> 0) they replace the voxel figures.
  double max_edge_mm = 0;
  double max_distance_mm = 0;
  // Each component's sizing shrinks to its thickness (3 x volume / area),
  // so a rib or vessel gets edges as short as it is thin while a large organ
  // keeps the defaults.
  bool adapt_to_thickness = true;
  // Poisson is tried first only on labels at least this thick (3 x volume /
  // area of the repaired surface, in voxels); thinner ones go straight to the
  // guard's meshed voxel mask. Across the shared multi-label volumes the
  // first Poisson surface was within tolerance for 7 of 157 labels thinner
  // than 15 voxels and 4 of 11 thicker ones, and it is most of their time.
  // 0 tries Poisson on every label; without fall-back it always is.
  double min_thickness_voxels = 15;
  // Per-label sizing; it also overrides the adaptation.
  std::vector<LabelSizing> label_sizing;
  // Islands smaller than 4^3 voxels are segmentation noise in practice, and too
  // small for Poisson to reconstruct as anything but a blob.
  uint64_t min_component_voxels = 64;
  // Strands one voxel thick are below what a smooth surface can follow at the
  // voxel size: Poisson would shrink them to nothing, far from the voxels.
  bool prune_strands = true;
  // Windowed-sinc smoothing of the repaired surface before its points and
  // normals go to Poisson: the staircase is voxel-scale noise, and Poisson
  // fed with it reproduces part of it (sphere: 0.14 voxel RMS without, see
  // docs/pipeline.md). Positions only; the repaired surface itself is reported as is.
  surface::SmoothingParams smoothing;
  surface::NormalWeighting normals = surface::NormalWeighting::kUniform;
  // Grid: one point per voxel cube. Marching Cubes gives a little more than
  // that, and coarser cells let the surface drift (2 voxels doubles the
  // sphere's radial error). Hierarchy clusters of 3 are about a fifth faster on
  // the liver at the same Hausdorff distance, but leave the sphere's vertices
  // 0.119 voxel RMS off, above the 0.1 target (docs/pipeline.md, "Point reduction").
  surface::PointReduction point_reduction = surface::PointReduction::kGrid;
  double point_cell_voxels = 1;
  // Point budget of the grid reduction per component: a larger surface gets a
  // coarser cell. The solve's time grows with its points, so this bounds a
  // component's solve whatever the organ's size. The liver (242 k points at 1
  // voxel) stays under it; smaller budgets trade Hausdorff distance for time (docs/pipeline.md,
  // "Point reduction"). 0: no budget.
  uint64_t max_points = 250'000;
  // Components with more points than this are solved as two overlapping
  // halves on two threads: the liver's solve takes about half as long as one
  // solve, for the same volume and mean distance (docs/pipeline.md, "Two halves").
  // Below it one solve is quick anyway. 0: always one solve.
  uint64_t split_points = 150'000;
  uint32_t point_cluster_size = 3;
};

enum class VolumeMethod {
  kNone,
  // TetGen on each label's output surface (paper §2.4.2), one region per label.
  kTetgen,
  // Hexahedra inside each label, pyramids and tetrahedra out to its surface
  // (paper §2.4.3-2.4.4; mixed_mesh/mixed_mesher.h).
  kMixed,
  // Hexahedra only, where they can be valid; other labels are left out and
  // the report says why.
  kHex,
  // One tetrahedral mesh of every label with shared interfaces
  // (conforming/conforming_mesher.h); the label surfaces come from it.
  kConforming,
};

// The guard on what is delivered: each label's output surface is compared
// with its Marching Cubes surface; outside the tolerance it is rebuilt finer,
// then replaced by the label's smoothed voxel mask meshed at one half, and
// what is delivered outside it anyway is listed in the report's warnings.
struct GuardOptions {
  // Largest |volume change|, percent of the Marching Cubes volume, for labels
  // of at least kSmallLabelVoxels voxels, and for smaller ones.
  double volume_percent = 3;
  double small_volume_percent = 10;
  // Largest Hausdorff distance, mm; 0: the largest spacing the segmentation
  // was drawn at (input.drawn_spacing).
  double hausdorff_mm = 0;
  // Rebuild and fall back when outside the tolerance (false: only measure
  // and warn).
  bool fall_back = true;
  // Any label delivered outside the tolerance, or not at all, fails the run.
  bool strict = false;
};

struct MeshParams {
  // Labels to mesh; empty means every non-zero label in the volume.
  std::vector<int32_t> labels;
  // A volume resampled by nearest neighbour from a coarser grid (blocks of
  // equal pixels along two axes or more, volume/drawn_grid.h) is meshed and
  // judged on that grid; false keeps the file's grid.
  bool mesh_on_drawn_grid = true;
  SurfaceMethod surface = SurfaceMethod::kNet;
  NetOptions net;
  PoissonOptions poisson;
  GuardOptions guard;
  // Surface files to write per label.
  std::vector<surface::SurfaceFormat> formats{surface::SurfaceFormat::kStl,
                                              surface::SurfaceFormat::kVtp};
  // Format "dcm": each surface also as a DICOM Encapsulated STL object in
  // the input DICOM SEG's patient, study and frame of reference, in a new
  // series. DICOM SEG inputs only.
  bool dicom_surfaces = false;
  VolumeMethod volume = VolumeMethod::kNone;
  // kMixed: the hexahedra's edge, mm; 0 for three voxels (the cube root of
  // the voxel volume).
  double hex_size_mm = 0;
  // kMixed: the largest octant's edge inside a label, mm; 0 for hex_size_mm
  // throughout (no octree).
  double hex_interior_size_mm = 0;
  // kConforming: voxel faces between labels above which the grid is
  // coarsened; 0 for no bound.
  uint64_t conforming_max_interface_faces = conforming::kDefaultMaxInterfaceFaces;
  volume_mesh::TetgenParams tetgen;
  volume_mesh::ImproveParams improve;
  // Volume mesh files (when `volume` is not kNone).
  std::vector<volume_mesh::VolumeFormat> volume_formats{volume_mesh::VolumeFormat::kVtu};
  // Files of the whole job: the surfaces in one scene, the label volume.
  std::vector<SceneFormat> scene_formats;
  // The frame every mesh file's coordinates are written in (report.json
  // stays LPS and says which frame the files use).
  CoordinateFrame frame = CoordinateFrame::kLps;
  // Labels meshed at once (each label's own stages use up to two threads);
  // 0: one per core. The output does not depend on it.
  unsigned threads = 0;
  // Size limits applied to the input before anything is allocated.
  volume::ReadLimits limits;
  // Label names and colours over those the input gives (--label-names).
  volume::LabelDescriptions label_names;
};

}  // namespace labelmesh
