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

}  // namespace labelmesh::client
