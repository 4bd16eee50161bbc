// `_panoptes.Player`: the UI-free playback engine, headless, for notebooks and scripted figures. The
// engine runs on a virtual clock that only advance() moves, so a script shows the same frames on every
// machine (as `panoptes play --headless` does).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <memory>
#include <string>

#include "core/error.hpp"
#include "player/controls.hpp"
#include "player/engine.hpp"
#include "player/keys.hpp"
#include "store/database.hpp"
#include "python/bindings.hpp"
#include "python/frame_array.hpp"

namespace py = pybind11;

namespace panoptes::python {
namespace {

player::Direction parse_direction(const std::string& s) {
  for (auto d : {player::Direction::left, player::Direction::right, player::Direction::up, player::Direction::down,
                 player::Direction::in, player::Direction::out})
    if (player::to_string(d) == s) return d;
  throw Error("navigate: direction \"" + s + "\"; expected left, right, up, down, in or out");
}

// A task given by index or by name ("p+s"), as db.frame() takes it; `what` names the call in errors.
int resolve_task(const store::Manifest& manifest, const py::object& task, const std::string& what) {
  if (py::isinstance<py::str>(task)) {
    const std::string name = task.cast<std::string>();
    const int i = manifest.find_task(name);
    if (i >= 0) return i;
    std::string names;
    for (const auto& t : manifest.tasks) names += (names.empty() ? "\"" : ", \"") + t.name + "\"";
    throw Error(what + ": the database has no task \"" + name + "\"; its tasks are " + names);
  }
  if (py::isinstance<py::int_>(task) && !py::isinstance<py::bool_>(task)) return task.cast<int>();
  throw Error(what + ": task " + std::string(py::str(task)) + " (" + std::string(py::str(task.get_type().attr("__name__"))) +
              "); expected a task index (int) or name (str)");
}

class PyPlayer {
 public:
  PyPlayer(const std::filesystem::path& dir, int camera, const py::object& task, int frame, bool prefetch,
           std::size_t cache_mb)
      : clock_(std::make_unique<player::VirtualClock>()) {
    player::EngineOptions o;
    o.camera = camera;
    o.task = py::isinstance<py::str>(task) ? resolve_task(store::Database::open(dir).manifest(), task, "Player")
                                           : resolve_task(store::Manifest{}, task, "Player");
    o.frame = frame;
    o.prefetch = prefetch;
    o.start_playing = false;
    o.cache_bytes = cache_mb << 20;
    o.time_source = clock_->source();
    engine_ = std::make_unique<player::Engine>(dir, o);
    controls_ = std::make_unique<player::Controls>(*engine_);
  }

  player::Engine& engine() { return *engine_; }
  player::Controls& controls() { return *controls_; }

  /// A key of the players' key table ("Up", "Shift+Tab", "3"), dispatched as the window and headless
  /// runs do (walks inside lattices, field of view in 360° streams). True when it changed something.
  bool key(const std::string& name) {
    const auto action = player::action_for_key(name);
    if (!action) throw Error("key: unknown key \"" + name + "\" (the names of `panoptes play --help`)");
    return controls_->apply(*action) == player::Controls::Result::done;
  }

  bool walk(const std::string& direction) {
    static const char* names[] = {"forward", "back", "left", "right", "up", "down"};
    for (int i = 0; i < 6; ++i)
      if (direction == names[i]) return controls_->walk(player::Walk(i));
    throw Error("walk: direction \"" + direction + "\"; expected forward, back, left, right, up or down");
  }

  py::dict selection() const {
    const player::Selection s = engine_->selection();
    py::dict d;
    d["camera"] = s.camera;
    d["task"] = s.task;
    d["frame"] = s.frame;
    return d;
  }

  /// Moves the virtual clock and lets the engine follow it (frames advance while playing).
  void advance(double seconds) {
    if (!(seconds >= 0)) throw Error("advance: " + std::to_string(seconds) + " s; expected a non-negative duration");
    clock_->advance(seconds);
    engine_->tick();
  }

  py::dict shown() {
    player::ShownFrame f;
    {
      py::gil_scoped_release release;
      engine_->tick();
      f = engine_->current_frame();
    }
    py::dict d;
    d["camera"] = f.selection.camera;
    d["task"] = f.selection.task;
    d["frame"] = f.selection.frame;
    d["time"] = f.time;
    d["status"] = std::string(player::to_string(f.status));
    d["message"] = f.message;
    d["cache_hit"] = f.cache_hit;
    d["image"] = rgb_array(*f.frame);
    return d;
  }

  int task_index(const py::object& task, const std::string& what) const {
    return resolve_task(engine_->manifest(), task, what);
  }

  int axis_index(const py::object& axis) const {
    if (py::isinstance<py::str>(axis)) {
      const std::string name = axis.cast<std::string>();
      const int i = engine_->manifest().find_axis(name);
      if (i < 0) throw Error("step_axis: the database has no parameter axis \"" + name + "\"");
      return i;
    }
    return axis.cast<int>();
  }

 private:
  std::unique_ptr<player::VirtualClock> clock_;  // outlives the engine, which reads it
  std::unique_ptr<player::Engine> engine_;
  std::unique_ptr<player::Controls> controls_;  // after engine_: destroyed before it
};

}  // namespace

void bind_player(py::module_& m) {
  py::class_<PyPlayer>(m, "Player")
      .def(py::init<std::filesystem::path, int, py::object, int, bool, std::size_t>(), py::arg("path"),
           py::arg("camera") = 0, py::arg("task") = 0, py::arg("frame") = 0, py::arg("prefetch") = true, py::arg("cache_mb") = 256)
      .def_property_readonly("selection", &PyPlayer::selection)
      .def_property_readonly("frame_count", [](PyPlayer& p) { return p.engine().frame_count(); })
      .def_property_readonly("playing", [](PyPlayer& p) { return p.engine().playing(); })
      .def_property_readonly("fps", [](PyPlayer& p) { return p.engine().fps(); })
      .def_property("speed", [](PyPlayer& p) { return p.engine().speed(); },
                    [](PyPlayer& p, double s) { p.engine().set_speed(s); })
      .def_property("loop", [](PyPlayer& p) { return p.engine().loop(); },
                    [](PyPlayer& p, bool l) { p.engine().set_loop(l); })
      .def("play", [](PyPlayer& p) { p.engine().set_playing(true); })
      .def("pause", [](PyPlayer& p) { p.engine().set_playing(false); })
      .def("advance", &PyPlayer::advance, py::arg("seconds"))
      .def("navigate", [](PyPlayer& p, const std::string& d) { return p.engine().navigate(parse_direction(d)); },
           py::arg("direction"))
      .def("jump_to_camera", [](PyPlayer& p, int c) { return p.engine().jump_to_camera(c); }, py::arg("camera"))
      .def("set_task", [](PyPlayer& p, const py::object& t) { return p.engine().set_task(p.task_index(t, "set_task")); },
           py::arg("task"))
      .def("next_task", [](PyPlayer& p) { return p.engine().next_task(); })
      .def("previous_task", [](PyPlayer& p) { return p.engine().previous_task(); })
      .def("step_axis", [](PyPlayer& p, const py::object& axis, int delta) {
             return p.engine().step_axis(p.axis_index(axis), delta);
           }, py::arg("axis"), py::arg("delta") = 1)
      .def("seek", [](PyPlayer& p, int f) { p.engine().seek(f); }, py::arg("frame"))
      .def("step_frame", [](PyPlayer& p, int d) { p.engine().step_frame(d); }, py::arg("delta") = 1)
      .def("nearest_camera", [](PyPlayer& p, std::array<double, 3> d, int shell) {
             return p.engine().nearest_camera({d[0], d[1], d[2]}, shell);
           }, py::arg("direction"), py::arg("shell") = -1)
      .def("snap_to_direction", [](PyPlayer& p, std::array<double, 3> d) {
             return p.engine().snap_to_direction({d[0], d[1], d[2]});
           }, py::arg("direction"))
      .def("key", &PyPlayer::key, py::arg("name"))
      .def("walk", &PyPlayer::walk, py::arg("direction"))
      .def_property_readonly("mode", [](PyPlayer& p) { return std::string(player::to_string(p.controls().mode())); })
      .def_property_readonly("active_axis", [](PyPlayer& p) { return p.engine().active_axis(); })
      .def_property("look",
                    [](PyPlayer& p) {
                      const auto& l = p.controls().look();
                      return py::make_tuple(l.yaw_deg, l.pitch_deg, l.fov_deg);
                    },
                    [](PyPlayer& p, std::array<double, 3> l) { p.controls().set_look({l[0], l[1], l[2]}); })
      .def("shown", &PyPlayer::shown)
      .def("statistics_json", [](PyPlayer& p) { return player::to_json(p.engine().statistics()).dump(); });
}

}  // namespace panoptes::python
