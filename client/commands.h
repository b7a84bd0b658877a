// SPDX-License-Identifier: AGPL-3.0-or-later
// The labelmesh subcommands. Each registers its options on the CLI11 app and
// returns a runner that yields the process exit code.
#pragma once

#include <functional>

namespace CLI {
class App;
}

namespace labelmesh::client {

using CommandRunner = std::function<int()>;

CommandRunner add_info_command(CLI::App& app);
CommandRunner add_mesh_command(CLI::App& app);
CommandRunner add_phantom_command(CLI::App& app);
// Commands that talk to a labelmeshd server.
CommandRunner add_submit_command(CLI::App& app);
CommandRunner add_watch_command(CLI::App& app);
CommandRunner add_status_command(CLI::App& app);
CommandRunner add_fetch_command(CLI::App& app);
CommandRunner add_cancel_command(CLI::App& app);
CommandRunner add_delete_command(CLI::App& app);
CommandRunner add_list_command(CLI::App& app);
CommandRunner add_health_command(CLI::App& app);

}  // namespace labelmesh::client
