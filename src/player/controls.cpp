#include "player/controls.hpp"

#include <algorithm>

#include "player/engine.hpp"
#include "player/headless.hpp"

namespace panoptes::player {

ViewMode view_mode(const store::Manifest& m) {
  if (!is_equirectangular(m)) return ViewMode::sphere;
  const auto& p = m.rig.parameters;
  const bool path = p.contains("path") && p["path"] == true;
  return lattice_shape(m)[0] > 0 || path ? ViewMode::lattice : ViewMode::panorama;
}

std::string_view to_string(ViewMode mode) {
  switch (mode) {
    case ViewMode::sphere: return "sphere";
    case ViewMode::panorama: return "panorama";
    case ViewMode::lattice: return "lattice";
  }
  return "sphere";
}

Operation operation(Action a, ViewMode mode) {
  if (a == Action::none) return Operation::none;
  if (mode == ViewMode::lattice) {
    // Inside a lattice (or along a path) the arrows and PageUp/PageDown walk relative to the view; the
    // parameter-axis keys have nothing left to step, so A does nothing there.
    switch (a) {
      case Action::camera_up: return Operation::walk_forward;
      case Action::camera_down: return Operation::walk_back;
      case Action::camera_left: return Operation::walk_left;
      case Action::camera_right: return Operation::walk_right;
      case Action::axis_up: return Operation::walk_up;
      case Action::axis_down: return Operation::walk_down;
      case Action::next_axis:
      case Action::previous_axis: return Operation::none;
      default: break;
    }
  }
  if (mode != ViewMode::sphere) {
    // A 360° frame is shown as a perspective cut-out: magnifying it is narrowing its field of view.
    switch (a) {
      case Action::zoom_in: return Operation::fov_narrow;
      case Action::zoom_out: return Operation::fov_widen;
      case Action::zoom_reset: return Operation::fov_reset;
      default: break;
    }
  }
  return is_engine_action(a) ? Operation::engine : Operation::front_end;
}

std::string_view operation_name(Action a, ViewMode mode) {
  switch (operation(a, mode)) {
    case Operation::none: return "";
    case Operation::engine:
    case Operation::front_end: return to_string(a);
    case Operation::walk_forward: return "walk_forward";
    case Operation::walk_back: return "walk_back";
    case Operation::walk_left: return "walk_left";
    case Operation::walk_right: return "walk_right";
    case Operation::walk_up: return "walk_up";
    case Operation::walk_down: return "walk_down";
    case Operation::fov_narrow: return "fov_narrow";
    case Operation::fov_widen: return "fov_widen";
    case Operation::fov_reset: return "fov_reset";
  }
  return "";
}

std::string_view description(const KeyBinding& b, ViewMode mode) {
  // Z and X keep their engine action inside a lattice or along a path, where the graph's in/out
  // neighbours are not camera shells: the lattice's next camera north / south (a world axis, whatever
  // the view), a path's next / previous camera.
  if (mode == ViewMode::lattice && b.action == Action::shell_in)
    return "step north (the world's axis, whatever the view); along a path: the next camera";
  if (mode == ViewMode::lattice && b.action == Action::shell_out)
    return "step south; along a path: the previous camera";
  switch (operation(b.action, mode)) {
    case Operation::none: return "";
    case Operation::engine:
    case Operation::front_end: return b.description;
    case Operation::walk_forward: return "walk forward: to the neighbouring camera ahead of the view";
    case Operation::walk_back: return "walk back: to the neighbouring camera behind the view";
    case Operation::walk_left: return "walk left of the view";
    case Operation::walk_right: return "walk right of the view";
    case Operation::walk_up: return "walk up (towards the sky)";
    case Operation::walk_down: return "walk down";
    case Operation::fov_narrow: return "narrow the field of view (magnify; also the wheel)";
    case Operation::fov_widen: return "widen the field of view";
    case Operation::fov_reset: return "field of view back to 90 degrees";
  }
  return "";
}

bool usable(Action a, ViewMode mode, const store::Manifest& m) {
  const Operation op = operation(a, mode);
  if (op == Operation::none) return false;
  if (op != Operation::engine && op != Operation::front_end) return true;
  const auto any_neighbour = [&](int store::Neighbours::*slot) {
    if (m.graph.empty()) return true;  // no navigation data: the engine may still find one
    for (const auto& n : m.graph.neighbours)
      if (n.*slot >= 0) return true;
    return false;
  };
  switch (a) {
    case Action::axis_up:
    case Action::axis_down:
    case Action::next_axis:
    case Action::previous_axis: return !m.axes.empty();
    case Action::shell_in: return any_neighbour(&store::Neighbours::in);
    case Action::shell_out: return any_neighbour(&store::Neighbours::out);
    case Action::face_action: return mode != ViewMode::sphere;
    default: return true;
  }
}

std::string_view refusal(Action a, ViewMode mode, const store::Manifest* m) {
  const Operation op = operation(a, mode);
  if (op == Operation::none) return "this key does nothing inside a lattice or along a path";
  if (is_walk(op)) return "no camera that way";
  const KeyBinding* b = binding_of(a);
  // C in a 360° view is refused by the frame, not the database: the row's text is about fixed views.
  if (a == Action::face_action && mode != ViewMode::sphere) return "nothing stands out in this frame to turn to";
  if (op == Operation::front_end) return b ? b->refusal : std::string_view();
  if (op != Operation::engine) return "";  // a field of view at its limit needs no words
  // Inside a lattice Z / X step north / south (description()): "shell" would be the wrong word there.
  if (mode == ViewMode::lattice && (a == Action::shell_in || a == Action::shell_out)) return "no camera that way";
  if (m && (a == Action::shell_in || a == Action::shell_out)) {
    const auto several = std::any_of(m->cameras.begin(), m->cameras.end(),
                                     [&](const store::CameraEntry& c) { return c.labels.shell != m->cameras[0].labels.shell; });
    if (!several)
      return "Z / X move between camera shells, and this rig has only one (a rig spec like \"yinyang@2,3\" has two); "
             "use + / - or the wheel to magnify";
  }
  if (m && m->axes.empty() && (a == Action::axis_up || a == Action::axis_down)) return binding_of(Action::next_axis)->refusal;
  return b ? b->refusal : std::string_view();
}

bool is_walk(Operation op) { return op >= Operation::walk_forward && op <= Operation::walk_down; }

Walk walk_of(Operation op) {
  switch (op) {
    case Operation::walk_back: return Walk::back;
    case Operation::walk_left: return Walk::left;
    case Operation::walk_right: return Walk::right;
    case Operation::walk_up: return Walk::up;
    case Operation::walk_down: return Walk::down;
    default: return Walk::forward;
  }
}

Controls::Controls(Engine& engine, Look look)
    : engine_(engine), mode_(view_mode(engine.manifest())), look_(clamped(look)) {}

void Controls::set_look(const Look& look) { look_ = clamped(look); }

std::string_view Controls::refusal(Action action) const {
  return player::refusal(action, mode_, &engine_.manifest());
}

bool Controls::walk(Walk w) { return walk_keeping_view(engine_, look_, w); }

Controls::Result Controls::apply(Action action) {
  const Operation op = operation(action, mode_);
  switch (op) {
    case Operation::none: return Result::refused;
    case Operation::front_end: return Result::front_end;
    case Operation::engine: return engine_.apply(action) ? Result::done : Result::refused;
    case Operation::fov_narrow:
    case Operation::fov_widen:
    case Operation::fov_reset: {
      const Look before = look_;
      look_.fov_deg = op == Operation::fov_reset ? Look{}.fov_deg
                      : op == Operation::fov_narrow ? look_.fov_deg / kKeyFovFactor
                                                    : look_.fov_deg * kKeyFovFactor;
      look_ = clamped(look_);
      return look_ == before ? Result::refused : Result::done;
    }
    default: return walk(walk_of(op)) ? Result::done : Result::refused;
  }
}

bool Controls::run(const ScriptCommand& c) {
  using K = ScriptCommand::Kind;
  switch (c.kind) {
    case K::look: set_look(c.look); return true;
    case K::walk: return walk(c.walk);
    case K::key: return apply(c.action) == Result::done;
    case K::seek: engine_.seek(c.value); return c.value >= 0 && c.value < engine_.frame_count();
    case K::camera: return engine_.jump_to_camera(c.value);
    case K::task: {
      const int t = c.value >= 0 ? c.value : engine_.manifest().find_task(c.name);
      return t >= 0 && engine_.set_task(t);
    }
    case K::axis: {
      const int a = engine_.manifest().find_axis(c.name);
      return a >= 0 && engine_.step_axis(a, c.value);
    }
    case K::snap: return engine_.snap_to_direction(c.direction);
    case K::speed: engine_.set_speed(c.speed); return true;
    case K::play: engine_.set_playing(true); return true;
    case K::pause: engine_.set_playing(false); return true;
    case K::end: return true;
  }
  return false;
}

}  // namespace panoptes::player
