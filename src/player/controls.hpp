#pragma once
// One meaning per key for every front end (issue 30): what a key's action does in the database at hand
// (its view mode: perspective rig, 360° panorama, walkable 360° lattice or path) and the dispatch that
// does it — engine commands, walking relative to the view, the look-around's field of view. The window
// (ui), headless runs, export-path and Python's Player all call Controls, so `key=Up` from camera 13
// leads to the same camera everywhere; the browser gets the same rules as data (keys_json.hpp).
#include <string_view>

#include "player/keys.hpp"
#include "player/look.hpp"

namespace panoptes::player {

class Engine;
struct ScriptCommand;

/// How a database is looked at, which decides what the arrows, PageUp/PageDown and +/-/0 do.
enum class ViewMode {
  sphere,    ///< perspective frames (sphere, shells, Yin-Yang, ring, file rigs): keys follow the graph
  panorama,  ///< 360° (equirectangular) frames, not walkable: the graph, plus looking around
  lattice,   ///< 360° frames of a lattice or path rig: arrows and PageUp/PageDown walk relative to the view
};
/// All view modes, in the order keys.json lists them.
inline constexpr ViewMode kViewModes[] = {ViewMode::sphere, ViewMode::panorama, ViewMode::lattice};
/// The view mode of a database: panorama when the rig records projection "equirectangular", lattice when
/// it also records a lattice shape matching the camera count (lattice_shape()) or `path = true`.
ViewMode view_mode(const store::Manifest& manifest);
/// "sphere", "panorama" or "lattice".
std::string_view to_string(ViewMode mode);

/// What an action does in a view mode.
enum class Operation {
  none,        ///< nothing in this mode
  engine,      ///< Engine::apply(action)
  walk_forward, walk_back, walk_left, walk_right, walk_up, walk_down,  ///< walk_keeping_view()
  fov_narrow,  ///< look-around field of view ÷ kKeyFovFactor
  fov_widen,   ///< field of view × kKeyFovFactor
  fov_reset,   ///< field of view back to Look{}.fov_deg
  front_end,   ///< executed by the front end itself (magnify, full screen, screenshot, help, quit, ...)
};
/// Field-of-view factor of one +/- key press in 360° streams (the wheel uses kWheelFovFactor per notch).
inline constexpr double kKeyFovFactor = 1.25;
inline constexpr double kWheelFovFactor = 1.15;

Operation operation(Action action, ViewMode mode);
/// Name of what `action` does in `mode` as keys.json writes it: the action's own name for engine and
/// front-end operations, "walk_forward", "fov_narrow", ...; empty for Operation::none.
std::string_view operation_name(Action action, ViewMode mode);
/// The help line of a key binding as it acts in `mode` (the binding's own description unless the mode
/// changes what it does, e.g. Up walks forward in a lattice); empty when the key does nothing there.
std::string_view description(const KeyBinding& binding, ViewMode mode);
/// Whether `action` can change anything in this database as `mode` dispatches it: false where the
/// operation is none, for the parameter-axis keys of a database without parameter axes, for Z / X where
/// no camera of the navigation graph has a closer / farther neighbour, and for C on perspective frames
/// (there it only says that the views are fixed). The help overlays (window, browser) list usable keys.
bool usable(Action action, ViewMode mode, const store::Manifest& manifest);
/// What every front end says when a key's action is refused in `mode` (Controls::apply returned
/// refused): the binding's own text (keys.cpp), a walk's "no camera that way", the lattice's "does
/// nothing here", or, with a manifest, the database's reason (one camera shell, no parameter axes).
/// Empty when a refusal needs no words (a speed or field of view at its limit). keys.json publishes it.
std::string_view refusal(Action action, ViewMode mode, const store::Manifest* manifest = nullptr);
/// True for the walk_* operations.
bool is_walk(Operation op);
/// The Walk of a walk_* operation.
Walk walk_of(Operation op);

/// The key dispatch over one Engine: the view mode, the look (360° streams) and every action and script
/// command applied the same way for all front ends.
class Controls {
 public:
  /// Result of apply(): done, refused (nothing that way / nothing changed), or left to the front end.
  enum class Result { done, refused, front_end };

  explicit Controls(Engine& engine, Look look = {});
  ViewMode mode() const { return mode_; }
  bool is_360() const { return mode_ != ViewMode::sphere; }
  const Look& look() const { return look_; }
  /// Sets the look (clamped: pitch ±89°, fov 20..120°, yaw wrapped).
  void set_look(const Look& look);
  /// The look for front ends that turn it continuously (a drag, the wheel); they keep it clamped().
  Look& mutable_look() { return look_; }
  /// Applies a key's action as `operation(action, mode())` says.
  Result apply(Action action);
  /// refusal(action, mode(), the engine's manifest): the text to show when apply(action) was refused.
  std::string_view refusal(Action action) const;
  /// Walks relative to the view (any mode with a graph); false when there is no camera that way.
  bool walk(Walk walk);
  /// Applies a script command (key= through apply(); look=, walk=, seek=, camera=, ...); false when it
  /// changed nothing it should have (no such edge, unknown task name, ...). `end` returns true.
  bool run(const ScriptCommand& command);

 private:
  Engine& engine_;
  ViewMode mode_;
  Look look_;
};

}  // namespace panoptes::player
