// `_panoptes.Database`: store::Database for Python. Cameras come out as NumPy columns (one array per
// field, like the binary camera table), frames as (H, W, 3) uint8 arrays; the manifest's small parts
// (tasks, axes, domain, rig, provenance) as JSON text that the Python package parses.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "python/bindings.hpp"
#include "python/frame_array.hpp"
#include "store/database.hpp"

namespace py = pybind11;

namespace panoptes::python {
namespace {

/// An opened database plus a few open movie readers, so reading a stream frame after frame decodes
/// one packet per frame instead of reopening and seeking.
class PyDatabase {
 public:
  explicit PyDatabase(const std::filesystem::path& dir) : db_(store::Database::open(dir)) {}

  const store::Database& database() const { return db_; }

  py::array_t<std::uint8_t> frame(int camera, int task, int frame) {
    check_stream(camera, task);
    if (frame < 0 || frame >= db_.frame_count())
      throw Error(db_.dir().string() + ": frame " + std::to_string(frame) + " out of range; the database has " +
                  std::to_string(db_.frame_count()) + " complete frames (0.." + std::to_string(db_.frame_count() - 1) +
                  ")");
    video::YuvFrame yuv;
    {
      py::gil_scoped_release release;
      std::lock_guard lock(mutex_);
      reader(camera, task).read(frame, yuv);
    }
    return rgb_array(yuv);
  }

  std::string manifest_json() const {
    store::Manifest m = db_.manifest();
    m.cameras.clear();
    m.graph.neighbours.clear();
    nlohmann::json j = store::to_json(m);
    j.erase("cameras");
    if (j.contains("navigation")) j["navigation"].erase("neighbours");
    return j.dump();
  }

  py::dict cameras() const {
    const auto& cams = db_.manifest().cameras;
    const py::ssize_t n = py::ssize_t(cams.size());
    py::array_t<double> position({n, py::ssize_t(3)}), look_at({n, py::ssize_t(3)}), up({n, py::ssize_t(3)});
    py::array_t<double> fov(n), lat(n), lon(n);
    py::array_t<std::int32_t> shell(n), neighbours({n, py::ssize_t(6)});
    py::list patch;
    auto p = position.mutable_unchecked<2>(), l = look_at.mutable_unchecked<2>(), u = up.mutable_unchecked<2>();
    auto f = fov.mutable_unchecked<1>(), la = lat.mutable_unchecked<1>(), lo = lon.mutable_unchecked<1>();
    auto s = shell.mutable_unchecked<1>();
    auto nb = neighbours.mutable_unchecked<2>();
    const auto& graph = db_.manifest().graph.neighbours;
    for (py::ssize_t i = 0; i < n; ++i) {
      const store::CameraEntry& c = cams[std::size_t(i)];
      for (int a = 0; a < 3; ++a) p(i, a) = c.position[a], l(i, a) = c.look_at[a], u(i, a) = c.up[a];
      f(i) = c.fov_y_deg;
      la(i) = c.labels.lat_deg;
      lo(i) = c.labels.lon_deg;
      s(i) = c.labels.shell;
      patch.append(c.labels.patch);
      const store::Neighbours g = graph.empty() ? store::Neighbours{} : graph[std::size_t(i)];
      const int row[6] = {g.left, g.right, g.up, g.down, g.in, g.out};
      for (int k = 0; k < 6; ++k) nb(i, k) = row[k];
    }
    py::dict d;
    d["position"] = position;
    d["look_at"] = look_at;
    d["up"] = up;
    d["fov"] = fov;
    d["latitude"] = lat;
    d["longitude"] = lon;
    d["shell"] = shell;
    d["neighbours"] = neighbours;
    d["patch"] = patch;
    d["has_navigation"] = !graph.empty();
    return d;
  }

 private:
  void check_stream(int camera, int task) const {
    if (camera < 0 || camera >= db_.camera_count())
      throw Error(db_.dir().string() + ": camera " + std::to_string(camera) + " out of range; the database has " +
                  std::to_string(db_.camera_count()) + " cameras");
    if (task < 0 || task >= db_.task_count())
      throw Error(db_.dir().string() + ": task " + std::to_string(task) + " out of range; the database has " +
                  std::to_string(db_.task_count()) + " tasks");
  }

  // Most recently used first; a handful covers iterating a few streams side by side.
  video::MovieReader& reader(int camera, int task) {
    for (auto it = readers_.begin(); it != readers_.end(); ++it)
      if (it->first == std::pair{camera, task}) {
        readers_.splice(readers_.begin(), readers_, it);
        return *readers_.front().second;
      }
    readers_.emplace_front(std::pair{camera, task}, db_.stream(camera, task));
    if (readers_.size() > kMaxReaders) readers_.pop_back();
    return *readers_.front().second;
  }

  static constexpr std::size_t kMaxReaders = 8;
  store::Database db_;
  std::mutex mutex_;
  std::list<std::pair<std::pair<int, int>, std::unique_ptr<video::MovieReader>>> readers_;
};

}  // namespace


void bind_database(py::module_& m) {
  py::class_<PyDatabase, std::shared_ptr<PyDatabase>>(m, "Database")
      .def(py::init<std::filesystem::path>(), py::arg("path"))
      .def_property_readonly("path", [](const PyDatabase& d) { return d.database().dir(); })
      .def_property_readonly("status", [](const PyDatabase& d) { return std::string(store::to_string(d.database().status())); })
      .def_property_readonly("stored_status",
                             [](const PyDatabase& d) { return std::string(store::to_string(d.database().stored_status())); })
      .def_property_readonly("frame_count", [](const PyDatabase& d) { return d.database().frame_count(); })
      .def_property_readonly("camera_count", [](const PyDatabase& d) { return d.database().camera_count(); })
      .def_property_readonly("task_count", [](const PyDatabase& d) { return d.database().task_count(); })
      .def_property_readonly("times",
                             [](const PyDatabase& d) {
                               const int n = d.database().frame_count();
                               py::array_t<double> t(n);
                               for (int i = 0; i < n; ++i) t.mutable_at(i) = d.database().manifest().frame_time(i);
                               return t;
                             })
      .def("manifest_json", &PyDatabase::manifest_json)
      .def("cameras", &PyDatabase::cameras)
      .def("stream_path", [](const PyDatabase& d, int c, int t) { return d.database().stream_path(c, t); })
      // Issue 46: a packed database's stream as byte ranges of its packs (init segment first).
      .def_property_readonly("packed", [](const PyDatabase& d) { return d.database().packed(); })
      .def("packed_stream", [](const PyDatabase& d, int c, int t) {
        py::list pieces;
        for (const auto& p : d.database().packed_stream(c, t).pieces)
          pieces.append(py::dict(py::arg("file") = p.file.string(), py::arg("offset") = p.offset, py::arg("size") = p.size,
                                 py::arg("first_frame") = p.first_frame, py::arg("frames") = p.frames));
        return pieces;
      })
      .def("frame", &PyDatabase::frame, py::arg("camera"), py::arg("task"), py::arg("frame"));
}

}  // namespace panoptes::python
