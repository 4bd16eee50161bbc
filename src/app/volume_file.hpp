#pragma once
// Volume files for `panoptes render`: NumPy .npy (3-D float32/float64) and VTK legacy
// STRUCTURED_POINTS (.vtk, ASCII or BINARY). Header-only: the readers belong to the command (the
// render module must not read files, DESIGN.md), and app/CMakeLists.txt compiles cmd_*.cpp only.
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/file_read.hpp"
#include "core/vec3.hpp"

namespace panoptes::app {

/// A scalar volume on a uniform grid: dims points per axis, x fastest (index i + nx·(j + ny·k)).
struct Volume {
  std::array<int, 3> dims{0, 0, 0};
  Vec3 origin{0, 0, 0};
  Vec3 spacing{1, 1, 1};
  bool has_geometry = false;  ///< origin/spacing came from the file (VTK), not defaults (NumPy)
  std::vector<float> values;
};

namespace volume_detail {

inline std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

template <class T>
T byteswap_value(T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  std::reverse(b, b + sizeof(T));
  std::memcpy(&v, b, sizeof(T));
  return v;
}

// Converts n raw values of type T (byte order `big_endian`) at `src` to float.
template <class T>
void convert(const char* src, std::size_t n, bool big_endian, std::vector<float>& out) {
  out.resize(n);
  const bool swap = big_endian != (std::endian::native == std::endian::big);
  for (std::size_t i = 0; i < n; ++i) {
    T v;
    std::memcpy(&v, src + i * sizeof(T), sizeof(T));
    if (swap) v = byteswap_value(v);
    out[i] = float(v);
  }
}

/// Largest volume accepted: 2^34 points (64 GB of float32), at most 2^24 per axis.
inline constexpr long long kMaxVolumePoints = 1LL << 34;

// Returns the number of points; the bounds keep every size computed from it far from overflow.
inline std::size_t check_dims(const std::string& path, const std::array<long long, 3>& d) {
  const std::string dims = std::to_string(d[0]) + "x" + std::to_string(d[1]) + "x" + std::to_string(d[2]);
  for (long long n : d)
    if (n < 2 || n > (1 << 24))
      throw FileError(path, "volume of " + dims + " points; expected 2 .. 16777216 points per axis");
  if (d[0] * d[1] > kMaxVolumePoints / d[2])
    throw FileError(path, "volume of " + dims + " points is more than the limit of " + std::to_string(kMaxVolumePoints) +
                              " points");
  return std::size_t(d[0] * d[1] * d[2]);
}

inline std::string read_all(const std::string& path) {
  return read_regular_file(path, std::uint64_t(kMaxVolumePoints) * 8 + (1 << 20), "volume file");
}

}  // namespace volume_detail

/// The header of a NumPy .npy file: shape, order, element type (float32/float64 only) and where the
/// data starts. Throws FileError naming the file and what is wrong.
struct NpyHeader {
  std::vector<long long> shape;
  bool fortran = false;     ///< fortran_order: the first axis is the fastest
  bool big_endian = false;
  std::size_t elem = 4;     ///< 4 (float32) or 8 (float64)
  std::size_t offset = 0;   ///< of the first value in the file's contents
  std::size_t count() const {
    std::size_t n = 1;
    for (long long d : shape) n *= std::size_t(d);
    return n;
  }
};

inline NpyHeader parse_npy_header(const std::string& data, const std::string& path) {
  using namespace volume_detail;
  if (data.size() < 10 || std::memcmp(data.data(), "\x93NUMPY", 6) != 0)
    throw FileError(path, "not a NumPy .npy file (missing the \\x93NUMPY magic)");
  const int major = static_cast<unsigned char>(data[6]);
  std::size_t header_len, header_start;
  if (major == 1) {
    header_len = std::size_t(static_cast<unsigned char>(data[8])) | (std::size_t(static_cast<unsigned char>(data[9])) << 8);
    header_start = 10;
  } else if (major == 2 || major == 3) {
    if (data.size() < 12) throw FileError(path, "truncated .npy header");
    header_len = 0;
    for (int i = 0; i < 4; ++i) header_len |= std::size_t(static_cast<unsigned char>(data[8 + i])) << (8 * i);
    header_start = 12;
  } else {
    throw FileError(path, ".npy format version " + std::to_string(major) + "; expected 1, 2 or 3");
  }
  if (header_start + header_len > data.size()) throw FileError(path, "truncated .npy header");
  const std::string header = data.substr(header_start, header_len);
  auto value_of = [&](const std::string& key) {
    const auto k = header.find("'" + key + "'");
    if (k == std::string::npos) throw FileError(path, ".npy header has no '" + key + "' entry: " + header);
    const auto colon = header.find(':', k);
    std::size_t b = colon + 1;
    while (b < header.size() && header[b] == ' ') ++b;
    return b;
  };
  // dtype
  std::size_t p = value_of("descr");
  if (p >= header.size() || (header[p] != '\'' && header[p] != '"'))
    throw FileError(path, "unsupported .npy dtype description (structured arrays are not volumes)");
  const char q = header[p];
  const std::string descr = header.substr(p + 1, header.find(q, p + 1) - p - 1);
  // fortran_order
  p = value_of("fortran_order");
  const bool fortran = p < header.size() && header.compare(p, 4, "True") == 0;
  // shape
  p = value_of("shape");
  const auto close = header.find(')', p);
  if (p >= header.size() || header[p] != '(' || close == std::string::npos)
    throw FileError(path, "malformed .npy shape in " + header);
  std::vector<long long> shape;
  {
    std::string inner = header.substr(p + 1, close - p - 1);
    std::replace(inner.begin(), inner.end(), ',', ' ');
    std::istringstream ss(inner);
    long long n;
    while (ss >> n) shape.push_back(n);
  }
  NpyHeader h;
  h.shape = shape;
  h.fortran = fortran;
  h.offset = header_start + header_len;
  if (descr.size() != 3 || (descr[0] != '<' && descr[0] != '>' && descr[0] != '=' && descr[0] != '|') ||
      (descr.substr(1) != "f4" && descr.substr(1) != "f8"))
    throw FileError(path, "dtype '" + descr + "'; expected float32 ('<f4') or float64 ('<f8')");
  h.big_endian = descr[0] == '>';
  h.elem = descr[2] == '4' ? 4 : 8;
  return h;
}

/// Parses the contents of a NumPy .npy file (`path` names it in errors) holding a 3-D array of float32 or float64 (either byte order). C order
/// (fortran_order False) with shape (nz, ny, nx) — the last axis is x, the fastest; Fortran order with
/// shape (nx, ny, nz). Origin 0, spacing 1. Throws FileError naming the file and what is wrong.
inline Volume parse_npy(const std::string& data, const std::string& path) {
  using namespace volume_detail;
  const NpyHeader h = parse_npy_header(data, path);
  const std::vector<long long>& shape = h.shape;
  const bool fortran = h.fortran;
  if (shape.size() != 3) throw FileError(path, "array has " + std::to_string(shape.size()) + " dimensions; expected a 3-D volume");
  Volume v;
  const std::array<long long, 3> d = fortran ? std::array<long long, 3>{shape[0], shape[1], shape[2]}
                                             : std::array<long long, 3>{shape[2], shape[1], shape[0]};
  const std::size_t n = check_dims(path, d);
  v.dims = {int(d[0]), int(d[1]), int(d[2])};
  const std::size_t offset = h.offset, elem = h.elem;
  const bool big = h.big_endian;
  if (data.size() < offset + n * elem)
    throw FileError(path, "truncated data: " + std::to_string(data.size() - offset) + " bytes for " + std::to_string(n) +
                              " values of " + std::to_string(elem) + " bytes");
  if (elem == 4) convert<float>(data.data() + offset, n, big, v.values);
  else convert<double>(data.data() + offset, n, big, v.values);
  return v;
}

/// Reads a NumPy .npy file (see parse_npy).
inline Volume read_npy(const std::string& path) { return parse_npy(volume_detail::read_all(path), path); }

/// Parses the contents of a VTK legacy file (`path` names it in errors) with DATASET STRUCTURED_POINTS and one float or double SCALARS array of
/// POINT_DATA, ASCII or BINARY (big-endian, as the format prescribes). Throws FileError naming the
/// file, the keyword or value and what was expected.
inline Volume parse_vtk(const std::string& data, const std::string& path) {
  using namespace volume_detail;
  std::size_t pos = 0;
  auto next_line = [&]() -> std::string {
    if (pos >= data.size()) throw FileError(path, "unexpected end of file in the VTK header");
    std::size_t e = data.find('\n', pos);
    if (e == std::string::npos) e = data.size();
    std::string line = data.substr(pos, e - pos);
    pos = e + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line;
  };
  if (next_line().rfind("# vtk DataFile", 0) != 0) throw FileError(path, "not a VTK legacy file (first line must start with '# vtk DataFile')");
  next_line();  // title
  const std::string format = lower(next_line());
  const bool binary = format.rfind("binary", 0) == 0;
  if (!binary && format.rfind("ascii", 0) != 0) throw FileError(path, "format line '" + format + "'; expected ASCII or BINARY");
  Volume v;
  v.has_geometry = true;
  std::array<long long, 3> d{0, 0, 0};
  std::string type;
  long long npoints = -1;
  bool structured = false;
  while (true) {
    std::string line = next_line();
    std::istringstream ss(line);
    std::string key;
    if (!(ss >> key)) continue;
    key = lower(key);
    if (key == "dataset") {
      std::string kind;
      ss >> kind;
      if (lower(kind) != "structured_points")
        throw FileError(path, "DATASET " + kind + "; only STRUCTURED_POINTS (a uniform grid) is supported");
      structured = true;
    } else if (key == "dimensions") {
      if (!(ss >> d[0] >> d[1] >> d[2])) throw FileError(path, "malformed DIMENSIONS line: " + line);
    } else if (key == "origin") {
      if (!(ss >> v.origin.x >> v.origin.y >> v.origin.z)) throw FileError(path, "malformed ORIGIN line: " + line);
    } else if (key == "spacing" || key == "aspect_ratio") {
      if (!(ss >> v.spacing.x >> v.spacing.y >> v.spacing.z)) throw FileError(path, "malformed SPACING line: " + line);
    } else if (key == "point_data") {
      ss >> npoints;
    } else if (key == "cell_data") {
      throw FileError(path, "CELL_DATA; expected POINT_DATA scalars (values at the grid points)");
    } else if (key == "scalars") {
      std::string name;
      int comps = 1;
      ss >> name >> type;
      if (ss >> comps && comps != 1) throw FileError(path, "SCALARS with " + std::to_string(comps) + " components; expected 1");
      type = lower(type);
      if (type != "float" && type != "double")
        throw FileError(path, "SCALARS type '" + type + "'; expected float or double");
      std::string lt = next_line();  // LOOKUP_TABLE
      if (lower(lt).rfind("lookup_table", 0) != 0) pos -= lt.size() + 1;  // optional line: put it back
      break;
    } else if (key == "vectors" || key == "tensors" || key == "field" || key == "normals") {
      throw FileError(path, key + " data; expected one SCALARS array");
    }
  }
  if (!structured) throw FileError(path, "no DATASET STRUCTURED_POINTS line before the data");
  const std::size_t n = check_dims(path, d);
  if (npoints >= 0 && std::size_t(npoints) != n)
    throw FileError(path, "POINT_DATA " + std::to_string(npoints) + " but DIMENSIONS give " + std::to_string(n) + " points");
  for (int a = 0; a < 3; ++a)
    if (!(v.spacing[a] > 0)) throw FileError(path, "SPACING component " + std::to_string(v.spacing[a]) + "; expected > 0");
  v.dims = {int(d[0]), int(d[1]), int(d[2])};
  if (binary) {
    const std::size_t elem = type == "float" ? 4 : 8;
    if (data.size() < pos + n * elem)
      throw FileError(path, "truncated BINARY data: " + std::to_string(data.size() - std::min(pos, data.size())) + " bytes for " +
                                std::to_string(n) + " values");
    if (elem == 4) convert<float>(data.data() + pos, n, true, v.values);
    else convert<double>(data.data() + pos, n, true, v.values);
  } else {
    // Every ASCII value takes at least one character and one separator: refuse before allocating.
    const std::size_t left = data.size() - std::min(pos, data.size());
    if (left + 1 < 2 * n)
      throw FileError(path, "ASCII data: " + std::to_string(left) + " bytes cannot hold " + std::to_string(n) + " values");
    v.values.resize(n);
    const char* c = data.c_str() + std::min(pos, data.size());
    char* end = nullptr;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = std::strtod(c, &end);
      if (end == c) throw FileError(path, "ASCII data: value " + std::to_string(i) + " of " + std::to_string(n) + " is missing or not a number");
      v.values[i] = float(x);
      c = end;
    }
  }
  return v;
}

/// Reads a VTK legacy file (see parse_vtk).
inline Volume read_vtk(const std::string& path) { return parse_vtk(volume_detail::read_all(path), path); }

/// Reads a volume by file extension (.npy or .vtk); anything else is refused with the supported list.
inline Volume read_volume(const std::string& path) {
  const std::string l = volume_detail::lower(path);
  auto ends = [&](const char* s) { return l.size() >= std::strlen(s) && l.compare(l.size() - std::strlen(s), std::string::npos, s) == 0; };
  if (ends(".npy")) return read_npy(path);
  if (ends(".vtk")) return read_vtk(path);
  throw FileError(path, "unsupported volume format; expected NumPy .npy (3-D float32/float64) or VTK legacy .vtk "
                        "(STRUCTURED_POINTS)");
}

}  // namespace panoptes::app
