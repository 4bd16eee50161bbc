#pragma once
// Traces of scripted runs (issue 30): after every script command, the selection (camera, task, frame)
// and the look, one JSON line each, so the window, headless runs, Python and the browser can be checked
// against each other (`panoptes play --script S --trace FILE`). Format: docs/web.md, "Traces".
#include <filesystem>
#include <fstream>
#include <string>

#include "player/engine.hpp"
#include "player/look.hpp"

namespace panoptes::player {

struct ScriptCommand;

/// The state after one script command.
struct TraceStep {
  int step = 0;          ///< index of the command in the script (0-based; `end` is not traced)
  int line = 0;          ///< the command's line in the script file (1-based)
  std::string command;   ///< the command as written back by describe(), e.g. "key=Up"
  Selection selection;   ///< camera, task, frame after the command
  Look look;             ///< the view after the command (360° streams)
};

/// One JSON line (no newline): {"step":0,"line":3,"command":"key=Up","camera":16,"task":0,"frame":0,
/// "look":[0,0,90]}.
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
