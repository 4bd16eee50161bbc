#include "player/headless.hpp"

#include <algorithm>
#include <array>
#include <iterator>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/file_read.hpp"
#include "core/png.hpp"
#include "player/controls.hpp"
#include "player/playback_rule.hpp"

namespace panoptes::player {
namespace {

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return std::string(s.substr(b, e - b + 1));
}

double parse_double(const std::string& text, const std::string& where) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used != text.size() || !std::isfinite(v)) throw std::invalid_argument("trailing");
    return v;
  } catch (const std::exception&) {
    throw Error(where + ": expected a number, got \"" + text + "\"");
  }
}

int parse_int(const std::string& text, const std::string& where) {
  try {
    std::size_t used = 0;
    const long v = std::stol(text, &used);
    if (used != text.size() || v < -(1L << 30) || v > (1L << 30)) throw std::invalid_argument("trailing");
    return int(v);
  } catch (const std::exception&) {
    throw Error(where + ": expected an integer, got \"" + text + "\"");
  }
}

constexpr const char* kWalkNames[] = {"forward", "back", "left", "right", "up", "down"};

}  // namespace

std::string describe(const ScriptCommand& c) {
  using K = ScriptCommand::Kind;
  switch (c.kind) {
    case K::key: return "key=" + c.key;
    case K::seek: return "seek=" + std::to_string(c.value);
    case K::camera: return "camera=" + std::to_string(c.value);
    case K::task: return "task=" + (c.value >= 0 ? std::to_string(c.value) : c.name);
    case K::axis: return "axis=" + c.name + ":" + std::to_string(c.value);
    case K::snap: {
      char b[96];
      std::snprintf(b, sizeof b, "snap=%g,%g,%g", c.direction.x, c.direction.y, c.direction.z);
      return b;
    }
    case K::speed: return "speed=" + std::to_string(c.speed);
    case K::play: return "play";
    case K::pause: return "pause";
    case K::end: return "end";
    case K::look: {
      char b[96];
      std::snprintf(b, sizeof b, "look=%g,%g,%g", c.look.yaw_deg, c.look.pitch_deg, c.look.fov_deg);
      return b;
    }
    case K::walk: return std::string("walk=") + kWalkNames[int(c.walk)];
  }
  return "?";
}


std::vector<ScriptCommand> parse_script(const std::string& text, const std::string& source) {
  std::vector<ScriptCommand> out;
  std::istringstream in(text);
  std::string raw;
  int line_no = 0;
  double last_t = 0;
  while (std::getline(in, raw)) {
    ++line_no;
    const std::string where = source + ":" + std::to_string(line_no);
    std::string line = trim(raw.substr(0, raw.find('#')));
    if (line.empty()) continue;
    std::istringstream words(line);
    std::string word;
    ScriptCommand c;
    c.line = line_no;
    bool have_t = false, have_command = false;
    while (words >> word) {
      const auto eq = word.find('=');
      const std::string key = word.substr(0, eq), value = eq == std::string::npos ? "" : word.substr(eq + 1);
      if (key == "t" && eq != std::string::npos) {
        c.t = parse_double(value, where);
        if (c.t < 0) throw Error(where + ": time t=" + value + " is negative");
        // A run shows every tick up to the last command: an absurd time would play for ever.
        if (c.t > kMaxScriptSeconds)
          throw Error(where + ": time t=" + value + " is beyond the limit of " + std::to_string(int(kMaxScriptSeconds)) +
                      " s");
        have_t = true;
        continue;
      }
      if (have_command) throw Error(where + ": more than one command on the line (\"" + word + "\")");
      have_command = true;
      using K = ScriptCommand::Kind;
      if (key == "key") {
        // Key names contain no spaces; "Shift+Tab" etc. are single words.
        const auto action = action_for_key(value);
        if (!action) throw Error(where + ": unknown key \"" + value + "\" (see `panoptes play --help` or docs/player.md)");
        c.kind = K::key, c.action = *action, c.key = value;
      } else if (key == "seek") {
        c.kind = K::seek, c.value = parse_int(value, where);
        if (c.value < 0) throw Error(where + ": seek frame " + value + " is negative");
      } else if (key == "camera") {
        c.kind = K::camera, c.value = parse_int(value, where);
      } else if (key == "task") {
        c.kind = K::task;
        if (!value.empty() && value.find_first_not_of("0123456789") == std::string::npos)
          c.value = parse_int(value, where);
        else if (!value.empty())
          c.value = -1, c.name = value;
        else
          throw Error(where + ": task= needs a task id or name");
      } else if (key == "axis") {
        const auto colon = value.rfind(':');
        if (colon == std::string::npos || colon == 0)
          throw Error(where + ": expected axis=NAME:DELTA (e.g. axis=isovalue:+1), got \"" + word + "\"");
        c.kind = K::axis, c.name = value.substr(0, colon);
        std::string delta = value.substr(colon + 1);
        if (!delta.empty() && delta[0] == '+') delta.erase(0, 1);
        c.value = parse_int(delta, where);
      } else if (key == "snap") {
        std::array<double, 3> v{};
        std::istringstream parts(value);
        std::string part;
        int n = 0;
        while (std::getline(parts, part, ',')) {
          if (n == 3) throw Error(where + ": expected snap=X,Y,Z, got \"" + word + "\"");
          v[std::size_t(n++)] = parse_double(part, where);
        }
        if (n != 3) throw Error(where + ": expected snap=X,Y,Z, got \"" + word + "\"");
        c.kind = K::snap, c.direction = {v[0], v[1], v[2]};
        if (norm(c.direction) == 0) throw Error(where + ": snap direction is the zero vector");
      } else if (key == "look") {
        std::array<double, 3> v{};
        std::istringstream parts(value);
        std::string part;
        int n = 0;
        while (std::getline(parts, part, ',')) {
          if (n == 3) throw Error(where + ": expected look=YAW,PITCH,FOV (degrees), got \"" + word + "\"");
          v[std::size_t(n++)] = parse_double(part, where);
        }
        if (n != 3) throw Error(where + ": expected look=YAW,PITCH,FOV (degrees), got \"" + word + "\"");
        if (!(v[1] >= -89 && v[1] <= 89) || !(v[2] >= 20 && v[2] <= 120) || !std::isfinite(v[0]))
          throw Error(where + ": look=" + value + ": expected pitch in -89..89 and field of view in 20..120 degrees");
        c.kind = K::look, c.look = {v[0], v[1], v[2]};
      } else if (key == "walk") {
        const auto* it = std::find(std::begin(kWalkNames), std::end(kWalkNames), value);
        if (it == std::end(kWalkNames))
          throw Error(where + ": walk=" + value + ": expected forward, back, left, right, up or down");
        c.kind = K::walk, c.walk = Walk(it - std::begin(kWalkNames));
      } else if (key == "speed") {
        c.kind = K::speed, c.speed = parse_double(value, where);
        if (c.speed < 0.25 || c.speed > 8) throw Error(where + ": speed " + value + " is outside 0.25 .. 8");
      } else if (word == "play") {
        c.kind = K::play;
      } else if (word == "pause") {
        c.kind = K::pause;
      } else if (word == "end") {
        c.kind = K::end;
      } else {
        throw Error(where + ": unknown command \"" + word +
                    "\" (expected key=, seek=, camera=, task=, axis=, snap=, look=, walk=, speed=, play, pause or end)");
      }
    }
    if (!have_t) throw Error(where + ": missing time (lines look like `t=0.5 key=Right`)");
    if (!have_command) throw Error(where + ": a time without a command");
    if (c.t < last_t) throw Error(where + ": time t=" + std::to_string(c.t) + " is before the previous line's");
    last_t = c.t;
    out.push_back(std::move(c));
  }
  return out;
}

void check_script(const std::vector<ScriptCommand>& script, const store::Manifest& m) {
  using K = ScriptCommand::Kind;
  for (const ScriptCommand& c : script) {
    const std::string where = "script line " + std::to_string(c.line) + ": ";
    const auto range = [](int n) { return n > 0 ? "0.." + std::to_string(n - 1) : std::string("none"); };
    if (c.kind == K::camera && (c.value < 0 || c.value >= m.camera_count()))
      throw Error(where + "camera " + std::to_string(c.value) + " does not exist; the database has cameras " +
                  range(m.camera_count()));
    if (c.kind == K::task && c.value >= 0 && c.value >= m.task_count())
      throw Error(where + "task " + std::to_string(c.value) + " does not exist; the database has tasks " +
                  range(m.task_count()));
    if (c.kind == K::task && c.value < 0 && m.find_task(c.name) < 0) {
      std::string names;
      for (const auto& t : m.tasks) names += (names.empty() ? "" : ", ") + t.name;
      throw Error(where + "no task named \"" + c.name + "\"; the database has: " + names);
    }
    if (c.kind == K::axis && m.find_axis(c.name) < 0) {
      std::string names;
      for (const auto& a : m.axes) names += (names.empty() ? "" : ", ") + a.name;
      throw Error(where + "no parameter axis named \"" + c.name + "\"; the database has: " +
                  (names.empty() ? std::string("none") : names));
    }
    if (c.kind == K::seek && c.value >= std::max(1, m.frames_written))
      throw Error(where + "seek frame " + std::to_string(c.value) + " does not exist; the database has frames " +
                  range(m.frames_written));
  }
}

std::vector<ScriptCommand> read_script(const std::filesystem::path& path) {
  return parse_script(read_regular_file(path.string(), 16u << 20, "script"), path.string());
}

HeadlessResult run_headless(const std::filesystem::path& dir, const HeadlessOptions& options) {
  VirtualClock clock;
  EngineOptions eo = options.engine;
  eo.time_source = clock.source();
  Engine engine(dir, eo);
  check_script(options.script, engine.manifest());
  const double fps = engine.fps();
  engine.set_speed(options.speed > 0 ? options.speed
                                     : starting_speed(engine.frame_count(), fps, engine.manifest().playback_fps));

  double duration = 0;
  if (options.duration) {
    duration = *options.duration;
    if (!(duration > 0)) throw Error("duration must be positive, got " + std::to_string(duration));
  } else if (options.script.empty()) {
    duration = engine.frame_count() / fps;  // no script: play the database once
  } else {
    duration = options.script.back().t + 1 / fps;
    for (const auto& c : options.script)
      if (c.kind == ScriptCommand::Kind::end) {
        duration = c.t;
        break;
      }
  }
  const long ticks = std::max(1L, long(std::ceil(duration * fps - 1e-6)));
  if (ticks > 10'000'000) throw Error("run of " + std::to_string(duration) + " s is too long (over 10^7 frames)");

  if (options.frames_out) {
    std::error_code ec;
    std::filesystem::create_directories(*options.frames_out, ec);
    if (ec) throw FileError(options.frames_out->string(), "cannot create the frames directory: " + ec.message());
  }

  HeadlessResult result;
  Controls controls(engine, options.look);
  std::optional<TraceWriter> trace;
  if (options.trace_out) trace.emplace(*options.trace_out);
  int step = 0;
  nlohmann::json displayed = nlohmann::json::array(), commands = nlohmann::json::array();
  std::size_t next_command = 0;
  for (long k = 0; k < ticks; ++k) {
    const double t = double(k) / fps;
    // A real display gives the prefetch threads one frame period between ticks; waiting for them to
    // go idle models that deterministically (the shown frames never depend on it, only cache hits).
    if (options.wait_prefetch_each_tick) engine.wait_prefetch_idle();
    clock.set(t);
    engine.tick();
    bool ended = false;
    while (next_command < options.script.size() && options.script[next_command].t <= t + 1e-9) {
      const ScriptCommand& c = options.script[next_command++];
      if (c.kind == ScriptCommand::Kind::end) ended = true;
      const bool applied = controls.run(c);
      if (c.kind != ScriptCommand::Kind::end) {
        // A refused key says why, as the window's status line does (the trace compares them).
        const bool refused_key = c.kind == ScriptCommand::Kind::key && !applied;
        const TraceStep ts = trace_step(step++, c, engine, controls, refused_key ? std::string(controls.refusal(c.action)) : "");
        if (trace) trace->write(ts);
        result.trace.push_back(ts);
      }
      commands.push_back({{"t", c.t}, {"line", c.line}, {"command", describe(c)}, {"applied", applied}, {"tick", k}});
    }
    if (ended) break;
    DisplayedFrame df;
    df.index = int(k);
    df.t = t;
    df.shown = engine.current_frame();
    df.look = controls.look();
    const auto& s = df.shown.selection;
    result.shown.push_back(s);
    result.looks.push_back(df.look);
    ++result.frames_displayed;
    if (df.shown.status != FrameStatus::ok) ++result.placeholders;
    displayed.push_back({{"index", k}, {"t", t}, {"camera", s.camera}, {"task", s.task}, {"frame", s.frame},
                         {"status", std::string(to_string(df.shown.status))}, {"cache_hit", df.shown.cache_hit},
                         {"look", {df.look.yaw_deg, df.look.pitch_deg, df.look.fov_deg}}});
    if (options.frames_out) {
      char name[32];
      std::snprintf(name, sizeof name, "frame_%06ld.png", k);
      write_png((*options.frames_out / name).string(), video::MovieReader::to_rgba(*df.shown.frame));
    }
    if (options.on_frame) options.on_frame(df);
  }
  engine.wait_prefetch_idle();
  result.statistics = engine.statistics();
  if (options.stats_out) {
    nlohmann::json j = to_json(result.statistics);
    j["database"] = dir.string();
    j["fps"] = fps;
    j["frame_count"] = engine.frame_count();
    j["frames_displayed"] = result.frames_displayed;
    j["placeholders"] = result.placeholders;
    j["commands"] = std::move(commands);
    j["displayed"] = std::move(displayed);
    std::ofstream out(*options.stats_out);
    if (!out) throw FileError(options.stats_out->string(), "cannot create the statistics file");
    out << j.dump(2) << '\n';
    if (!out) throw FileError(options.stats_out->string(), "cannot write the statistics file");
  }
  return result;
}

}  // namespace panoptes::player
