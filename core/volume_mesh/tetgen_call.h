// SPDX-License-Identifier: AGPL-3.0-or-later
// Calling TetGen 1.5 safely: its switches from our parameters, and a run that
// turns everything it throws into a status. Included only by the files that
// call TetGen, so its header and licence stay there.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "absl/status/status.h"
#include "core/volume_mesh/tetrahedralize.h"

// TetGen's library interface: errors are thrown as ints instead of ending the process. The
// library itself is built this way, so its inline functions must be seen the same way here.
#define TETLIBRARY
#include <tetgen.h>

namespace labelmesh::volume_mesh {

// The refinement switches for `params` (-pq, -a, -Y, -o/), without output
// switches; check_tetgen_params(params) must be OK.
std::string tetgen_quality_switches(const TetgenParams& params);

// Fills `in` with a triangle surface as TetGen's piecewise linear complex,
// numbered from 0: each triangle one facet whose marker is its index + 1, so
// output faces name the triangle they lie in.
void fill_triangle_plc(const std::vector<std::array<double, 3>>& points,
                       const std::vector<std::array<uint32_t, 3>>& triangles, tetgenio& in);

// Point `index` of TetGen's output.
std::array<double, 3> tetgen_point(const tetgenio& out, int index);

// Runs TetGen with `switches`; nothing it throws gets past here. Error
// messages say what was being meshed: `what`, e.g. "the surface of label 3".
absl::Status run_tetgen(const std::string& switches, tetgenio& in, tetgenio& out,
                        std::string_view what);

}  // namespace labelmesh::volume_mesh
