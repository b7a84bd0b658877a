// SPDX-License-Identifier: AGPL-3.0-or-later
#include "client/label_warnings.h"

#include <cstdio>
#include <string>

namespace labelmesh::client {

namespace {

// At most this many touching pairs are named; the report has them all.
constexpr int kMostPairsNamed = 5;

void print_touching_labels(std::string_view command, const v1::Report& report) {
  const auto& pairs = report.volume().touching_labels();
  if (pairs.empty()) return;
  std::fprintf(stderr,
               "labelmesh %s: %d pair(s) of labels touch; each label's volume mesh is separate, "
               "so there they overlap and share no nodes (--volume conforming shares them):\n",
               std::string(command).c_str(), pairs.size());
  for (int i = 0; i < pairs.size() && i < kMostPairsNamed; ++i)
    std::fprintf(stderr, "  labels %d and %d: %llu voxel faces\n", pairs[i].first(),
                 pairs[i].second(), static_cast<unsigned long long>(pairs[i].voxel_faces()));
  if (pairs.size() > kMostPairsNamed)
    std::fprintf(stderr, "  and %d more (report.json, volume.touching_labels)\n",
                 pairs.size() - kMostPairsNamed);
}

}  // namespace

void print_label_warnings(std::string_view command, const v1::Report& report) {
  print_touching_labels(command, report);
  if (report.warnings().empty()) return;
  std::fprintf(stderr, "labelmesh %s: %d label(s) outside tolerance or not delivered:\n",
               std::string(command).c_str(), report.warnings_size());
  for (const auto& warning : report.warnings())
    std::fprintf(stderr, "  label %d: %s\n", warning.label(), warning.reason().c_str());
}

}  // namespace labelmesh::client
