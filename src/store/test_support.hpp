#pragma once
// Helpers shared by the store tests and benchmark: sample manifests and self-removing temp dirs.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "core/error.hpp"
#include "store/manifest.hpp"

namespace panoptes::store::testing {

/// Writes `text` to `path`, creating its directories (test fixtures: tables, manifests, images).
inline void write_file(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

/// The message of the panoptes::Error that f() throws, or "<no error>" (tests assert on messages).
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "<no error>";
}

/// A fresh directory under the system temp dir, removed (recursively) on destruction.
struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& tag = "store") {
    std::random_device rd;
    path = std::filesystem::temp_directory_path() /
           ("panoptes-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(rd()));
    std::filesystem::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::filesystem::path operator/(const std::string& s) const { return path / s; }
};

/// A valid manifest with `cameras` cameras on a unit sphere, `tasks` tasks on an "isovalue" axis, a
/// ring navigation graph and every field filled in.
inline Manifest sample_manifest(int cameras, int tasks, int width = 64, int height = 64) {
  Manifest m;
  m.title = "sample";
  m.provenance = {"store test", "0.1.0", "2026-11-21T00:00:00Z", "host", "store_test --x", {{"note", "a b"}}};
  m.domain = {{256, 512, 160}, {0, 0, 0}, {0.5, 0.5, 0.5}, "km", "", ""};
  m.image.width = width;
  m.image.height = height;
  m.video.gop = 5;
  m.video.crf = 20;
  m.rig.kind = "fibonacci";
  m.rig.parameters = {{"count", cameras}, {"radius", 3.0}};
  for (int c = 0; c < cameras; ++c) {
    const double z = 1 - (2.0 * c + 1) / cameras, r = std::sqrt(std::max(0.0, 1 - z * z));
    const double phi = c * 2.399963229728653;
    CameraEntry e;
    e.id = c;
    e.position = Vec3{3 * r * std::cos(phi), 3 * r * std::sin(phi), 3 * z};
    e.up = {0, 0, 1};
    e.fov_y_deg = 30;
    e.labels.patch = "fibonacci";
    e.labels.lat_deg = std::asin(z) * 180 / M_PI;
    e.labels.lon_deg = std::remainder(phi * 180 / M_PI, 360.0);
    m.cameras.push_back(e);
    Neighbours n;
    n.left = (c + cameras - 1) % cameras;
    n.right = (c + 1) % cameras;
    m.graph.neighbours.push_back(n);
  }
  ParameterAxis axis{"isovalue", {}, ""};
  for (int t = 0; t < tasks; ++t) axis.values.push_back(0.1 * (t + 1));
  m.axes.push_back(axis);
  for (int t = 0; t < tasks; ++t) {
    TaskEntry e;
    e.id = t;
    e.name = "iso " + std::to_string(t);
    e.method = "isosurface";
    e.fields = {"phi_s"};
    e.parameters = {{"isovalue", axis.values[std::size_t(t)]}};
    e.axes = {{"isovalue", t}};
    m.tasks.push_back(e);
  }
  return m;
}

}  // namespace panoptes::store::testing
