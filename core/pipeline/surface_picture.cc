// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/surface_picture.h"

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/util/side_by_side.h"
#include "core/util/vec3.h"

namespace labelmesh {
namespace {

using geometry::dot;
using Vec = geometry::Vec3;

// Screen right, screen up and the direction towards the viewer, in LPS.
struct Camera {
  Vec right, up, toward_viewer;
};

Camera camera_of(PictureView view) {
  switch (view) {
    case PictureView::kAnterior:
      return {{1, 0, 0}, {0, 0, 1}, {0, -1, 0}};
    case PictureView::kLeft:
      return {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}};
    case PictureView::kInferior:
      return {{1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
  }
  return {};
}

// Each side drawn this many times finer, then averaged: smooth edges.
constexpr int kSupersampling = 2;
constexpr double kMargin = 0.05;
constexpr uint8_t kBackground = 255;

struct Frame {
  double scale = 1;  // pixels per mm
  double centre_right = 0, centre_up = 0;
  int size = 0;  // fine pixels per side
};

Frame fit(const std::vector<ColouredSurface>& surfaces, const Camera& camera, int size) {
  double lo_r = std::numeric_limits<double>::max(), hi_r = -lo_r, lo_u = lo_r, hi_u = -lo_r;
  for (const auto& surface : surfaces) {
    for (const auto& p : surface.mesh->points) {
      const double r = dot(p, camera.right), u = dot(p, camera.up);
      lo_r = std::min(lo_r, r), hi_r = std::max(hi_r, r);
      lo_u = std::min(lo_u, u), hi_u = std::max(hi_u, u);
    }
  }
  Frame frame;
  frame.size = size * kSupersampling;
  if (lo_r > hi_r) return frame;
  const double extent = std::max({hi_r - lo_r, hi_u - lo_u, 1e-9});
  frame.scale = frame.size * (1 - 2 * kMargin) / extent;
  frame.centre_right = (lo_r + hi_r) / 2;
  frame.centre_up = (lo_u + hi_u) / 2;
  return frame;
}

struct Canvas {
  int size;
  std::vector<uint8_t> rgb;
  std::vector<double> depth;  // larger is nearer the viewer
  explicit Canvas(int n)
      : size(n),
        rgb(size_t(n) * n * 3, kBackground),
        depth(size_t(n) * n, -std::numeric_limits<double>::infinity()) {}
};

// Fills one triangle given in fine pixels (x right, y down) and depth.
void fill_triangle(Canvas& canvas, const std::array<Vec, 3>& v, const std::array<uint8_t, 3>& rgb) {
  const double area =
      (v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1]);
  if (std::abs(area) < 1e-12) return;
  const int x0 = std::max(0, int(std::floor(std::min({v[0][0], v[1][0], v[2][0]}))));
  const int x1 = std::min(canvas.size - 1, int(std::ceil(std::max({v[0][0], v[1][0], v[2][0]}))));
  const int y0 = std::max(0, int(std::floor(std::min({v[0][1], v[1][1], v[2][1]}))));
  const int y1 = std::min(canvas.size - 1, int(std::ceil(std::max({v[0][1], v[1][1], v[2][1]}))));
  const double inverse_area = 1 / area;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const double px = x + 0.5, py = y + 0.5;
      // Barycentric weights from the edge functions.
      const double w0 =
          ((v[1][0] - px) * (v[2][1] - py) - (v[2][0] - px) * (v[1][1] - py)) * inverse_area;
      const double w1 =
          ((v[2][0] - px) * (v[0][1] - py) - (v[0][0] - px) * (v[2][1] - py)) * inverse_area;
      const double w2 = 1 - w0 - w1;
      if (w0 < 0 || w1 < 0 || w2 < 0) continue;
      const double z = w0 * v[0][2] + w1 * v[1][2] + w2 * v[2][2];
      const size_t at = size_t(y) * canvas.size + x;
      if (z <= canvas.depth[at]) continue;
      canvas.depth[at] = z;
      std::copy(rgb.begin(), rgb.end(), canvas.rgb.begin() + 3 * at);
    }
  }
}

// Flat shading of a triangle with normal `n` (any length): full colour
// facing the viewer, darker as it turns away; either side lit alike.
std::array<uint8_t, 3> shade(const std::array<uint8_t, 3>& rgb, const Vec& n,
                             const Vec& toward_viewer) {
  const double length = geometry::norm(n);
  const double facing = length > 0 ? std::abs(dot(n, toward_viewer)) / length : 0;
  const double light = 0.3 + 0.7 * facing;
  return {uint8_t(rgb[0] * light), uint8_t(rgb[1] * light), uint8_t(rgb[2] * light)};
}

Picture downsampled(const Canvas& canvas) {
  Picture picture;
  picture.width = picture.height = canvas.size / kSupersampling;
  picture.rgb.resize(size_t(picture.width) * picture.height * 3);
  for (int y = 0; y < picture.height; ++y) {
    for (int x = 0; x < picture.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        int sum = 0;
        for (int dy = 0; dy < kSupersampling; ++dy)
          for (int dx = 0; dx < kSupersampling; ++dx)
            sum += canvas.rgb[3 * (size_t(y * kSupersampling + dy) * canvas.size +
                                   x * kSupersampling + dx) +
                              c];
        picture.rgb[3 * (size_t(y) * picture.width + x) + c] =
            uint8_t(sum / (kSupersampling * kSupersampling));
      }
    }
  }
  return picture;
}

}  // namespace

size_t Picture::covered_pixels() const {
  size_t covered = 0;
  for (size_t i = 0; i + 2 < rgb.size(); i += 3)
    covered += rgb[i] != kBackground || rgb[i + 1] != kBackground || rgb[i + 2] != kBackground;
  return covered;
}

Picture draw_surfaces(const std::vector<ColouredSurface>& surfaces, PictureView view, int size) {
  const Camera camera = camera_of(view);
  const Frame frame = fit(surfaces, camera, size);
  Canvas canvas(frame.size);
  const auto to_screen = [&](const Vec& p) -> Vec {
    return {frame.size / 2.0 + (dot(p, camera.right) - frame.centre_right) * frame.scale,
            frame.size / 2.0 - (dot(p, camera.up) - frame.centre_up) * frame.scale,
            dot(p, camera.toward_viewer)};
  };
  for (const auto& surface : surfaces) {
    const auto& points = surface.mesh->points;
    for (const auto& t : surface.mesh->triangles) {
      const std::array<Vec, 3> corners{points[t[0]], points[t[1]], points[t[2]]};
      const Vec n = geometry::cross(geometry::sub(corners[1], corners[0]),
                                    geometry::sub(corners[2], corners[0]));
      // On a closed surface the nearest triangle along any line of sight
      // faces the viewer: the others never show.
      if (surface.closed_outward && dot(n, camera.toward_viewer) <= 0) continue;
      fill_triangle(canvas, {to_screen(corners[0]), to_screen(corners[1]), to_screen(corners[2])},
                    shade(surface.rgb, n, camera.toward_viewer));
    }
  }
  return downsampled(canvas);
}

Picture in_a_row(const std::vector<Picture>& pictures) {
  Picture out;
  for (const auto& p : pictures) {
    out.width += p.width;
    out.height = std::max(out.height, p.height);
  }
  out.rgb.assign(size_t(out.width) * out.height * 3, kBackground);
  int left = 0;
  for (const auto& p : pictures) {
    for (int y = 0; y < p.height; ++y)
      std::copy_n(p.rgb.begin() + 3 * size_t(y) * p.width, 3 * p.width,
                  out.rgb.begin() + 3 * (size_t(y) * out.width + left));
    left += p.width;
  }
  return out;
}

std::string png_bytes(const Picture& picture) {
  vtkNew<vtkImageData> image;
  image->SetDimensions(picture.width, picture.height, 1);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* pixels = static_cast<uint8_t*>(image->GetScalarPointer());
  // VTK's rows run from the bottom up.
  for (int y = 0; y < picture.height; ++y)
    std::copy_n(picture.rgb.begin() + 3 * size_t(picture.height - 1 - y) * picture.width,
                3 * picture.width, pixels + 3 * size_t(y) * picture.width);
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputData(image);
  writer->WriteToMemoryOn();
  writer->Write();
  vtkUnsignedCharArray* result = writer->GetResult();
  if (result == nullptr) return {};
  const auto* bytes = result->GetPointer(0);
  return std::string(reinterpret_cast<const char*>(bytes),
                     size_t(result->GetNumberOfTuples()) * result->GetNumberOfComponents());
}

SurfacePictures make_surface_pictures(const std::vector<ColouredSurface>& surfaces) {
  constexpr int kOverviewSize = 300, kLabelSize = 128;
  SurfacePictures pictures;
  if (surfaces.empty()) return pictures;
  // Two threads: two views on one, the third and each label on the other.
  std::vector<Picture> views(3);
  side_by_side(
      [&] {
        views[0] = draw_surfaces(surfaces, PictureView::kAnterior, kOverviewSize);
        views[1] = draw_surfaces(surfaces, PictureView::kLeft, kOverviewSize);
      },
      [&] {
        views[2] = draw_surfaces(surfaces, PictureView::kInferior, kOverviewSize);
        for (const auto& surface : surfaces)
          pictures.label_png[surface.label] =
              png_bytes(draw_surfaces({surface}, PictureView::kAnterior, kLabelSize));
      });
  pictures.overview_png = png_bytes(in_a_row(views));
  return pictures;
}

}  // namespace labelmesh
