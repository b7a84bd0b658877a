// SPDX-License-Identifier: AGPL-3.0-or-later
#include "client/pipeline_options.h"

#include <CLI/CLI.hpp>

#include <cstdio>

#include "core/job/job_options.h"
#include "core/volume/label_table.h"

namespace labelmesh::client {

void add_pipeline_flags(CLI::App& command, PipelineFlags& flags) {
  command
      .add_option("--labels", flags.params.labels,
                  "Labels to mesh, e.g. 1,3 (default: every non-zero label)")
      ->delimiter(',');
  command
      .add_option("--surface", flags.surface,
                  "Surface method: net (the labels' shared surface net smoothed within each "
                  "voxel, judged against the voxels; the default), mc (Marching Cubes), repaired "
                  "(MC repaired with CGAL), poisson (repaired MC, then CGAL Poisson "
                  "reconstruction; the default under --volume tet, mixed or hex)")
      ->check(CLI::IsMember({"net", "mc", "repaired", "poisson"}));
  auto& poisson = flags.params.poisson;
  command
      .add_option("--min-angle", poisson.min_angle_deg,
                  "Poisson: smallest triangle angle, degrees, at most 30")
      ->capture_default_str();
  command
      .add_option("--max-edge", poisson.max_edge_voxels, "Poisson: longest triangle edge, voxels")
      ->capture_default_str();
  command
      .add_option("--max-distance", poisson.max_distance_voxels,
                  "Poisson: surface mesher distance bound, voxels")
      ->capture_default_str();
  command
      .add_option("--min-component-voxels", poisson.min_component_voxels,
                  "Drop connected components of a label with fewer voxels (repaired, poisson)")
      // CLI11 reads "-1" into an unsigned option as its largest value.
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command
      .add_option("--max-edge-mm", poisson.max_edge_mm,
                  "Longest triangle edge, mm; replaces --max-edge when set")
      ->check(CLI::NonNegativeNumber);
  command
      .add_option("--max-distance-mm", poisson.max_distance_mm,
                  "Surface mesher distance bound, mm; replaces --max-distance when set")
      ->check(CLI::NonNegativeNumber);
  command.add_flag("--no-adapt-to-thickness", flags.no_adapt_to_thickness,
                   "Keep the same sizing for thin components (by default each component's edges "
                   "are at most half its thickness, 3 x volume / area)");
  command
      .add_option("--poisson-min-thickness", poisson.min_thickness_voxels,
                  "Try Poisson first only on labels at least this many voxels thick (3 x volume / "
                  "area); thinner ones start with the meshed voxel mask; 0 for every label")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command.add_option("--label-sizing", flags.label_sizing,
                     "Per-label sizing LABEL:EDGE_MM[:DISTANCE_MM], e.g. 114:2:0.2; repeatable");
  command.add_option("--label-names", flags.label_names,
                     "Label names and colours: an ITK-SNAP label file, a FreeSurfer colour table "
                     "or a JSON map {\"5\": \"liver\"}; they name the surface files and the "
                     "report's labels");
  auto& guard = flags.params.guard;
  command
      .add_option("--volume-tolerance", guard.volume_percent,
                  "Delivery guard: largest volume change against Marching Cubes, percent")
      ->capture_default_str();
  command
      .add_option("--small-volume-tolerance", guard.small_volume_percent,
                  "Delivery guard: the same for labels under 1,000 voxels, percent")
      ->capture_default_str();
  command
      .add_option("--hausdorff-tolerance", guard.hausdorff_mm,
                  "Delivery guard: largest Hausdorff distance to Marching Cubes, mm (0: the "
                  "largest spacing the segmentation was drawn at)")
      ->capture_default_str();
  command.add_flag("--no-fall-back", flags.no_fall_back,
                   "Delivery guard: only measure and warn; never rebuild a surface outside "
                   "tolerance");
  command.add_flag("--file-grid", flags.file_grid,
                   "Mesh on the file's own grid even where its labels were resampled by nearest "
                   "neighbour from a coarser one (by default they are meshed and judged on the "
                   "coarser grid they were drawn on)");
  command.add_flag("--strict", guard.strict,
                   "Fail (exit 4) when any label is delivered outside tolerance, not at all, "
                   "or into another label's surface");
  command.add_flag("--keep-strands", flags.keep_strands,
                   "Keep strands one voxel thick (repaired, poisson); by default they are pruned");
  command
      .add_option("--smoothing-iterations", poisson.smoothing.iterations,
                  "Poisson: windowed-sinc smoothing of the repaired surface before "
                  "reconstruction, filter iterations (0: off)")
      ->capture_default_str();
  command
      .add_option("--smoothing-pass-band", poisson.smoothing.pass_band,
                  "Poisson: smoothing pass band in (0, 2); lower smooths more")
      ->capture_default_str();
  command
      .add_option("--normals", flags.normals,
                  "Poisson: vertex normals from incident triangles, uniform or area weighted")
      ->check(CLI::IsMember({"uniform", "area"}))
      ->capture_default_str();
  command
      .add_option("--point-reduction", flags.point_reduction,
                  "Poisson: thin the oriented points by a grid, hierarchy clusters, or none")
      ->check(CLI::IsMember({"grid", "hierarchy", "none"}))
      ->capture_default_str();
  command
      .add_option("--point-cell", poisson.point_cell_voxels,
                  "Poisson: grid cell of the grid point reduction, voxels")
      ->capture_default_str();
  command
      .add_option("--max-points", poisson.max_points,
                  "Poisson: point budget of the grid reduction per component; a larger surface "
                  "gets a coarser cell (0: no budget)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command
      .add_option("--split-points", poisson.split_points,
                  "Poisson: solve a component with more points than this as two halves on two "
                  "threads (0: always one solve)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command
      .add_option("--point-cluster-size", poisson.point_cluster_size,
                  "Poisson: largest cluster of the hierarchy point reduction, points")
      ->capture_default_str();
  command
      .add_option("--volume", flags.volume,
                  "Volume mesh: none; tet (TetGen on each label's output surface); mixed "
                  "(hexahedra inside each label and out to its surface, with pyramids and "
                  "tetrahedra where hexahedra cannot be valid); or hex (hexahedra only; labels "
                  "where they cannot be valid are left out and reported); or conforming (one "
                  "tetrahedral mesh of all labels, touching labels sharing their interfaces; "
                  "the label surfaces come from it)")
      ->check(CLI::IsMember({"none", "tet", "mixed", "hex", "conforming"}))
      ->capture_default_str();
  command
      .add_option("--hex-size", flags.params.hex_size_mm,
                  "Mixed and hex: the hexahedra's edge, mm; 0 for three voxels")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command
      .add_option("--hex-interior-size", flags.params.hex_interior_size_mm,
                  "Mixed: the largest octant's edge inside each label, mm (an octree: cubes of "
                  "--hex-size under the surface, coarser deeper in); 0 for one size throughout")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command
      .add_option("--conforming-max-faces", flags.params.conforming_max_interface_faces,
                  "Conforming: voxel faces between labels above which blocks of voxels are "
                  "merged (each keeping its most common label) so the mesh fits in about 1 GiB; "
                  "0 for no bound")
      ->capture_default_str();
  auto& tetgen = flags.params.tetgen;
  command
      .add_option("--tet-radius-edge", tetgen.radius_edge_ratio,
                  "Tet: largest circumradius / shortest edge (TetGen -q), at least 1")
      ->capture_default_str();
  command
      .add_option("--tet-min-dihedral", tetgen.min_dihedral_deg,
                  "Tet: smallest dihedral angle TetGen refines for, degrees (at most 30)")
      ->capture_default_str();
  command
      .add_option("--tet-max-volume", tetgen.max_volume_mm3,
                  "Tet: largest tetrahedron volume, mm^3 (TetGen -a); 0 for no bound")
      ->capture_default_str();
  command
      .add_option("--tet-max-dihedral", tetgen.max_dihedral_deg,
                  "Tet: TetGen's own optimisation (-o/) works on tetrahedra with a dihedral angle "
                  "above this, degrees in [90, 179]")
      ->capture_default_str();
  command
      .add_option("--tet-improve-quality", flags.params.improve.target_quality,
                  "Tet: the improvement pass after TetGen (flips, smoothing of interior points) "
                  "works on tetrahedra with quality Q below this; 0 turns it off")
      ->capture_default_str();
  command.add_flag("--tet-split-boundary", flags.tet_split_boundary,
                   "Tet: let TetGen add points on the surface (by default it keeps the surface "
                   "triangles, -Y)");
  command
      .add_option("--formats", flags.formats,
                  "Files to write: surfaces per label (stl, ply, obj, off, vtp; dcm: DICOM "
                  "Encapsulated STL in a DICOM SEG input's study); all surfaces in "
                  "one scene (vtm); the label volume beside the meshes (vti, mha); and, with "
                  "--volume, one volume mesh (vtu, msh, mesh, inp, node, xdmf); default stl,vtp; "
                  "with --volume and no volume format listed, vtu")
      ->delimiter(',')
      ->check(CLI::IsMember({"stl", "ply", "obj", "off", "vtp", "dcm", "vtm", "vti", "mha", "vtu",
                             "msh", "mesh", "inp", "node", "xdmf"}));
  command
      .add_option("--coordinates", flags.coordinates,
                  "Frame of the coordinates in the mesh files: lps (DICOM's patient frame) or "
                  "ras (3D Slicer's world frame: x and y negated)")
      ->check(CLI::IsMember({"lps", "ras"}))
      ->capture_default_str();
  command
      .add_option("--overlapping", flags.overlapping,
                  "Overlapping segments (DICOM SEG, 3D Slicer): refuse the input naming them, or "
                  "separate: mesh each segment on its own")
      ->check(CLI::IsMember({"refuse", "separate"}))
      ->capture_default_str();
  command
      .add_option("--max-voxels", flags.params.limits.max_voxels,
                  "Refuse volumes with more voxels than this")
      ->capture_default_str();
}

absl::StatusOr<v1::MeshOptions> to_mesh_options(const PipelineFlags& flags) {
  MeshParams params = flags.params;
  auto& poisson = params.poisson;
  for (const auto& text : flags.label_sizing) {
    int label = 0;
    double edge = 0, distance = 0;
    char extra = 0;
    const int read = std::sscanf(text.c_str(), "%d:%lf:%lf%c", &label, &edge, &distance, &extra);
    if (read != 2 && read != 3)
      return absl::InvalidArgumentError("--label-sizing: '" + text +
                                        "' is not LABEL:EDGE_MM[:DISTANCE_MM]");
    poisson.label_sizing.push_back({label, edge, distance});
  }
  if (!flags.label_names.empty()) {
    auto table = volume::read_label_table(flags.label_names);
    if (!table.ok()) return table.status();
    params.label_names = *std::move(table);
  }
  params.frame = flags.coordinates == "ras" ? CoordinateFrame::kRas : CoordinateFrame::kLps;
  params.limits.separate_overlapping = flags.overlapping == "separate";
  poisson.adapt_to_thickness = !flags.no_adapt_to_thickness;
  poisson.prune_strands = !flags.keep_strands;
  params.guard.fall_back = !flags.no_fall_back;
  params.mesh_on_drawn_grid = !flags.file_grid;
  params.tetgen.keep_boundary = !flags.tet_split_boundary;
  poisson.normals = flags.normals == "area" ? surface::NormalWeighting::kArea
                                            : surface::NormalWeighting::kUniform;
  poisson.point_reduction = flags.point_reduction == "hierarchy"
                                ? surface::PointReduction::kHierarchy
                            : flags.point_reduction == "none" ? surface::PointReduction::kNone
                                                              : surface::PointReduction::kGrid;
  params.volume = flags.volume == "tet"          ? VolumeMethod::kTetgen
                  : flags.volume == "mixed"      ? VolumeMethod::kMixed
                  : flags.volume == "hex"        ? VolumeMethod::kHex
                  : flags.volume == "conforming" ? VolumeMethod::kConforming
                                                 : VolumeMethod::kNone;
  params.surface = flags.surface == "mc"         ? SurfaceMethod::kMarchingCubes
                   : flags.surface == "repaired" ? SurfaceMethod::kRepaired
                   : flags.surface == "poisson"  ? SurfaceMethod::kPoisson
                                                 : SurfaceMethod::kNet;
  v1::MeshOptions proto = make_options(params);
  if (flags.surface.empty()) proto.set_surface(v1::SURFACE_METHOD_UNSPECIFIED);
  proto.clear_formats();
  for (const auto& format : flags.formats) proto.add_formats(format);
  return proto;
}

}  // namespace labelmesh::client
