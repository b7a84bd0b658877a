// SPDX-License-Identifier: AGPL-3.0-or-later
// The trade a Gaussian blur of each label's mask makes between the steps its
// surface keeps and the voxel centres it puts on the wrong side.
#pragma once

#include <string>

namespace labelmesh::bench {

// For each blur of 0.5 to 1.5 voxels, the median over labels of 1,000 voxels
// or more of its surface's axis-aligned share and of the boundary voxel
// centres it puts on the wrong side, and how many labels stay within 1 % of
// them; then per label the least share a blur gives within 1 %, beside the
// Slicer-like share and ours; and the same with the guard's volume and reach
// bounds applied too (not its distance bound, which ours pass as well).
// Prints; 1 when `path` cannot be read or meshed.
int bench_blurs(const std::string& path);

}  // namespace labelmesh::bench
