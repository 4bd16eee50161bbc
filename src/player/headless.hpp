#pragma once
// Scripted, window-less playback: a script of timed commands runs through the Engine on a virtual
// clock at the database's frame rate, so a run is deterministic (the same frames are shown whatever
// the machine's speed). Used by `panoptes play --headless`, `panoptes export-path`, tests, benchmarks.
//
// Script format (one command per line; '#' starts a comment; blank lines ignored):
//   t=SECONDS key=NAME           a key of the key table (keys.hpp), e.g. key=Right, key=Shift+Tab, key=3
//   t=SECONDS seek=FRAME         jump to a frame
//   t=SECONDS camera=ID          jump to a camera
//   t=SECONDS task=ID|NAME       select a task by id or by name
//   t=SECONDS axis=NAME:DELTA    step parameter axis NAME by DELTA (e.g. axis=isovalue:+1)
//   t=SECONDS snap=X,Y,Z         snap to the camera nearest the direction (as a mouse drag does)
//   t=SECONDS look=YAW,PITCH,FOV set the view inside a 360° stream (degrees; player/look.hpp)
//   t=SECONDS walk=DIR           walk to the neighbouring camera in direction DIR relative to the view:
//                                forward, back, left, right, up or down (lattice and path rigs)
//   t=SECONDS speed=FACTOR       playback speed (0.25 .. 8)
//   t=SECONDS play | pause       set the play state
//   t=SECONDS end                stop the run here (no frame is shown at this time)
// Without `end` (and without an explicit duration) the run ends once the last command's effect has
// been shown; without any command it plays the database once.
// Times are virtual seconds from the start, must not decrease and are at most kMaxScriptSeconds.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/vec3.hpp"
#include "player/engine.hpp"
#include "player/keys.hpp"
#include "player/look.hpp"
#include "player/trace.hpp"

namespace panoptes::player {

/// Latest time a script command may have (virtual seconds: one day).
inline constexpr double kMaxScriptSeconds = 86400;

/// One parsed script line.
struct ScriptCommand {
  enum class Kind { key, seek, camera, task, axis, snap, speed, play, pause, end, look, walk };
  double t = 0;
  Kind kind = Kind::key;
  Action action = Action::none;  ///< kind == key
  std::string key;               ///< kind == key: the key name as written
  int value = 0;                 ///< seek frame, camera id, task id (-1: by name), axis delta
  std::string name;              ///< task name or axis name
  Vec3 direction;                ///< kind == snap
  double speed = 1;              ///< kind == speed
  Look look;                     ///< kind == look
  Walk walk = Walk::forward;     ///< kind == walk
  int line = 0;                  ///< 1-based line number in the script
};

/// The command as a script line would write it (without the time), e.g. "key=Up", "walk=forward".
std::string describe(const ScriptCommand& command);

/// Checks a parsed script against a database: camera ids, task ids and names, axis names and seek
/// frames must exist (a typo must not be silently ignored). Throws Error naming the line, the value and
/// the valid range.
void check_script(const std::vector<ScriptCommand>& script, const store::Manifest& manifest);

/// Parses a script. `source` names it in errors. Throws Error naming the line and the bad text.
std::vector<ScriptCommand> parse_script(const std::string& text, const std::string& source = "script");
/// Reads and parses a script file. Throws FileError when it cannot be read, Error on bad syntax.
std::vector<ScriptCommand> read_script(const std::filesystem::path& path);

/// One displayed frame of a headless run.
struct DisplayedFrame {
  int index = 0;        ///< display tick (0, 1, 2, ...)
  double t = 0;         ///< virtual time of the tick, seconds
  ShownFrame shown;
  Look look;  ///< the view at this tick (applies to 360° streams: see perspective_cutout)
};

/// Options of run_headless.
struct HeadlessOptions {
  EngineOptions engine;           ///< time_source is replaced by the run's virtual clock
  std::vector<ScriptCommand> script;
  /// Run length in virtual seconds (ticks with t < duration are shown); unset = until an `end`
  /// command, else through the tick that shows the last command, else frame_count / fps.
  std::optional<double> duration;
  /// Writes every displayed frame as DIR/frame_NNNNNN.png (NNNNNN = display tick) if set.
  std::optional<std::filesystem::path> frames_out;
  /// Writes the statistics JSON (engine statistics + the list of displayed frames) if set.
  std::optional<std::filesystem::path> stats_out;
  /// Called for every displayed frame (e.g. to encode it), after frames_out is written.
  std::function<void(const DisplayedFrame&)> on_frame;
  /// Simulated display: wait for prefetch to go idle before each tick, as a real display would give
  /// the prefetch threads one frame period of time (makes cache hits on switches reproducible).
  bool wait_prefetch_each_tick = true;
  Look look;  ///< initial view (look= commands change it)
  /// Starting playback speed; 0 = the short-run rule every front end uses (starting_speed()).
  double speed = 1;
  /// Writes the trace (the state after each script command, trace.hpp) as JSON lines if set.
  std::optional<std::filesystem::path> trace_out;
};

/// Summary of a headless run.
struct HeadlessResult {
  int frames_displayed = 0;
  int placeholders = 0;   ///< displayed frames whose status was not ok
  Statistics statistics;
  std::vector<Selection> shown;  ///< selection of every displayed frame, in order
  std::vector<Look> looks;       ///< the view of every displayed frame, in order
  std::vector<TraceStep> trace;  ///< the state after every script command but `end`, in order
};

/// Runs a script through an Engine over the database in dir. Display ticks are at t = k / fps
/// (k = 0, 1, ...); at tick k the playback clock advances to t, then every command with time ≤ t
/// is applied in order through Controls (the key dispatch every front end shares), then the frame is taken (so `t=1 seek=10` shows frame 10 at t = 1). Throws FileError/Error for a bad database or an unwritable output.
HeadlessResult run_headless(const std::filesystem::path& dir, const HeadlessOptions& options);

}  // namespace panoptes::player
