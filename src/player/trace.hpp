#pragma once
// Traces of scripted runs (issue 30): after every script command, the selection (camera, task, frame),
// the active parameter axis, the camera's shell, the look and what a refused key said, one JSON line each, so the window, headless runs, Python and the browser can be checked
// against each other (`panoptes play --script S --trace FILE`). Format: docs/web.md, "Traces".
#include <filesystem>
#include <fstream>
#include <string>

#include "player/engine.hpp"
#include "player/look.hpp"

namespace panoptes::player {

struct ScriptCommand;
class Controls;

/// The state after one script command.
struct TraceStep {
  int step = 0;          ///< index of the command in the script (0-based; `end` is not traced)
  int line = 0;          ///< the command's line in the script file (1-based)
  std::string command;   ///< the command as written back by describe(), e.g. "key=Up"
  Selection selection;   ///< camera, task, frame after the command
  Look look;             ///< the view after the command (360° streams)
  int axis = -1;         ///< the active parameter axis (Engine::active_axis; -1 without axes)
  int shell = 0;         ///< the shown camera's shell (manifest label; 0 = outermost or only)
  std::string refusal;   ///< what the front end said when the command's key was refused (Controls::refusal)
};

/// The step of a command just applied: everything read from the engine and the dispatch, so the
/// window and headless runs trace the same fields. `refusal` as the front end showed it.
TraceStep trace_step(int step, const ScriptCommand& command, const Engine& engine, const Controls& controls,
                     std::string refusal = {});

/// One JSON line (no newline): {"step":0,"line":3,"command":"key=Up","camera":16,"task":0,"frame":0,
/// "axis":0,"shell":0,"look":[0,0,90]} and "refusal":"..." when a key was refused.
std::string to_json_line(const TraceStep& step);

/// Writes trace lines to a file as they come (flushed per line, so a window closed early keeps them).
class TraceWriter {
 public:
  /// Creates (truncates) `path`. Throws FileError when it cannot.
  explicit TraceWriter(const std::filesystem::path& path);
  /// Appends one line. Throws FileError when writing fails.
  void write(const TraceStep& step);

 private:
  std::filesystem::path path_;
  std::ofstream out_;
};

}  // namespace panoptes::player
