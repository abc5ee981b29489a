// Subcommands register themselves here, one file each (cmd_simplify.cpp, cmd_measure.cpp, ...),
// so adding a command never touches main.cpp.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>

namespace qem::cli {

/// Adds a subcommand to `app`; the returned callback runs it and gives the exit code.
using CommandFactory = std::function<std::function<int()>(CLI::App& app)>;

/// Registers a subcommand factory; `order` sorts the commands in `qem --help`.
bool register_command(int order, CommandFactory factory);

}  // namespace qem::cli
