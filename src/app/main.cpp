#include <csignal>
#include <cstdio>
#include <exception>
#include <new>
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

namespace {

// The one error line, with what the system's terse words mean for the user.
std::string explained(std::string message) {
  // EFBIG from write(2) (and FFmpeg's copy of it) once `ulimit -f` is reached.
  if (message.find("File too large") != std::string::npos)
    message += " (the file size limit was reached: see `ulimit -f`; the file ends at its last complete write)";
  return message;
}

}  // namespace

int main(int argc, char** argv) {
  // Past `ulimit -f` the kernel would kill us with SIGXFSZ (a core dump, no message); ignored, the
  // write fails with EFBIG instead and the error names the file.
  std::signal(SIGXFSZ, SIG_IGN);
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
  } catch (const std::bad_alloc&) {
    std::string what = "panoptes";
    for (const CLI::App* sub : root.get_subcommands()) what += " " + sub->get_name();
    std::fprintf(stderr,
                 "panoptes: error: out of memory while running `%s` (its input asks for more memory than this "
                 "machine or its limit gives; see the command's size options or PANOPTES_MEMORY_LIMIT)\n",
                 what.c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panoptes: error: %s\n", explained(e.what()).c_str());
    return 1;
  }
  return panoptes::app::exit_code();
}
