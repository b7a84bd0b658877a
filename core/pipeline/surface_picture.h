// SPDX-License-Identifier: AGPL-3.0-or-later
// Pictures of the delivered surfaces for report.html: drawn in software
// (a depth buffer and flat shading), so that a worker with no display and no
// OpenGL can make them, and stored as PNG.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/surface/triangle_mesh.h"

namespace labelmesh {

// Directions a picture is seen from, in the patient's frame (LPS): from the
// front (superior up, the patient's left on the right), from the patient's
// left (superior up, anterior on the left), and from the feet (anterior up,
// the patient's left on the right, as axial images are shown).
enum class PictureView { kAnterior, kLeft, kInferior };

struct ColouredSurface {
  int32_t label = 0;
  const surface::TriangleMesh* mesh = nullptr;
  std::array<uint8_t, 3> rgb{200, 200, 200};
  // Closed, wound outward throughout and not crossing itself: its
  // triangles facing away from the viewer are hidden behind its own and
  // need not be drawn.
  bool closed_outward = false;
};

// An RGB picture, row by row from the top.
struct Picture {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgb;
  // Pixels not left at the white background.
  size_t covered_pixels() const;
};

// The surfaces seen from `view`, orthographic, the box of every point fitted
// into `size` x `size` pixels with a margin. White where no surface is.
Picture draw_surfaces(const std::vector<ColouredSurface>& surfaces, PictureView view, int size);

// The pictures side by side, top-aligned, on white.
Picture in_a_row(const std::vector<Picture>& pictures);

// PNG file bytes of the picture (VTK's PNG writer).
std::string png_bytes(const Picture& picture);

// What report.html shows: every surface from the front, the left and the feet,
// and each label alone from the front, as PNG bytes.
struct SurfacePictures {
  std::string overview_png;
  std::map<int32_t, std::string> label_png;
};

SurfacePictures make_surface_pictures(const std::vector<ColouredSurface>& surfaces);

}  // namespace labelmesh
