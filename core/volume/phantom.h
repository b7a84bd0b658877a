// SPDX-License-Identifier: AGPL-3.0-or-later
// Synthetic label volumes with known analytic geometry, for the demo and for
// accuracy tests. Every voxel is labelled by the shape at its centre.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/volume/label_volume.h"

namespace labelmesh::volume {

enum class PhantomShape {
  kSphere,                 // label 1: ball of radius 20 voxels, 1 mm isotropic.
  kNestedSpheres,          // labels 1, 2, 3: ball r < 6, shells 6-12 and 12-18 voxels.
  kTorus,                  // label 1: major radius 14, minor 6 voxels (genus 1).
  kTouchingBoxes,          // labels 1, 2: two voxel-aligned boxes sharing a face.
  kObliqueEllipsoid,       // label 1: semi-axes 18, 12, 9 mm on an oblique grid of
                           // 0.8 x 1.1 x 1.7 mm voxels.
  kThinShapes,             // labels 1-11 of thin_shapes(), 3 mm isotropic voxels.
  kThinShapesAnisotropic,  // the same on 0.75 x 0.75 x 3 mm voxels.
};

std::optional<PhantomShape> phantom_shape_from_name(std::string_view name);
// sphere, nested-spheres, torus, boxes, oblique-ellipsoid, thin-shapes,
// thin-shapes-anisotropic.
const std::vector<std::string_view>& phantom_shape_names();

// What a label's surface should enclose, from the analytic shape.
struct PhantomTruth {
  int32_t label = 0;
  double volume_mm3 = 0;
  // Exact except for the ellipsoid (Knud Thomsen's formula, within 1.1 %).
  double area_mm2 = 0;
};

struct Phantom {
  LabelVolume volume;
  std::vector<PhantomTruth> truth;
  // LPS centre of the shape, mm.
  std::array<double, 3> centre{0, 0, 0};
};

// `scale` multiplies every length, in voxels (2 gives a sphere of radius 40);
// for the thin shapes, it multiplies the spacing.
Phantom make_phantom(PhantomShape shape, double scale = 1.0);

}  // namespace labelmesh::volume
