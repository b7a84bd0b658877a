// SPDX-License-Identifier: AGPL-3.0-or-later
#include "core/pipeline/build_info.h"

#include <CGAL/version_macros.h>
#include <vtkVersionMacros.h>

namespace labelmesh {

v1::BuildInfo build_info() {
  v1::BuildInfo info;
#if defined(__clang__)
  info.set_compiler("clang " __clang_version__);
#elif defined(__GNUC__)
  info.set_compiler("gcc " __VERSION__);
#endif
#ifdef NDEBUG
  info.set_build_type("release");
#else
  info.set_build_type("debug");
#endif
  info.set_cgal_version(CGAL_VERSION_STR);
  info.set_vtk_version(VTK_VERSION);
#if defined(__SANITIZE_ADDRESS__)
  info.add_sanitizers("address");
#endif
#if defined(__SANITIZE_THREAD__)
  info.add_sanitizers("thread");
#endif
  return info;
}

}  // namespace labelmesh
