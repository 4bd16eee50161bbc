#pragma once
// `panoptes render --grid GRID.toml`: volumes on a grid that is not a uniform box (issue 33). The TOML
// names the grid's kind and its coordinate arrays (.npy, 1-D); the volumes then hold the values at
// the grid's points and go through the in-situ grid stage (insitu::GridAdapter), as a simulation's do.
//
//   [grid]
//   kind = "spherical"          # rectilinear | spherical | yinyang
//   r = "r.npy"                 # rectilinear: x, y, z; spherical and yinyang: r, theta, phi (radians)
//   theta = "theta.npy"
//   phi = "phi.npy"
//   points = 128                # optional: points along the longest axis of the uniform grid rendered
//   outside = 0.0               # optional: the value outside the grid's domain (a shell's core)
//
// Volumes: .npy of shape (n2, n1, n0) (C order, the first coordinate fastest; Fortran order
// (n0, n1, n2)); Yin-Yang: (2, n2, n1, n0), Yin then Yang. Header-only (app compiles cmd_*.cpp only).
#include <toml++/toml.h>

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "app/volume_file.hpp"
#include "core/error.hpp"
#include "core/file_read.hpp"
#include "core/toml_keys.hpp"
#include "grid/grid_description.hpp"
#include "insitu/grid_adapter.hpp"

namespace panoptes::app {

/// A non-uniform grid read from a --grid file, and how to resample it.
struct RenderGrid {
  grid::GridDescription source;
  insitu::ResampleOptions resample;
};

namespace render_grid_detail {

inline std::string read_npy_bytes(const std::string& path) {
  return read_regular_file(path, std::uint64_t(volume_detail::kMaxVolumePoints) * 16 + (1 << 20), "volume file");
}

// A coordinate array has at most 65535 values (GridDescription's limit): 512 kB of float64 and a
// header. A larger file (a 3 GB sparse .npy was read whole, issue 44) is refused before it is read.
inline std::string read_coordinate_bytes(const std::string& path) {
  return read_regular_file(path, std::uint64_t(65535) * 8 + (1 << 16), "coordinate file (at most 65535 values)");
}

// A 1-D float32/float64 .npy array of coordinates, in double precision.
inline std::vector<double> read_coordinates(const std::string& path, const std::string& key) {
  const std::string data = read_coordinate_bytes(path);
  const NpyHeader h = parse_npy_header(data, path);
  if (h.shape.size() != 1)
    throw FileError(path, "grid." + key + ": array of " + std::to_string(h.shape.size()) +
                              " dimensions; expected a 1-D array of coordinates");
  const std::size_t n = h.count();
  if (data.size() < h.offset + n * h.elem) throw FileError(path, "truncated data");
  std::vector<double> v(n);
  std::vector<float> f;
  if (h.elem == 8) {
    const bool swap = h.big_endian != (std::endian::native == std::endian::big);
    for (std::size_t i = 0; i < n; ++i) {
      double x;
      std::memcpy(&x, data.data() + h.offset + 8 * i, 8);
      v[i] = swap ? volume_detail::byteswap_value(x) : x;
    }
  } else {
    volume_detail::convert<float>(data.data() + h.offset, n, h.big_endian, f);
    for (std::size_t i = 0; i < n; ++i) v[i] = f[i];
  }
  return v;
}

}  // namespace render_grid_detail

/// Reads a --grid TOML file (see the file's comment); coordinate paths are relative to its folder.
/// Throws FileError naming the file, the key and the value (non-monotonic coordinates, a Yin-Yang
/// patch that leaves a gap, ...).
inline RenderGrid read_render_grid(const std::string& path) {
  using namespace toml_keys;
  const Source c{path};
  toml::table root;
  try {
    root = toml::parse(read_regular_file(path, 1 << 20, "grid file"), path);
  } catch (const toml::parse_error& e) {
    throw FileError(path, std::string("TOML: ") + std::string(e.description()));
  }
  only_keys(c, root, "", {"grid"});
  const toml::table* t = root["grid"].as_table();
  if (!t) c.fail("grid", "missing (a [grid] table is required)");
  const std::string kind_text = str(c, *t, "kind", "grid.", "", true);
  grid::GridKind kind;
  try {
    kind = grid::parse_grid_kind(kind_text);
  } catch (const std::exception& e) {
    c.fail("grid.kind", e.what());
  }
  if (kind == grid::GridKind::uniform)
    c.fail("grid.kind", "\"uniform\" needs no grid file (use --origin and --spacing); expected rectilinear, spherical or yinyang");
  const std::array<std::string, 3> names = kind == grid::GridKind::rectilinear ? std::array<std::string, 3>{"x", "y", "z"}
                                                                               : std::array<std::string, 3>{"r", "theta", "phi"};
  only_keys(c, *t, "grid", {"kind", names[0], names[1], names[2], "points", "outside"});
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::array<std::vector<double>, 3> coords;
  for (int a = 0; a < 3; ++a) {
    const std::filesystem::path file = str(c, *t, names[a], "grid.", "", true);
    coords[a] = render_grid_detail::read_coordinates((file.is_absolute() ? file : dir / file).string(), names[a]);
    if (coords[a].size() < 2 || coords[a].size() > 65535)
      c.fail("grid." + names[a], std::to_string(coords[a].size()) + " coordinates; expected 2 to 65535");
  }
  RenderGrid g;
  g.source = grid::GridDescription::of_kind(kind, coords[0], coords[1], coords[2]);
  try {
    g.source.validate();
  } catch (const std::exception& e) {
    throw FileError(path, e.what());
  }
  g.resample.longest_axis_points = int_in(c, *t, "points", "grid.", 0, 0, 4096);
  if (g.resample.longest_axis_points == 1) c.fail("grid.points", "1; expected 2 to 4096 (or 0: the source's largest dimension)");
  if (const auto* o = t->get("outside")) {
    const auto v = o->value<double>();
    if (!v || !std::isfinite(*v)) c.fail("grid.outside", "expected a finite number");
    g.resample.outside_value = float(*v);
  }
  return g;
}

/// The values of one volume file on `g` (every patch, Yin before Yang, the first axis fastest), checked
/// against the grid's points: .npy only.
inline std::vector<float> read_grid_volume(const std::string& path, const grid::GridDescription& g) {
  const std::string data = render_grid_detail::read_npy_bytes(path);
  const NpyHeader h = parse_npy_header(data, path);
  const render::Index3 d = g.dims();
  const int patches = g.patches();
  // Expected shapes in C order; Fortran order reverses them (same bytes).
  std::vector<long long> expect = {d[2], d[1], d[0]};
  if (patches == 2) expect.insert(expect.begin(), 2);
  std::vector<long long> got = h.shape;
  if (h.fortran) std::reverse(got.begin(), got.end());
  auto text = [](const std::vector<long long>& s) {
    std::string t = "(";
    for (std::size_t i = 0; i < s.size(); ++i) t += (i ? ", " : "") + std::to_string(s[i]);
    return t + (s.size() == 1 ? ",)" : ")");
  };
  if (got != expect) {
    const std::string which = patches == 2 ? "a Yin-Yang volume (2 patches, Yin then Yang, of (nphi, ntheta, nr) points)"
                                           : "the grid's (n2, n1, n0) points in C order";
    throw FileError(path, "array of shape " + text(h.shape) + "; expected " + text(expect) + ", " + which + " of the " +
                              g.summary() + " (--grid)");
  }
  const std::size_t n = h.count();
  if (data.size() < h.offset + n * h.elem)
    throw FileError(path, "truncated data: " + std::to_string(data.size() - h.offset) + " bytes for " + std::to_string(n) + " values");
  std::vector<float> v;
  if (h.elem == 4) volume_detail::convert<float>(data.data() + h.offset, n, h.big_endian, v);
  else volume_detail::convert<double>(data.data() + h.offset, n, h.big_endian, v);
  return v;
}

}  // namespace panoptes::app
