// SPDX-License-Identifier: AGPL-3.0-or-later
#include "client/pipeline_options.h"

#include <CLI/CLI.hpp>

#include <cstdio>

#include "core/volume/label_table.h"

namespace labelmesh::client {

void add_pipeline_flags(CLI::App& command, PipelineFlags& flags) {
  command
      .add_option("--labels", flags.labels,
                  "Labels to mesh, e.g. 1,3 (default: every non-zero label)")
      ->delimiter(',');
  command
      .add_option("--surface", flags.surface,
                  "Surface method: net (the labels' shared surface net smoothed within each "
                  "voxel, judged against the voxels; the default), mc (Marching Cubes), repaired "
                  "(MC repaired with CGAL), poisson (repaired MC, then CGAL Poisson "
                  "reconstruction; the default under --volume tet, mixed or hex)")
      ->check(CLI::IsMember({"net", "mc", "repaired", "poisson"}));
  auto& poisson = flags.poisson;
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
  auto& guard = flags.guard;
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
  command.add_flag("--strict", guard.strict,
                   "Fail (exit 4) when any label is delivered outside tolerance or not at all");
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
      .add_option("--hex-size", flags.hex_size_mm,
                  "Mixed and hex: the hexahedra's edge, mm; 0 for three voxels")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command
      .add_option("--hex-interior-size", flags.hex_interior_size_mm,
                  "Mixed: the largest octant's edge inside each label, mm (an octree: cubes of "
                  "--hex-size under the surface, coarser deeper in); 0 for one size throughout")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  command
      .add_option("--conforming-max-faces", flags.conforming_max_interface_faces,
                  "Conforming: voxel faces between labels above which blocks of voxels are "
                  "merged (each keeping its most common label) so the mesh fits in about 1 GiB; "
                  "0 for no bound")
      ->capture_default_str();
  auto& tetgen = flags.tetgen;
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
      .add_option("--tet-improve-quality", flags.improve.target_quality,
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
  command.add_option("--max-voxels", flags.max_voxels, "Refuse volumes with more voxels than this")
      ->capture_default_str();
}

absl::StatusOr<v1::MeshOptions> to_mesh_options(const PipelineFlags& flags) {
  v1::MeshOptions proto;
  for (const auto& text : flags.label_sizing) {
    int label = 0;
    double edge = 0, distance = 0;
    char extra = 0;
    const int read = std::sscanf(text.c_str(), "%d:%lf:%lf%c", &label, &edge, &distance, &extra);
    if (read != 2 && read != 3)
      return absl::InvalidArgumentError("--label-sizing: '" + text +
                                        "' is not LABEL:EDGE_MM[:DISTANCE_MM]");
    auto* entry = proto.add_label_sizing();
    entry->set_label(label);
    entry->set_max_edge_mm(edge);
    entry->set_max_distance_mm(distance);
  }
  if (!flags.label_names.empty()) {
    auto table = volume::read_label_table(flags.label_names);
    if (!table.ok()) return table.status();
    for (const auto& named : *table) {
      auto* entry = proto.add_label_names();
      entry->set_label(named.label);
      entry->set_name(named.name);
      if (named.colour) {
        for (uint8_t c : *named.colour) entry->add_colour_rgb(c);
      }
    }
  }
  proto.set_coordinates(flags.coordinates == "ras" ? v1::COORDINATE_FRAME_RAS
                                                   : v1::COORDINATE_FRAME_LPS);
  proto.set_overlapping_segments(flags.overlapping == "separate" ? v1::OVERLAPPING_SEGMENTS_SEPARATE
                                                                 : v1::OVERLAPPING_SEGMENTS_REFUSE);
  if (flags.poisson.max_edge_mm > 0) proto.set_max_edge_mm(flags.poisson.max_edge_mm);
  if (flags.poisson.max_distance_mm > 0) proto.set_max_distance_mm(flags.poisson.max_distance_mm);
  proto.set_adapt_to_thickness(!flags.no_adapt_to_thickness);
  proto.set_poisson_min_thickness_voxels(flags.poisson.min_thickness_voxels);
  proto.set_volume_tolerance_percent(flags.guard.volume_percent);
  proto.set_small_volume_tolerance_percent(flags.guard.small_volume_percent);
  proto.set_hausdorff_tolerance_mm(flags.guard.hausdorff_mm);
  proto.set_fall_back(!flags.no_fall_back);
  proto.set_strict(flags.guard.strict);
  for (int32_t label : flags.labels) proto.add_labels(label);
  proto.set_surface(flags.surface == "mc"         ? v1::SURFACE_METHOD_MARCHING_CUBES
                    : flags.surface == "repaired" ? v1::SURFACE_METHOD_REPAIRED
                    : flags.surface == "poisson"  ? v1::SURFACE_METHOD_POISSON
                    : flags.surface == "net"      ? v1::SURFACE_METHOD_NET
                                                  : v1::SURFACE_METHOD_UNSPECIFIED);
  const auto& poisson = flags.poisson;
  proto.set_min_angle_deg(poisson.min_angle_deg);
  proto.set_max_edge_voxels(poisson.max_edge_voxels);
  proto.set_max_distance_voxels(poisson.max_distance_voxels);
  proto.set_min_component_voxels(poisson.min_component_voxels);
  proto.set_point_cell_voxels(poisson.point_cell_voxels);
  proto.set_point_cluster_size(poisson.point_cluster_size);
  proto.set_max_points(poisson.max_points);
  proto.set_split_points(poisson.split_points);
  proto.set_prune_strands(!flags.keep_strands);
  proto.set_smoothing_iterations(poisson.smoothing.iterations);
  proto.set_smoothing_pass_band(poisson.smoothing.pass_band);

  proto.set_normals(flags.normals == "area" ? v1::NORMAL_WEIGHTING_AREA
                                            : v1::NORMAL_WEIGHTING_UNIFORM);
  proto.set_point_reduction(flags.point_reduction == "hierarchy" ? v1::POINT_REDUCTION_HIERARCHY
                            : flags.point_reduction == "none"    ? v1::POINT_REDUCTION_NONE
                                                                 : v1::POINT_REDUCTION_GRID);
  if (flags.volume != "none") {
    proto.set_volume(flags.volume == "mixed"        ? v1::VOLUME_METHOD_MIXED
                     : flags.volume == "hex"        ? v1::VOLUME_METHOD_HEX
                     : flags.volume == "conforming" ? v1::VOLUME_METHOD_CONFORMING
                                                    : v1::VOLUME_METHOD_TETGEN);
    proto.set_hex_size_mm(flags.hex_size_mm);
    proto.set_conforming_max_interface_faces(flags.conforming_max_interface_faces);
    proto.set_hex_interior_size_mm(flags.hex_interior_size_mm);
    proto.set_tet_radius_edge(flags.tetgen.radius_edge_ratio);
    proto.set_tet_min_dihedral_deg(flags.tetgen.min_dihedral_deg);
    proto.set_tet_max_volume_mm3(flags.tetgen.max_volume_mm3);
    proto.set_tet_keep_boundary(!flags.tet_split_boundary);
    proto.set_tet_max_dihedral_deg(flags.tetgen.max_dihedral_deg);
    proto.set_tet_improve_quality(flags.improve.target_quality);
  }
  for (const auto& format : flags.formats) proto.add_formats(format);
  proto.set_max_voxels(flags.max_voxels);
  return proto;
}

}  // namespace labelmesh::client
