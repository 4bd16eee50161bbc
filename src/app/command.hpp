#pragma once
// Subcommands register themselves here, so each lives in its own thin cmd_<name>.cpp.
#include <CLI/CLI.hpp>

#include <functional>
#include <source_location>

namespace panoptes::app {

/// Adds a subcommand (options + callback) to the root `panoptes` app. Callbacks report failures by
/// throwing; main() prints them as one line and exits non-zero.
using CommandSetup = std::function<void(CLI::App& root)>;

/// Registers a subcommand at static-initialization time: `static CommandRegistration r([](CLI::App& root){...});`
/// `where` (the registering file) orders the subcommands in --help whatever the order of static
/// initialization, which a unity build of the command units changes.
struct CommandRegistration {
  explicit CommandRegistration(CommandSetup setup, std::source_location where = std::source_location::current());
};

/// Runs every registered setup on root (in name order of registration files).
void add_registered_commands(CLI::App& root);

/// Exit code a callback may set to end the program with a status other than 0 without an error line.
int& exit_code();

}  // namespace panoptes::app
