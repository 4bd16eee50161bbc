// `_panoptes.Session`: insitu::Session for a Python simulation. Fields are NumPy arrays used in place
// (no copy): the session keeps a reference to each array until it is rebound, and reads it during
// process()/snapshot(). Communicators come from mpi4py (its C API, mpi4py/mpi4py.h).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "core/error.hpp"
#include "core/strided.hpp"
#include "camera/rig_spec.hpp"
#include "grid/grid_description.hpp"
#include "insitu/grid_adapter.hpp"
#include "insitu/rank_agreement.hpp"
#include "insitu/resources.hpp"
#include "insitu/session.hpp"
#include "insitu/task_plan.hpp"
#include "python/bindings.hpp"

#ifdef PANOPTES_HAVE_MPI4PY
#include <mpi4py/mpi4py.h>
#endif

namespace py = pybind11;

namespace panoptes::python {
namespace {

std::array<int, 3> triple(const std::vector<long long>& v, const char* what, const char* call) {
  if (v.size() != 3)
    throw Error(std::string(call) + ": " + what + " has " + std::to_string(v.size()) + " entries; expected 3 (x, y, z)");
  for (long long x : v)
    if (x < 0 || x > (1LL << 31) - 1)
      throw Error(std::string(call) + ": " + what + " entry " + std::to_string(x) + "; expected 0 .. 2^31-1");
  return {int(v[0]), int(v[1]), int(v[2])};
}

class PySession {
 public:
  PySession(const std::string& config, bool is_file, const py::object& comm) {
    std::exception_ptr local;
    try {
      config_ = is_file ? insitu::load_session_config(config) : insitu::parse_session_config_text(config, "configuration text");
      config_.validate();
    } catch (...) {
      local = std::current_exception();
    }
    config_.program = "panoptes Python";
    if (!comm.is_none()) {
#if defined(PANOPTES_HAVE_MPI4PY)
      // Imported here, not at module import: mpi4py.MPI initializes MPI, which reading a database
      // must not do. A caller that passes a communicator has imported mpi4py already.
      if (import_mpi4py() < 0) throw py::error_already_set();
      MPI_Comm* c = PyMPIComm_Get(comm.ptr());
      if (!c) throw py::error_already_set();
      comm_ = *c;
#else
      throw Error("Session: a communicator was given, but this Panoptes was built without MPI or without mpi4py");
#endif
    }
    // Collective (issue 42): a rank whose configuration is refused makes every rank's Session() raise;
    // the others would otherwise wait for it at the first snapshot.
#ifdef PANOPTES_HAVE_MPI
    int init = 0;
    MPI_Initialized(&init);
    if (comm_ || init) {
      py::gil_scoped_release release;
      agreement_ = insitu::RankAgreement(comm_ ? *comm_ : MPI_COMM_WORLD, config_.mpi_timeout);
    }
#endif
    py::gil_scoped_release release;
    agreement_.agree(insitu::CallRecord{}, local, insitu::Failure::failed);
  }

  /// A call of this process's that raised (a field it could not bind, ...): the next collective call
  /// is refused on every rank, naming this one, instead of rendering what it holds.
  /// Keyed by what the call sets ("set_block", "field T", ...): a later call that sets it right clears it.
  void record_outcome(const std::string& key, const std::string* failure) {
    if (failure) failed_calls_[key] = *failure;
    else failed_calls_.erase(key);
  }

  void set_grid(const std::vector<long long>& dims, const std::array<double, 3>& origin,
                const std::array<double, 3>& spacing) {
    need_no_session("set_grid", "grid");
    const auto d = triple(dims, "dims", "set_grid");
    render::GridGeometry g{{d[0], d[1], d[2]}, {origin[0], origin[1], origin[2]}, {spacing[0], spacing[1], spacing[2]}};
    try {
      g.validate();
    } catch (const std::exception& e) {
      throw Error(std::string("set_grid: ") + e.what());
    }
    grid_ = g;
    source_.reset();
  }

  /// A grid that is not a uniform box (C API panoptes_set_grid_rectilinear / _spherical / _yinyang):
  /// three 1-D coordinate arrays, validated here; the session resamples its fields in situ.
  void set_source_grid(const std::string& kind, const std::vector<double>& a, const std::vector<double>& b,
                       const std::vector<double>& c) {
    const std::string call = "set_grid_" + kind;
    need_no_session(call.c_str(), "grid");
    const std::vector<double>* axes[3] = {&a, &b, &c};
    for (int d = 0; d < 3; ++d)
      if (axes[d]->size() < 2 || axes[d]->size() > 65535)
        throw Error(call + ": coordinate array " + std::to_string(d) + " has " + std::to_string(axes[d]->size()) +
                    " entries; expected 2 to 65535 points");
    grid::GridDescription g = grid::GridDescription::of_kind(grid::parse_grid_kind(kind), a, b, c);
    try {
      g.validate();
    } catch (const std::exception& e) {
      throw Error(call + ": " + e.what());
    }
    source_ = std::move(g);
    grid_.reset();
  }

  /// Yin-Yang: the patch (0 = Yin, 1 = Yang) the following set_block/set_field calls describe.
  void set_patch(int patch) {
    if (!source_ || source_->kind != grid::GridKind::yinyang)
      throw Error("set_patch: only a Yin-Yang grid has patches (call set_grid_yinyang first)");
    if (patch != 0 && patch != 1) throw Error("set_patch: patch " + std::to_string(patch) + "; expected 0 (Yin) or 1 (Yang)");
    if (patch == patch_) return;
    // After the first snapshot the blocks are fixed, but a process holding both patches re-binds each
    // one's fields every step (issue 42, point 7), so a patch that had a block may still be selected.
    if (session_) {
      const auto it = other_patches_.find(patch);
      if (it == other_patches_.end() || !it->second.block)
        throw Error("set_patch: patch " + std::to_string(patch) +
                    " had no block in this process at the first snapshot; the blocks cannot change after it");
    }
    other_patches_[patch_] = {block_, fields_};
    PatchState next = other_patches_[patch];
    other_patches_.erase(patch);
    block_ = next.block;
    fields_ = next.fields;
    patch_ = patch;
  }

  void set_resample(int longest_axis_points, double outside_value) {
    need_no_session("set_resample", "resampling");
    if (longest_axis_points != 0 && (longest_axis_points < 2 || longest_axis_points > 4096))
      throw Error("set_resample: " + std::to_string(longest_axis_points) +
                  " points; expected 2 to 4096 along the longest axis (0 = the source's largest dimension)");
    if (!std::isfinite(outside_value)) throw Error("set_resample: the outside value is not finite");
    resample_ = {longest_axis_points, float(outside_value)};
  }

  void set_block(const std::vector<long long>& offset, const std::vector<long long>& extent,
                 const std::vector<long long>& ghost_lo, const std::vector<long long>& ghost_hi) {
    need_no_session("set_block", "block");
    const auto o = triple(offset, "offset", "set_block"), e = triple(extent, "extent", "set_block");
    const auto lo = triple(ghost_lo, "ghost_lo", "set_block"), hi = triple(ghost_hi, "ghost_hi", "set_block");
    insitu::LocalBlock b;
    for (int a = 0; a < 3; ++a) b.offset[a] = o[a], b.extent[a] = e[a], b.ghost_lo[a] = lo[a], b.ghost_hi[a] = hi[a];
    block_ = b;
  }

  void set_halo(const std::vector<long long>& valid_lo, const std::vector<long long>& valid_hi, bool edges_valid) {
    need_no_session("set_halo", "halo");
    if (!block_) throw Error("set_halo: call set_block first");
    insitu::LocalBlock& b = *block_;
    for (const auto* v : {&valid_lo, &valid_hi})
      if (v->size() != 3)
        throw Error("set_halo: valid_lo/valid_hi has " + std::to_string(v->size()) + " entries; expected 3 (x, y, z)");
    static const char* const axes = "xyz";
    for (int a = 0; a < 3; ++a) {
      if (valid_lo[a] < -1 || valid_lo[a] > b.ghost_lo[a] || valid_hi[a] < -1 || valid_hi[a] > b.ghost_hi[a])
        throw Error(std::string("set_halo: valid ghost layers ") + std::to_string(valid_lo[a]) + " below / " +
                    std::to_string(valid_hi[a]) + " above on axis " + axes[a] + "; expected -1 (every stored layer) or 0 .. the stored " +
                    std::to_string(b.ghost_lo[a]) + " / " + std::to_string(b.ghost_hi[a]) + " (set_block)");
      b.valid_lo[a] = int(valid_lo[a]);
      b.valid_hi[a] = int(valid_hi[a]);
    }
    b.edges_valid = edges_valid;
  }

  /// Binds `array` (shape (nz, ny, nx) of the GHOSTED block, float32 or float64, any strides) without
  /// copying it.
  void set_field(const std::string& name, const py::array& array) {
    fields_.erase(name);  // a binding that fails leaves none (not the previous step's array)
    if (!block_) throw Error("set_field: call set_block first");
    const insitu::LocalBlock& b = *block_;
    const std::array<py::ssize_t, 3> shape{b.extent[2] + b.ghost_lo[2] + b.ghost_hi[2],
                                           b.extent[1] + b.ghost_lo[1] + b.ghost_hi[1],
                                           b.extent[0] + b.ghost_lo[0] + b.ghost_hi[0]};
    const bool f32 = py::isinstance<py::array_t<float>>(array), f64 = py::isinstance<py::array_t<double>>(array);
    if (!f32 && !f64)
      throw Error("set_field: field \"" + name + "\" has dtype " + py::str(array.dtype()).cast<std::string>() +
                  "; expected float32 or float64");
    if (array.ndim() != 3 || array.shape(0) != shape[0] || array.shape(1) != shape[1] || array.shape(2) != shape[2]) {
      std::string got = "(";
      for (py::ssize_t i = 0; i < array.ndim(); ++i) got += (i ? ", " : "") + std::to_string(array.shape(i));
      throw Error("set_field: field \"" + name + "\" has shape " + got + ")" + "; expected (" + std::to_string(shape[0]) +
                  ", " + std::to_string(shape[1]) + ", " + std::to_string(shape[2]) +
                  ") = (nz, ny, nx) of the block including its ghost layers");
    }
    const py::ssize_t item = array.itemsize();
    std::array<std::int64_t, 3> stride{};  // elements per x, y, z step
    for (int a = 0; a < 3; ++a) {
      const py::ssize_t s = array.strides(2 - a);
      if (s % item != 0)
        throw Error("set_field: field \"" + name + "\" has a stride of " + std::to_string(s) +
                    " bytes, not a multiple of its element size; pass numpy.ascontiguousarray(a)");
      stride[a] = s / item;
    }
    // NumPy allows any strides (as_strided): an array whose reach overflows 64-bit offsets would wrap
    // around to another address at every read.
    if (!strided_reach({shape[2], shape[1], shape[0]}, stride, item))
      throw Error("set_field: field \"" + name + "\" has strides (" + std::to_string(array.strides(0)) + ", " +
                  std::to_string(array.strides(1)) + ", " + std::to_string(array.strides(2)) +
                  ") bytes that reach further than 64-bit offsets can address; expected the strides of an array in memory");
    insitu::FieldInput in;
    in.name = name;
    const std::int64_t shift = b.ghost_lo[0] * stride[0] + b.ghost_lo[1] * stride[1] + b.ghost_lo[2] * stride[2];
    in.data = static_cast<const char*>(array.data()) + shift * item;
    in.type = f64 ? insitu::ScalarType::f64 : insitu::ScalarType::f32;
    in.stride = stride;
    fields_[name] = {in, array};  // the reference keeps the array alive while the session may read it
  }

  bool due(long long step, double time) { return session().due(step, time); }

  bool process(long long step, double time) {
    insitu::Session& s = session();
    const auto in = inputs();
    py::gil_scoped_release release;
    return s.process(step, time, in);
  }

  void snapshot(double time) {
    insitu::Session& s = session();
    const auto in = inputs();
    py::gil_scoped_release release;
    s.snapshot(time, in);
  }

  void finalize() {
    insitu::Session& s = session();
    py::gil_scoped_release release;
    s.finalize();
  }

  insitu::Session& session() {
    if (session_) {
      if (!failed_calls_.empty()) session_->refuse_next_call(failures());
      failed_calls_.clear();
      return *session_;
    }
    // The preconditions and this process's failed calls, agreed with the other ranks before the
    // session's first collective (a rank that cannot start refuses the call on every rank).
    std::exception_ptr local;
    try {
      if (!failed_calls_.empty()) throw Error(failures());
      if (!grid_ && !source_) throw Error("set_grid (or set_grid_rectilinear, _spherical, _yinyang) must be called before the first snapshot");
      if (!block_ && (!source_ || grid_blocks().empty())) throw Error("set_block must be called before the first snapshot");
    } catch (...) {
      local = std::current_exception();
    }
    failed_calls_.clear();
    py::gil_scoped_release release;  // collective construction: other ranks may still be in Python
    agreement_.agree(insitu::CallRecord{}, local, insitu::Failure::refused);
#ifdef PANOPTES_HAVE_MPI
    int init = 0;
    MPI_Initialized(&init);
    if (comm_ || init) {
      const MPI_Comm c = comm_ ? *comm_ : MPI_COMM_WORLD;
      if (source_) {
        session_ = std::make_unique<insitu::Session>(config_, *source_, grid_blocks(), resample_, c);
      } else {
        session_ = std::make_unique<insitu::Session>(config_, *grid_, *block_, c);
      }
      return *session_;
    }
#endif
    if (source_) {
      session_ = std::make_unique<insitu::Session>(config_, *source_, grid_blocks(), resample_);
    } else {
      session_ = std::make_unique<insitu::Session>(config_, *grid_, *block_);
    }
    return *session_;
  }

  std::string output_dir() const { return config_.output_dir; }

  // Known as soon as the Session exists: a simulation needs its rank to compute its block.
  std::pair<int, int> rank_and_size() const {
    if (session_) return {session_->rank(), session_->ranks()};
    int rank = 0, size = 1;
#ifdef PANOPTES_HAVE_MPI
    int init = 0, done = 0;
    MPI_Initialized(&init);
    MPI_Finalized(&done);
    if (init && !done) {
      const MPI_Comm c = comm_ ? *comm_ : MPI_COMM_WORLD;
      MPI_Comm_rank(c, &rank);
      MPI_Comm_size(c, &size);
    }
#endif
    return {rank, size};
  }

  int camera_count() const {
    if (session_) return session_->camera_count();
    const camera::RigSpec spec = camera::RigSpec::parse(config_.rig);
    const bool needs_grid = spec.kind == camera::RigSpec::Kind::file || spec.kind == camera::RigSpec::Kind::path;
    if (needs_grid && !grid_) throw Error("camera_count: the rig \"" + config_.rig + "\" is placed in the grid: call set_grid first");
    return int(insitu::rig_camera_count(config_, grid_ ? *grid_ : render::GridGeometry{}));
  }

  // The tasks the session will render: one per window, isovalue or slice position of each [[task]] (as
  // insitu::Session expands them; test_session.py checks both agree).
  int task_count() const {
    if (session_) return session_->task_count();
    std::size_t n = 0;
    for (const insitu::TaskConfig& t : config_.tasks) n += insitu::planned_task_count(t);
    return int(n);
  }
  int snapshots() const { return session_ ? session_->snapshots() : 0; }

 private:
  void need_no_session(const char* call, const char* what) const {
    if (session_) throw Error(std::string(call) + ": the " + what + " cannot change after the first snapshot");
  }
  using Fields = std::map<std::string, std::pair<insitu::FieldInput, py::array>>;
  struct PatchState {
    std::optional<insitu::LocalBlock> block;
    Fields fields;
  };
  // Every patch's state, the selected one included, in patch order (non-uniform grids).
  std::map<int, PatchState> all_patches() const {
    std::map<int, PatchState> all = other_patches_;
    all[patch_] = {block_, fields_};
    return all;
  }
  std::vector<insitu::GridBlock> grid_blocks() const {
    std::vector<insitu::GridBlock> v;
    for (const auto& [patch, st] : all_patches())
      if (st.block) v.push_back({patch, st.block->offset, st.block->extent, st.block->ghost_lo, st.block->ghost_hi});
    return v;
  }
  // Non-uniform grids: one input per field and block, blocks in patch order (as grid_blocks() gave
  // them to the session's grid stage, which resamples them at snapshots only).
  std::vector<insitu::FieldInput> inputs() {
    std::vector<insitu::FieldInput> v;
    if (!source_) {
      for (const auto& [name, f] : fields_) v.push_back(f.first);
      return v;
    }
    for (const auto& [patch, st] : all_patches())
      if (st.block)
        for (const auto& [name, f] : st.fields) v.push_back(f.first);
    return v;
  }

  insitu::SessionConfig config_;
#ifdef PANOPTES_HAVE_MPI
  std::optional<MPI_Comm> comm_;
#else
  std::optional<int> comm_;
#endif
  std::optional<render::GridGeometry> grid_;
  std::optional<insitu::LocalBlock> block_;
  Fields fields_;
  std::optional<grid::GridDescription> source_;
  insitu::ResampleOptions resample_;
  int patch_ = 0;
  std::map<int, PatchState> other_patches_;
  std::unique_ptr<insitu::Session> session_;
  insitu::RankAgreement agreement_;  // before the session exists
  std::map<std::string, std::string> failed_calls_;
  std::string failures() const {
    std::string all;
    for (const auto& [what, message] : failed_calls_)
      all += (all.empty() ? "" : "; ") + ("field \"" + what.substr(6) + "\" is not bound: its binding failed (" + message + ")");
    return all;
  }
};

// A field binding whose failure is remembered for the next collective call (PySession::record_outcome):
// the other setters leave their state as it was when they fail, and the start agrees on what is missing.
// `key`: what the call sets; set_field's is "field NAME" (its first argument).
template <class... A>
auto recorded(const char* key, void (PySession::*call)(A...)) {
  return [key, call](PySession& s, A... a) {
    std::string what = key;
    if constexpr (sizeof...(A) > 0) {
      using First = std::decay_t<std::tuple_element_t<0, std::tuple<A...>>>;
      if constexpr (std::is_same_v<First, std::string>)
        if (what == "field") what += " " + std::get<0>(std::forward_as_tuple(a...));
    }
    try {
      (s.*call)(std::forward<A>(a)...);
    } catch (const std::exception& e) {
      const std::string message = e.what();
      s.record_outcome(what, &message);
      throw;
    }
    s.record_outcome(what, nullptr);
  };
}

}  // namespace

void bind_session(py::module_& m) {
  py::class_<PySession>(m, "Session")
      .def(py::init<std::string, bool, py::object>(), py::arg("config"), py::arg("is_file"), py::arg("comm"))
      .def("set_grid", &PySession::set_grid, py::arg("dims"), py::arg("origin"), py::arg("spacing"))
      .def("set_source_grid", &PySession::set_source_grid, py::arg("kind"), py::arg("a"), py::arg("b"), py::arg("c"))
      .def("set_patch", &PySession::set_patch, py::arg("patch"))
      .def("set_resample", &PySession::set_resample, py::arg("longest_axis_points"), py::arg("outside_value"))
      .def("set_block", &PySession::set_block, py::arg("offset"), py::arg("extent"), py::arg("ghost_lo"),
           py::arg("ghost_hi"))
      .def("set_halo", &PySession::set_halo, py::arg("valid_lo"), py::arg("valid_hi"), py::arg("edges_valid"))
      .def("set_field", recorded("field", &PySession::set_field), py::arg("name"), py::arg("array"))
      .def("due", &PySession::due, py::arg("step"), py::arg("time"))
      .def("process", &PySession::process, py::arg("step"), py::arg("time"))
      .def("snapshot", &PySession::snapshot, py::arg("time"))
      .def("finalize", &PySession::finalize)
      .def_property_readonly("output_dir", &PySession::output_dir)
      .def_property_readonly("rank", [](const PySession& s) { return s.rank_and_size().first; })
      .def_property_readonly("ranks", [](const PySession& s) { return s.rank_and_size().second; })
      .def_property_readonly("camera_count", &PySession::camera_count)
      .def_property_readonly("task_count", &PySession::task_count)
      .def_property_readonly("snapshots", &PySession::snapshots);
}

}  // namespace panoptes::python
