#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "app/command.hpp"
#include "core/error.hpp"
#include "core/stop_request.hpp"

namespace panoptes::app {
namespace {
std::vector<CommandSetup>& registry() {
  static std::vector<CommandSetup> r;
  return r;
}
}  // namespace

CommandRegistration::CommandRegistration(CommandSetup setup) { registry().push_back(std::move(setup)); }

void add_registered_commands(CLI::App& root) {
  for (auto& setup : registry()) setup(root);
}

int& exit_code() {
  static int code = 0;
  return code;
}

}  // namespace panoptes::app

int main(int argc, char** argv) {
  CLI::App root{
      "Panoptes: in-situ visualization from very many cameras, kept as compressed movies, explored "
      "interactively afterwards.",
      "panoptes"};
  root.set_version_flag("--version", "panoptes 0.1.0");
  root.require_subcommand(1);
  panoptes::app::add_registered_commands(root);
  try {
    root.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version are "errors" of exit code 0: let CLI11 print them. Everything else is one
    // line in the house style and status 1, like any other error.
    if (e.get_exit_code() == 0) return root.exit(e);
    std::string where;
    for (const CLI::App* sub : root.get_subcommands()) where = std::string(" ") + sub->get_name();
    std::fprintf(stderr, "panoptes: error: %s (see `panoptes%s --help`)\n", e.what(), where.c_str());
    return 1;
  } catch (const panoptes::Interrupted& e) {
    std::fprintf(stderr, "panoptes: interrupted: %s\n", e.what());
    return 128 + e.signal();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panoptes: error: %s\n", e.what());
    return 1;
  }
  return panoptes::app::exit_code();
}
