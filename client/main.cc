// SPDX-License-Identifier: AGPL-3.0-or-later
// labelmesh: segmented label volumes in, surface meshes and a quality report out.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <map>

#include "client/commands.h"
#include "client/exit_codes.h"

int main(int argc, char** argv) {
  using namespace labelmesh::client;
  CLI::App app{"labelmesh " LABELMESH_VERSION
               ": meshes segmented medical label volumes (NIfTI, MetaImage, NRRD, INR, VTI).\n"
               "Coordinates are in millimetres, in the input's patient space, LPS convention."};
  app.set_version_flag("--version", "labelmesh " LABELMESH_VERSION);
  app.require_subcommand(1);
  app.footer(kExitCodeHelp);
  std::map<const CLI::App*, CommandRunner> runners;
  for (auto add : {add_info_command, add_mesh_command, add_phantom_command, add_submit_command,
                   add_watch_command, add_status_command, add_fetch_command, add_cancel_command,
                   add_delete_command, add_list_command, add_health_command}) {
    const size_t before = app.get_subcommands({}).size();
    CommandRunner runner = add(app);
    runners[app.get_subcommands({}).at(before)] = std::move(runner);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return kExitUsage;
  }
  for (const auto& [subcommand, runner] : runners) {
    if (subcommand->parsed()) return runner();
  }
  return kExitUsage;
}
