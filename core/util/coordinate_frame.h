// SPDX-License-Identifier: AGPL-3.0-or-later
// The frame output coordinates are written in. Everything inside labelmesh is
// LPS millimetres (DICOM's patient frame); RAS (3D Slicer's and most
// neuroimaging tools' world frame) is the same space with x and y negated, a
// rotation by 180 degrees about the z axis, so no element turns inside out.
#pragma once

#include <array>
#include <string_view>

namespace labelmesh {

enum class CoordinateFrame { kLps, kRas };

// "LPS" or "RAS", as 3D Slicer writes it after "SPACE=".
inline std::string_view frame_name(CoordinateFrame frame) {
  return frame == CoordinateFrame::kRas ? "RAS" : "LPS";
}

// An LPS point in `frame`.
inline std::array<double, 3> in_frame(const std::array<double, 3>& lps, CoordinateFrame frame) {
  if (frame == CoordinateFrame::kLps) return lps;
  return {-lps[0], -lps[1], lps[2]};
}

}  // namespace labelmesh
