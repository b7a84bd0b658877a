// SPDX-License-Identifier: AGPL-3.0-or-later
// The report's pictures of the surfaces: which side each view shows, what is
// in front, the area a known box covers, and PNG bytes VTK reads back.
#include "core/pipeline/surface_picture.h"

#include <gtest/gtest.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <array>
#include <cmath>
#include <vector>

#include "core/surface/surface_statistics.h"
#include "support/lat_long_sphere.h"

namespace labelmesh {
namespace {

using Rgb = std::array<uint8_t, 3>;
constexpr Rgb kRed{228, 26, 28}, kBlue{55, 126, 184};

// An axis-aligned box, LPS mm, as 12 outward triangles.
surface::TriangleMesh box(std::array<double, 3> centre, std::array<double, 3> half) {
  surface::TriangleMesh mesh;
  for (int i = 0; i < 8; ++i)
    mesh.points.push_back({centre[0] + (i & 1 ? half[0] : -half[0]),
                           centre[1] + (i & 2 ? half[1] : -half[1]),
                           centre[2] + (i & 4 ? half[2] : -half[2])});
  mesh.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                    {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return mesh;
}

Rgb pixel(const Picture& picture, int x, int y) {
  const size_t at = 3 * (size_t(y) * picture.width + x);
  return {picture.rgb[at], picture.rgb[at + 1], picture.rgb[at + 2]};
}

// Pixels of exactly `rgb` (faces square to the view are drawn at full
// colour) in the picture's left and right halves, or top and bottom.
struct Halves {
  size_t first = 0, second = 0;
};
Halves count_colour(const Picture& picture, const Rgb& rgb, bool left_right) {
  Halves halves;
  for (int y = 0; y < picture.height; ++y) {
    for (int x = 0; x < picture.width; ++x) {
      if (pixel(picture, x, y) != rgb) continue;
      const bool first = left_right ? x < picture.width / 2 : y < picture.height / 2;
      (first ? halves.first : halves.second)++;
    }
  }
  return halves;
}

TEST(SurfacePicture, EachViewShowsThePatientsSidesWhereDoctorsLookForThem) {
  // Red on the patient's left (+x) and anterior (-y); blue on the right, posterior.
  const auto left_front = box({50, -50, 0}, {10, 10, 10});
  const auto right_back = box({-50, 50, 0}, {10, 10, 10});
  const std::vector<ColouredSurface> surfaces{{1, &left_front, kRed}, {2, &right_back, kBlue}};

  // From the front the patient's left is on the viewer's right.
  const Picture front = draw_surfaces(surfaces, PictureView::kAnterior, 200);
  EXPECT_EQ(count_colour(front, kRed, true).first, 0u);
  EXPECT_GT(count_colour(front, kRed, true).second, 500u);
  EXPECT_GT(count_colour(front, kBlue, true).first, 500u);
  // From the patient's left, anterior is on the viewer's left.
  const Picture side = draw_surfaces(surfaces, PictureView::kLeft, 200);
  EXPECT_GT(count_colour(side, kRed, true).first, 500u);
  EXPECT_EQ(count_colour(side, kRed, true).second, 0u);
  // From the feet, anterior is up.
  const Picture feet = draw_surfaces(surfaces, PictureView::kInferior, 200);
  EXPECT_GT(count_colour(feet, kRed, false).first, 500u);
  EXPECT_EQ(count_colour(feet, kRed, false).second, 0u);
  EXPECT_GT(count_colour(feet, kBlue, false).second, 500u);
}

TEST(SurfacePicture, TheNearerSurfaceHidesTheFartherOne) {
  const auto small_front = box({0, -40, 0}, {5, 5, 5});
  const auto large_back = box({0, 40, 0}, {20, 20, 20});
  const Picture front = draw_surfaces({{1, &large_back, kBlue}, {2, &small_front, kRed}},
                                      PictureView::kAnterior, 200);
  EXPECT_EQ(pixel(front, 100, 100), kRed);
  // From the feet both show, the large one more.
  const Picture feet = draw_surfaces({{1, &large_back, kBlue}, {2, &small_front, kRed}},
                                     PictureView::kInferior, 200);
  const auto red = count_colour(feet, kRed, false), blue = count_colour(feet, kBlue, false);
  EXPECT_GT(blue.first + blue.second, 8 * (red.first + red.second));
}

TEST(SurfacePicture, FromTheFeetTheInferiorSurfaceIsInFront) {
  // A small red box below (inferior, smaller z) a large blue one: seen from
  // the feet the red one hides the middle of the blue one.
  const auto lower = box({0, 0, -40}, {5, 5, 5});
  const auto upper = box({0, 0, 40}, {20, 20, 20});
  const Picture feet =
      draw_surfaces({{1, &upper, kBlue}, {2, &lower, kRed}}, PictureView::kInferior, 200);
  EXPECT_EQ(pixel(feet, 100, 100), kRed);
  EXPECT_EQ(pixel(feet, 30, 100), kBlue);
}

TEST(SurfacePicture, ABoxCoversTheAreaItsShapeAndTheMarginGive) {
  // 100 x 20 x 20 mm, fitted into 300 px with 5 % margins: 270 px for 100 mm.
  const auto bar = box({0, 0, 0}, {50, 10, 10});
  const Picture front = draw_surfaces({{1, &bar, kRed}}, PictureView::kAnterior, 300);
  EXPECT_EQ(front.width, 300);
  EXPECT_EQ(front.height, 300);
  const double expected = 270.0 * 54.0;
  EXPECT_NEAR(double(front.covered_pixels()), expected, 0.03 * expected);
  // Seen end on, the 20 x 20 mm end fills the same 270 px square.
  const Picture side = draw_surfaces({{1, &bar, kRed}}, PictureView::kLeft, 300);
  EXPECT_NEAR(double(side.covered_pixels()), 270.0 * 270.0, 0.03 * 270.0 * 270.0);
}

TEST(SurfacePicture, ClosedSurfacesLookTheSameWithTheirBackFacesLeftOut) {
  auto sphere = testing::lat_long_sphere(24, 48);
  if (surface::signed_volume(sphere) < 0) sphere.flip_orientation();
  for (auto& p : sphere.points) p[0] += 6;  // half in front of the box, half inside it
  const auto cube = box({-4, 0, 0}, {8, 6, 12});
  for (const auto view : {PictureView::kAnterior, PictureView::kLeft, PictureView::kInferior}) {
    std::vector<ColouredSurface> surfaces{{1, &sphere, kRed}, {2, &cube, kBlue}};
    const Picture every_face = draw_surfaces(surfaces, view, 200);
    for (auto& s : surfaces) s.closed_outward = true;
    const Picture front_faces = draw_surfaces(surfaces, view, 200);
    EXPECT_GT(every_face.covered_pixels(), 10000u);
    EXPECT_EQ(front_faces.rgb, every_face.rgb) << int(view);
  }
  // Marked closed and outward, a face turned away from the viewer is not
  // drawn: the box's posterior face (normal +y, LPS) seen from the front.
  surface::TriangleMesh posterior = cube;
  posterior.triangles.clear();
  for (const auto& tri : cube.triangles) {
    const auto& a = cube.points[tri[0]];
    const auto& b = cube.points[tri[1]];
    const auto& c = cube.points[tri[2]];
    const double normal_y =
        (c[0] - a[0]) * (b[2] - a[2]) - (c[2] - a[2]) * (b[0] - a[0]);  // (b - a) x (c - a), y
    if (normal_y > 0) posterior.triangles.push_back(tri);
  }
  ASSERT_EQ(posterior.triangles.size(), 2u);
  EXPECT_GT(draw_surfaces({{2, &posterior, kBlue}}, PictureView::kAnterior, 64).covered_pixels(),
            1000u);
  ColouredSurface marked{2, &posterior, kBlue};
  marked.closed_outward = true;
  EXPECT_EQ(draw_surfaces({marked}, PictureView::kAnterior, 64).covered_pixels(), 0u);
}

TEST(SurfacePicture, PngBytesReadBackAsTheSamePicture) {
  const auto cube = box({0, 0, 0}, {10, 10, 10});
  const Picture front = draw_surfaces({{1, &cube, kBlue}}, PictureView::kAnterior, 64);
  const Picture strip = in_a_row({front, front});
  ASSERT_EQ(strip.width, 128);
  const std::string png = png_bytes(strip);
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(0, 4), "\x89PNG");

  vtkNew<vtkPNGReader> reader;
  reader->SetMemoryBuffer(png.data());
  reader->SetMemoryBufferLength(png.size());
  reader->Update();
  vtkImageData* image = reader->GetOutput();
  int dims[3];
  image->GetDimensions(dims);
  EXPECT_EQ(dims[0], 128);
  EXPECT_EQ(dims[1], 64);
  // The top-left corner is background; the centre of the right copy is the cube.
  // (VTK counts rows from the bottom.)
  const auto at = [&](int x, int y, int c) {
    return int(image->GetScalarComponentAsDouble(x, strip.height - 1 - y, 0, c));
  };
  EXPECT_EQ(at(0, 0, 0), 255);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(at(96, 32, c), kBlue[c]) << c;
}

}  // namespace
}  // namespace labelmesh
