// `panoptes play DB`: the interactive player (SDL2 window, module ui) or, with --headless, a scripted
// run of the same engine that writes the frames that would have been shown and the statistics.
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include "app/command.hpp"
#include "app/task_option.hpp"
#include "core/error.hpp"
#include "player/controls.hpp"
#include "player/headless.hpp"
#include "player/keys_json.hpp"
#include "store/database.hpp"
#ifdef PANOPTES_HAVE_UI
#include "ui/window_app.hpp"
#endif

namespace cmd_play {  // named, not anonymous: the unity build joins the command units

struct PlayArgs {
  std::string db;
  bool headless = false;
  std::string script, frames_out, stats, trace;
  bool keys_json = false;
  double duration = 0;
  int camera = 0, frame = 0;
  std::string task = "0";  // an index or a name
  double speed = 0;  // 0 = automatic: the short-run rule (player/playback_rule.hpp)
  bool paused = false, no_loop = false;
  double cache_mb = 0;
  bool no_prefetch = false;
  int prefetch_threads = 2, readers = 32;
  // window only
  int width = 0, height = 0;
  bool fullscreen = false, software = false, no_vsync = false;
  int max_frames = 0;
  std::string screenshot_on_exit, output_dir = ".";
  std::string latency_log;
};

std::string key_table() {
  namespace player = panoptes::player;
  std::string text = "Keys (window; the same names are used in scripts as key=NAME):\n";
  for (const auto& b : player::key_bindings()) {
    char line[200];
    std::snprintf(line, sizeof line, "  %-13s %s\n", std::string(b.key).c_str(), std::string(b.description).c_str());
    text += line;
  }
  text += "In 360-degree databases (panorama, lattice) + / - / 0 change the field of view; inside a lattice or\n"
          "along a path the keys act as follows:\n";
  for (const auto& b : player::key_bindings()) {
    const auto mode = player::ViewMode::lattice;
    if (player::operation(b.action, mode) == player::operation(b.action, player::ViewMode::panorama)) continue;
    char line[200];
    const std::string_view d = player::description(b, mode);
    std::snprintf(line, sizeof line, "  %-13s %s\n", std::string(b.key).c_str(),
                  d.empty() ? "nothing" : std::string(d).c_str());
    text += line;
  }
  return text;
}

void run_play(const PlayArgs& a) {
  namespace player = panoptes::player;
  if (a.keys_json) {
    // The key table as the browser receives it (docs/web.md); with a database, its view mode too.
    if (a.db.empty()) {
      std::printf("%s\n", player::keys_json().dump(2).c_str());
    } else {
      const auto db = panoptes::store::Database::open(a.db);
      std::printf("%s\n", player::keys_json(&db.manifest()).dump(2).c_str());
    }
    return;
  }
  if (a.db.empty()) throw panoptes::Error("play: db is required (a database directory); run panoptes play --help for more information");
  if (!std::filesystem::exists(std::filesystem::path(a.db) / "panoptes.json"))
    throw panoptes::FileError(a.db, std::filesystem::exists(a.db)
                                        ? "not a Panoptes database (no panoptes.json inside)"
                                        : "no such database directory");
  if (a.headless) {
    player::HeadlessOptions o;
    o.engine.camera = a.camera;
    o.engine.task = panoptes::app::resolve_task_option(a.db, a.task);
    o.engine.frame = a.frame;
    o.engine.start_playing = !a.paused;
    o.engine.loop = !a.no_loop;
    o.engine.cache_bytes = std::size_t(a.cache_mb * 1024 * 1024);
    o.engine.prefetch = !a.no_prefetch;
    o.engine.prefetch_threads = a.prefetch_threads;
    o.engine.reader_pool_capacity = a.readers;
    if (!a.script.empty()) o.script = player::read_script(a.script);
    if (a.duration > 0) o.duration = a.duration;
    if (!a.frames_out.empty()) o.frames_out = a.frames_out;
    if (!a.stats.empty()) o.stats_out = a.stats;
    if (!a.trace.empty()) o.trace_out = a.trace;
    o.speed = a.speed;  // 0: the short-run rule, as the window starts
    const auto r = player::run_headless(a.db, o);
    const auto lat = [&] {
      std::vector<double> v;
      for (const auto& s : r.statistics.switches) v.push_back(s.latency_ms);
      return player::summarize(v);
    }();
    std::printf("played %d frames (%d placeholders); %zu switches, latency p50 %.2f ms, max %.2f ms; "
                "cache hits %lld / misses %lld\n",
                r.frames_displayed, r.placeholders, lat.count, lat.p50, lat.max,
                static_cast<long long>(r.statistics.cache_hits), static_cast<long long>(r.statistics.cache_misses));
    return;
  }
#ifdef PANOPTES_HAVE_UI
  panoptes::ui::WindowOptions w;
  w.width = a.width;
  w.height = a.height;
  w.fullscreen = a.fullscreen;
  w.software_renderer = a.software;
  w.vsync = !a.no_vsync;
  w.camera = a.camera;
  w.task = panoptes::app::resolve_task_option(a.db, a.task);
  w.frame = a.frame;
  w.speed = a.speed;
  w.paused = a.paused;
  w.loop = !a.no_loop;
  w.cache_bytes = std::size_t(a.cache_mb * 1024 * 1024);
  w.script = a.script;
  w.trace = a.trace;
  w.max_frames = a.max_frames;
  w.screenshot_on_exit = a.screenshot_on_exit;
  w.output_dir = a.output_dir;
  w.latency_log = a.latency_log;
  const auto r = panoptes::ui::run_window(a.db, w);
  if (!r.summary.empty()) std::printf("%s\n", r.summary.c_str());
#else
  throw panoptes::Error(
      "the window front end is not built in this panoptes (SDL2 / Dear ImGui were not found at build "
      "time); use `panoptes play " + a.db + " --headless --script FILE --frames-out DIR`");
#endif
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto args = std::make_shared<PlayArgs>();
  auto* sub = root.add_subcommand(
      "play",
      "Play a movie database: switch cameras and tasks while time plays (window), or run a script of "
      "timed key presses without a window (--headless)");
  sub->footer(key_table() +
              "\nIn 360-degree databases (equirectangular frames) the keys act on the view: left drag looks around,\n"
              "+ / - / 0 and the wheel set the field of view, C turns toward the strongest signal. On a lattice or\n"
              "path rig the arrows walk forward / back / left / right relative to where you look and PageUp /\n"
              "PageDown walk up / down (toward the sky / the ground); H in the window shows the keys as they act there.\n" +
              "\nScript lines (headless and --script): `t=SECONDS key=NAME`, `t=S seek=FRAME`, `t=S camera=ID`,\n"
              "`t=S task=ID|NAME`, `t=S axis=NAME:DELTA`, `t=S snap=X,Y,Z`, `t=S look=YAW,PITCH,FOV`, `t=S walk=DIR`,\n"
              "`t=S speed=F`, `t=S play|pause|end`;\n"
              "'#' starts a comment. See docs/player.md.");
  sub->add_option("db", args->db, "Database directory (holds panoptes.json)");
  sub->add_flag("--keys-json", args->keys_json,
                "Print the key table as JSON (the document the web player reads, docs/web.md) and exit; with DB "
                "also the database's view mode");
  sub->add_option("--trace", args->trace,
                  "With --script: write the camera, task, frame and look after each script command as JSON lines "
                  "(window and headless; docs/web.md)");
  sub->add_flag("--headless", args->headless, "Run without a window: play the script on a virtual clock");
  sub->add_option("--script", args->script, "Script of timed commands (headless; in the window: injected keys)")
      ->check(CLI::ExistingFile);
  sub->add_option("--frames-out", args->frames_out, "Headless: write every shown frame as DIR/frame_NNNNNN.png");
  sub->add_option("--stats", args->stats, "Headless: write statistics (switch latency, decode time, cache) as JSON");
  sub->add_option("--duration", args->duration,
                  "Headless: seconds of virtual time to play (default: until the script's last command is "
                  "shown, or the whole database once without a script)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--camera", args->camera, "Start camera id")->check(CLI::NonNegativeNumber);
  sub->add_option("--task", args->task, "Start task: its id or its name (e.g. p+s)");
  sub->add_option("--frame", args->frame, "Start frame")->check(CLI::NonNegativeNumber);
  sub->add_option("--speed", args->speed,
                  "Playback speed factor (0.25 .. 8) of the database's playback rate (default: x1, slowed down "
                  "so that a run of few frames lasts at least 4 s, as in every front end)")
      ->check(CLI::Range(0.25, 8.0));
  sub->add_flag("--paused", args->paused, "Start paused");
  sub->add_flag("--no-loop", args->no_loop, "Stop at the end instead of looping");
  sub->add_option("--cache-mb", args->cache_mb, "Frame cache cap in MiB (default: min(1/8 of RAM, 2 GiB))")
      ->check(CLI::NonNegativeNumber);
  sub->add_flag("--no-prefetch", args->no_prefetch, "Headless: disable background prefetch (for comparisons)");
  sub->add_option("--prefetch-threads", args->prefetch_threads, "Headless: prefetch threads")->check(CLI::Range(0, 64));
  sub->add_option("--readers", args->readers, "Headless: maximum open movie readers")->check(CLI::Range(2, 100000));
  sub->add_option("--width", args->width, "Window width in pixels (default: the frame's aspect filling most of the display)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--height", args->height, "Window height in pixels")->check(CLI::NonNegativeNumber);
  sub->add_flag("--fullscreen", args->fullscreen, "Start in full screen");
  sub->add_flag("--software", args->software, "Use SDL's software renderer");
  sub->add_flag("--no-vsync", args->no_vsync, "Do not wait for the display refresh");
  sub->add_option("--max-frames", args->max_frames, "Window: close after this many presented frames")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--screenshot-on-exit", args->screenshot_on_exit, "Window: save the final window image (frame, HUD and legend, also after one frame) as PNG");
  sub->add_option("--output-dir", args->output_dir, "Window: directory for screenshots (S) and recordings (R)");
  sub->add_option("--latency-log", args->latency_log,
                  "Window: write every key / click / wheel turn's latency to FILE, one line each (from the input's "
                  "own X server timestamp to the presented frame, monotonic ms; what the HUD shows under details)");
  sub->callback([args] { run_play(*args); });
});

}  // namespace
