// Panoptes for C++ codes: a header-only RAII wrapper over the C API (panoptes.h, libpanoptes.so), so a
// C++ simulation links only Panoptes::panoptes (or `pkg-config panoptes`) and sees no Panoptes C++
// symbols, FFmpeg or toml++. Errors are panoptes::Error exceptions carrying the C API's code and
// message. Every call is collective over the communicator, as in C. Guide: docs/instrumenting.md.
//
//   #include <mpi.h>
//   #include <panoptes.hpp>
//   panoptes::Session viz("viz.toml", MPI_COMM_WORLD);
//   viz.set_grid({nx, ny, nz}, {0, 0, 0}, {h, h, h});
//   viz.set_block(offset, extent, ghost_lo, ghost_hi);     // owned points + STORED ghost layers
//   viz.set_halo({1, 1, 1}, {1, 1, 1}, false);             // optional: valid layers, face-only exchange
//   for (...) {
//     viz.set_field("T", u.data(), u.size());              // contiguous x-fastest over the ghosted block
//     viz.process(step, time);
//   }
//   viz.finalize();
#ifndef PANOPTES_HPP
#define PANOPTES_HPP

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "panoptes.h"

#if defined(MPI_VERSION) || defined(OMPI_MPI_H) || defined(MPICH_VERSION)
#define PANOPTES_HPP_HAVE_MPI 1
#endif

namespace panoptes {

/// A failed Panoptes call: code() is PANOPTES_ERROR_CONFIG, _USAGE or _RUN; what() the message.
class Error : public std::runtime_error {
 public:
  Error(int code, const std::string& message) : std::runtime_error(message), code_(code) {}
  int code() const noexcept { return code_; }

 private:
  int code_;
};

/// An in-situ visualization session (panoptes_session). Move-only; the destructor frees it (without
/// finalize() the database is left interrupted, its snapshots playable).
class Session {
 public:
  /// From a TOML file (or, with is_file = false, TOML text) on MPI_COMM_WORLD when MPI is initialized.
  explicit Session(const std::string& config, bool is_file = true) { open(config, is_file, PANOPTES_COMM_WORLD); }
#ifdef PANOPTES_HPP_HAVE_MPI
  /// On communicator `comm` (include <mpi.h> before this header).
  Session(const std::string& config, MPI_Comm comm, bool is_file = true) { open(config, is_file, MPI_Comm_c2f(comm)); }
#endif
  ~Session() { panoptes_destroy(s_); }
  Session(Session&& o) noexcept : s_(std::exchange(o.s_, nullptr)) {}
  Session& operator=(Session&& o) noexcept {
    std::swap(s_, o.s_);
    return *this;
  }
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  /// The global grid: points per axis (x, y, z), origin and spacing in world units.
  void set_grid(const std::array<int, 3>& dims, const std::array<double, 3>& origin, const std::array<double, 3>& spacing) {
    check(panoptes_set_grid(s_, dims.data(), origin.data(), spacing.data()));
  }
  /// Grids that are not uniform boxes (panoptes.h): per-axis coordinates, resampled in situ.
  void set_grid_rectilinear(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& z) {
    const int dims[3] = {int(x.size()), int(y.size()), int(z.size())};
    check(panoptes_set_grid_rectilinear(s_, dims, x.data(), y.data(), z.data()));
  }
  /// A spherical shell: radii, colatitudes in [0, pi] and longitudes (radians), each increasing.
  void set_grid_spherical(const std::vector<double>& r, const std::vector<double>& theta, const std::vector<double>& phi) {
    const int dims[3] = {int(r.size()), int(theta.size()), int(phi.size())};
    check(panoptes_set_grid_spherical(s_, dims, r.data(), theta.data(), phi.data()));
  }
  /// A Yin-Yang grid: one patch's coordinates, shared by Yin (0) and Yang (1); select with set_patch.
  void set_grid_yinyang(const std::vector<double>& r, const std::vector<double>& theta, const std::vector<double>& phi) {
    const int dims[3] = {int(r.size()), int(theta.size()), int(phi.size())};
    check(panoptes_set_grid_yinyang(s_, dims, r.data(), theta.data(), phi.data()));
  }
  /// Yin-Yang: the patch the following set_block / set_field calls describe.
  void set_patch(int patch) { check(panoptes_set_patch(s_, patch)); }
  /// Points along the longest axis of the uniform grid rendered (0 = automatic) and the outside value.
  void set_resample(int longest_axis_points, double outside_value = 0.0) {
    check(panoptes_set_resample(s_, longest_axis_points, outside_value));
  }
  /// This rank's owned points (0-based offset, extent) and the ghost layers its arrays STORE around them.
  void set_block(const std::array<int, 3>& offset, const std::array<int, 3>& extent,
                 const std::array<int, 3>& ghost_lo = {0, 0, 0}, const std::array<int, 3>& ghost_hi = {0, 0, 0}) {
    check(panoptes_set_block(s_, offset.data(), extent.data(), ghost_lo.data(), ghost_hi.data()));
  }
  /// Of the stored ghosts, those the halo exchange keeps valid (-1 = all stored), and whether it fills
  /// edge and corner ghosts too (false: face-only halos; Panoptes fetches those points itself).
  void set_halo(const std::array<int, 3>& valid_lo, const std::array<int, 3>& valid_hi, bool edges_valid = false) {
    check(panoptes_set_halo(s_, valid_lo.data(), valid_hi.data(), edges_valid ? 1 : 0));
  }
  /// Binds a contiguous x-fastest float/double buffer of `count` elements over the ghosted block (checked:
  /// a buffer shorter than the block is refused). No copy: keep it alive until the next snapshot.
  template <class T>
  void set_field(const std::string& name, const T* data, std::size_t count) {
    check(panoptes_set_field_n(s_, name.c_str(), data, type_of<T>(), nullptr, static_cast<long long>(count)));
  }
  /// Binds an array in any axis order: layout names the grid axis of each dimension ("zxy": first
  /// dimension z), extents/strides (elements) per dimension in that order; data = element (0, 0, 0).
  template <class T>
  void set_field(const std::string& name, const T* data, const std::string& layout, const std::array<long long, 3>& extents,
                 const std::array<long long, 3>& strides) {
    check(panoptes_set_field_layout(s_, name.c_str(), data, type_of<T>(), layout.c_str(), extents.data(), strides.data()));
  }
  /// The same for a buffer of `count` elements from data on (checked: an array that reaches outside it is refused).
  template <class T>
  void set_field(const std::string& name, const T* data, const std::string& layout, const std::array<long long, 3>& extents,
                 const std::array<long long, 3>& strides, std::size_t count) {
    check(panoptes_set_field_layout_n(s_, name.c_str(), data, type_of<T>(), layout.c_str(), extents.data(), strides.data(),
                                      static_cast<long long>(count)));
  }
  /// Whether the schedule asks for a snapshot at (step, time).
  bool due(long long step, double time) {
    int d = 0;
    check(panoptes_due(s_, step, time, &d));
    return d != 0;
  }
  /// Renders and stores a snapshot if due; returns whether it did.
  bool process(long long step, double time) {
    int taken = 0;
    check(panoptes_process(s_, step, time, &taken));
    return taken != 0;
  }
  /// Renders and stores a snapshot now, whatever the schedule.
  void snapshot(double time) { check(panoptes_snapshot(s_, time)); }
  /// Closes every movie and marks the database complete.
  void finalize() { check(panoptes_finalize(s_)); }
  /// The C handle, for calls this wrapper does not cover.
  panoptes_session* handle() const noexcept { return s_; }

 private:
  template <class T>
  static constexpr int type_of() {
    static_assert(std::is_same_v<T, float> || std::is_same_v<T, double>, "Panoptes fields are float or double");
    return std::is_same_v<T, double> ? PANOPTES_FLOAT64 : PANOPTES_FLOAT32;
  }
  static void check(int code) {
    if (code != PANOPTES_OK) throw Error(code, panoptes_last_error());
  }
  void open(const std::string& config, bool is_file, int fortran_comm) {
    check(panoptes_create(config.c_str(), is_file ? 1 : 0, fortran_comm, &s_));
  }
  panoptes_session* s_ = nullptr;
};

}  // namespace panoptes

#endif  // PANOPTES_HPP
