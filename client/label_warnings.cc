// SPDX-License-Identifier: AGPL-3.0-or-later
#include "client/label_warnings.h"

#include <cstdio>
#include <string>

namespace labelmesh::client {

void print_label_warnings(std::string_view command, const v1::Report& report) {
  if (report.warnings().empty()) return;
  std::fprintf(stderr, "labelmesh %s: %d label(s) outside tolerance or not delivered:\n",
               std::string(command).c_str(), report.warnings_size());
  for (const auto& warning : report.warnings())
    std::fprintf(stderr, "  label %d: %s\n", warning.label(), warning.reason().c_str());
}

}  // namespace labelmesh::client
