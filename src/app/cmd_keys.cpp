// `panoptes keys`: the player's key table as text, Markdown (docs/ui.md's table is this output) or the
// keys.json document the browser reads — one table, printed, never copied by hand.
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "app/command.hpp"
#include "core/error.hpp"
#include "player/controls.hpp"
#include "player/keys.hpp"
#include "player/keys_json.hpp"

namespace cmd_keys {  // named, not anonymous: the unity build joins the command units

using panoptes::player::KeyBinding;
using panoptes::player::ViewMode;

struct Args {
  bool markdown = false, json = false;
  std::string mode;  // empty: every mode
};

// Consecutive bindings of one action and one description print as one row ("H, F1").
struct Row {
  std::string keys;
  const KeyBinding* binding;
};

std::vector<Row> rows() {
  std::vector<Row> out;
  for (const KeyBinding& b : panoptes::player::key_bindings()) {
    if (!out.empty() && out.back().binding->action == b.action && out.back().binding->description == b.description) {
      out.back().keys += ", " + std::string(b.key);
      continue;
    }
    out.push_back({std::string(b.key), &b});
  }
  return out;
}

std::string md_cell(std::string_view text) {
  std::string s;
  for (char c : text) s += c == '|' ? std::string("\\|") : std::string(1, c);
  return s;
}

std::string md_key(const std::string& keys) {
  std::string s = "`";
  for (char c : keys) s += c == ',' ? std::string("`,") : c == ' ' ? std::string(" `") : std::string(1, c);
  return md_cell(s + "`");
}

ViewMode parse_mode(const std::string& text) {
  for (ViewMode m : panoptes::player::kViewModes)
    if (text == panoptes::player::to_string(m)) return m;
  throw panoptes::Error("--mode \"" + text + "\": expected sphere, panorama or lattice");
}

void print_markdown(const std::optional<ViewMode>& mode) {
  using panoptes::player::description;
  if (mode) {
    std::printf("| Key | What it does (%s) |\n|---|---|\n", std::string(to_string(*mode)).c_str());
    for (const Row& r : rows()) {
      const auto d = description(*r.binding, *mode);
      if (!d.empty()) std::printf("| %s | %s |\n", md_key(r.keys).c_str(), md_cell(d).c_str());
    }
    return;
  }
  // One row per key: what it does with perspective frames, and in 360° modes only where that differs.
  std::printf("| Key | What it does | 360° panorama | 360° lattice / path |\n|---|---|---|---|\n");
  for (const Row& r : rows()) {
    const auto base = description(*r.binding, ViewMode::sphere);
    std::string cells[2];
    int i = 0;
    for (ViewMode m : {ViewMode::panorama, ViewMode::lattice}) {
      const auto d = description(*r.binding, m);
      cells[i++] = d.empty() ? "—" : d == base ? "" : md_cell(d);
    }
    std::printf("| %s | %s | %s | %s |\n", md_key(r.keys).c_str(), base.empty() ? "—" : md_cell(base).c_str(),
                cells[0].c_str(), cells[1].c_str());
  }
}

void print_text(const std::optional<ViewMode>& mode) {
  bool first = true;
  for (ViewMode m : panoptes::player::kViewModes) {
    if (mode && m != *mode) continue;
    std::printf("%s%s mode:\n", first ? "" : "\n", std::string(to_string(m)).c_str());
    first = false;
    for (const Row& r : rows()) {
      const auto d = panoptes::player::description(*r.binding, m);
      if (!d.empty()) std::printf("  %-16s %s\n", r.keys.c_str(), std::string(d).c_str());
    }
  }
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto args = std::make_shared<Args>();
  auto* sub = root.add_subcommand(
      "keys", "Print the player's key table (the one the window, headless scripts, Python and the browser use)");
  auto* md = sub->add_flag("--markdown", args->markdown,
                           "a Markdown table (docs/ui.md's key table is this output without --mode)");
  sub->add_flag("--json", args->json,
                "the keys.json document the web player reads (every mode; --mode adds \"mode\")")
      ->excludes(md);
  sub->add_option("--mode", args->mode,
                  "only what the keys do in this view mode: sphere (perspective frames), panorama (360° frames) "
                  "or lattice (walkable 360° lattice or path)");
  sub->callback([args] {
    std::optional<ViewMode> mode;
    if (!args->mode.empty()) mode = parse_mode(args->mode);
    if (args->json) {
      auto j = panoptes::player::keys_json();
      if (mode) j["mode"] = std::string(to_string(*mode));
      std::printf("%s\n", j.dump(2).c_str());
    } else if (args->markdown) {
      print_markdown(mode);
    } else {
      print_text(mode);
    }
  });
});

}  // namespace
