#include <algorithm>
#include <csignal>
#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include "app/command.hpp"
#include "core/error.hpp"
#include "core/stop_request.hpp"
#include "core/version.hpp"

namespace panoptes::app {
namespace {
struct Registered {
  std::string file;
  CommandSetup setup;
};
std::vector<Registered>& registry() {
  static std::vector<Registered> r;
  return r;
}
}  // namespace

CommandRegistration::CommandRegistration(CommandSetup setup, std::source_location where) {
  registry().push_back({where.file_name(), std::move(setup)});
}

void add_registered_commands(CLI::App& root) {
  std::stable_sort(registry().begin(), registry().end(),
                   [](const Registered& a, const Registered& b) { return a.file < b.file; });
  for (auto& r : registry()) r.setup(root);
}

int& exit_code() {
  static int code = 0;
  return code;
}

namespace {

// Edit distance (insertions, deletions, substitutions) between two short words.
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

std::string unknown_command_message(const CLI::App& root, const std::string& word) {
  std::string best, names;
  std::size_t best_distance = std::string::npos;
  for (const CLI::App* sub : root.get_subcommands([](const CLI::App*) { return true; })) {
    const std::string& name = sub->get_name();
    names += (names.empty() ? "" : ", ") + name;
    const std::size_t d = edit_distance(word, name);
    if (d < best_distance) best_distance = d, best = name;
  }
  std::string text = "unknown command \"" + word + "\"";
  // Two edits catch the usual typos (pley, paly, rnu) without suggesting unrelated short words.
  if (best_distance <= std::min<std::size_t>(2, std::max<std::size_t>(1, word.size() / 2)))
    return text + "; did you mean \"" + best + "\"? (see `panoptes --help`)";
  return text + "; the commands are " + names + " (see `panoptes --help`)";
}

void explain_number_options(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    // The type name, without the descriptions of the option's checks ("FLOAT:FLOAT in [0 - 1]").
    const std::string full = option->get_type_name();
    const std::string type = full.substr(0, full.find(':'));
    const bool integer = type == "INT" || type == "UINT";
    if (!integer && type != "FLOAT") continue;
    // Runs before the option's own checks (transform() goes first), so a word given for a number is
    // reported as such rather than as "Value abc not in range".
    option->transform(CLI::Validator(
        [integer, type](std::string& value) {
          double d = 0;
          long long i = 0;
          const bool ok = integer ? CLI::detail::lexical_cast(value, i) : CLI::detail::lexical_cast(value, d);
          if (ok) return std::string();
          return "\"" + value + "\" is not " +
                 (integer ? std::string(type == "UINT" ? "a non-negative integer (e.g. 3)" : "an integer (e.g. 3)")
                          : std::string("a number (e.g. 0.5)"));
        },
        "", "number"));
  }
  for (CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) explain_number_options(*sub);
}

}  // namespace
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
  root.set_version_flag("--version", std::string("panoptes ") + panoptes::kVersion);
  root.require_subcommand(1);
  panoptes::app::add_registered_commands(root);
  panoptes::app::explain_number_options(root);
  // A mistyped command: CLI11 would only say "A subcommand is required".
  if (argc > 1 && argv[1][0] != '-' &&
      root.get_subcommands([&](const CLI::App* sub) { return sub->check_name(argv[1]); }).empty()) {
    std::fprintf(stderr, "panoptes: error: %s\n", panoptes::app::unknown_command_message(root, argv[1]).c_str());
    return 1;
  }
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
