// What a caller asks of one meshing run: user intent only, with defaults.
// Values derived from the input (tolerances from voxel size) never live here.
#pragma once

#include <cstdint>
#include <vector>

#include "core/surface/write_surface.h"
#include "core/volume/volume_header.h"

namespace labelmesh {

enum class SurfaceMethod {
  kMarchingCubes,  // VTK discrete flying edges; staircase surface (paper §2.2).
};

struct MeshParams {
  // Labels to mesh; empty means every non-zero label in the volume.
  std::vector<int32_t> labels;
  SurfaceMethod surface = SurfaceMethod::kMarchingCubes;
  // Surface files to write per label.
  std::vector<surface::SurfaceFormat> formats{surface::SurfaceFormat::kStl,
                                              surface::SurfaceFormat::kVtp};
  // Size limits applied to the input before anything is allocated.
  volume::ReadLimits limits;
};

}  // namespace labelmesh
