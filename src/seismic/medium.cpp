#include "seismic/medium.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

#include "core/echo.hpp"
#include "core/error.hpp"
#include "core/file_read.hpp"

namespace panoptes::seismic {

MediumSpec MediumSpec::homogeneous(double rho, double vp, double vs, double qp, double qs) {
  MediumSpec m;
  m.kind = Kind::layered;
  m.layers.push_back(Layer{0.0, rho, vp, vs, qp, qs});
  return m;
}

bool MediumBlock::attenuating() const {
  for (float q : qp)
    if (std::isfinite(q)) return true;
  for (float q : qs)
    if (std::isfinite(q)) return true;
  return false;
}

namespace {

// The value of 'key' in a .npy header (a Python dict literal): a quoted string without its quotes, a
// parenthesized tuple without its parentheses, or a bare word (True/False). By hand, not <regex>:
// std::regex cost ~5 CPU-s of compiling this unit (issue 34: a new user's first build).
std::optional<std::string> npy_header_value(const std::string& header, const std::string& key) {
  const std::size_t k = header.find("'" + key + "'");
  if (k == std::string::npos) return std::nullopt;
  std::size_t i = header.find_first_not_of(" \t", k + key.size() + 2);
  if (i == std::string::npos || header[i] != ':') return std::nullopt;
  i = header.find_first_not_of(" \t", i + 1);
  if (i == std::string::npos) return std::nullopt;
  const char open = header[i];
  if (open == '\'' || open == '(') {
    const std::size_t end = header.find(open == '(' ? ')' : '\'', i + 1);
    if (end == std::string::npos) return std::nullopt;
    return header.substr(i + 1, end - i - 1);
  }
  const std::size_t end = header.find_first_of(", }", i);
  return header.substr(i, end == std::string::npos ? std::string::npos : end - i);
}

}  // namespace

std::vector<float> read_npy_planes(const std::string& path, int nx, int ny, int nz, int k_begin, int k_end) {
  // A FIFO or device named as a medium file must be refused, not block the run (or read forever).
  regular_file_size(path, UINT64_MAX, "medium file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError(path, "cannot open medium file");
  char magic[8];
  if (!in.read(magic, 8) || std::memcmp(magic, "\x93NUMPY", 6) != 0)
    throw FileError(path, "not a .npy file (bad magic)");
  const int major = static_cast<unsigned char>(magic[6]);
  std::uint32_t header_len = 0;
  if (major == 1) {
    unsigned char b[2];
    if (!in.read(reinterpret_cast<char*>(b), 2)) throw FileError(path, "truncated .npy header");
    header_len = b[0] | (b[1] << 8);
  } else if (major == 2 || major == 3) {
    unsigned char b[4];
    if (!in.read(reinterpret_cast<char*>(b), 4)) throw FileError(path, "truncated .npy header");
    header_len = b[0] | (b[1] << 8) | (b[2] << 16) | (std::uint32_t(b[3]) << 24);
  } else {
    throw FileError(path, "unsupported .npy version " + std::to_string(major));
  }
  if (header_len > 65536) throw FileError(path, "implausible .npy header length");
  std::string header(header_len, '\0');
  if (!in.read(header.data(), header_len)) throw FileError(path, "truncated .npy header");
  const auto data_start = static_cast<std::streamoff>(in.tellg());
  const auto descr = npy_header_value(header, "descr");
  if (!descr) throw FileError(path, ".npy header has no 'descr'");
  if (*descr != "<f4") throw FileError(path, "dtype '" + echo(*descr) + "' (expected float32 '<f4')");
  const auto fortran = npy_header_value(header, "fortran_order");
  if (!fortran || (*fortran != "True" && *fortran != "False"))
    throw FileError(path, ".npy header has no 'fortran_order'");
  if (*fortran == "True") throw FileError(path, "Fortran-ordered array (expected C order, shape (nz, ny, nx))");
  const auto shape_text = npy_header_value(header, "shape");
  if (!shape_text) throw FileError(path, ".npy header has no 'shape'");
  std::vector<long long> shape;
  {
    const std::string& s = *shape_text;
    std::stringstream ss(s);
    std::string tok;
    while (std::getline(ss, tok, ',')) {
      if (tok.find_first_not_of(" \t") == std::string::npos) continue;
      shape.push_back(std::stoll(tok));
    }
  }
  const std::string want = "(" + std::to_string(nz) + ", " + std::to_string(ny) + ", " + std::to_string(nx) + ")";
  if (shape.size() != 3 || shape[0] != nz || shape[1] != ny || shape[2] != nx)
    throw FileError(path, "shape (" + echo(*shape_text) + ") does not match the grid: expected (nz, ny, nx) = " + want);
  const std::size_t plane = std::size_t(nx) * ny;
  in.seekg(0, std::ios::end);
  const auto size = static_cast<std::streamoff>(in.tellg());
  if (size < data_start + static_cast<std::streamoff>(plane * nz * 4))
    throw FileError(path, "truncated data: " + std::to_string(size - data_start) + " bytes, expected " +
                              std::to_string(plane * nz * 4));
  std::vector<float> out(plane * (k_end - k_begin));
  in.seekg(data_start + static_cast<std::streamoff>(plane * k_begin * 4));
  if (!in.read(reinterpret_cast<char*>(out.data()), static_cast<std::streamsize>(out.size() * 4)))
    throw FileError(path, "read error");
  return out;
}

void write_npy(const std::string& path, const std::vector<float>& data, int nx, int ny, int nz) {
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + std::to_string(nz) + ", " +
                       std::to_string(ny) + ", " + std::to_string(nx) + "), }";
  // Pad so magic + len + header + '\n' is a multiple of 64 (the .npy spec).
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::ofstream out(path, std::ios::binary);
  if (!out) throw FileError(path, "cannot create file");
  out.write("\x93NUMPY\x01\x00", 8);
  const unsigned char len[2] = {static_cast<unsigned char>(header.size() & 0xff),
                                static_cast<unsigned char>(header.size() >> 8)};
  out.write(reinterpret_cast<const char*>(len), 2);
  out.write(header.data(), static_cast<std::streamsize>(header.size()));
  out.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size() * 4));
  if (!out) throw FileError(path, "write error");
}

namespace {

std::string node_name(int i, int j, int k, double h) {
  std::ostringstream s;
  s << "node (" << i << ", " << j << ", " << k << ") at (" << i * h << ", " << j * h << ", " << k * h << ") m";
  return s.str();
}

void check_values(const MediumBlock& b, double h, const std::string& where) {
  for (int k = b.k0; k < b.k0 + b.nk; ++k)
    for (int j = 0; j < b.ny; ++j)
      for (int i = 0; i < b.nx; ++i) {
        const auto n = b.index(i, j, k);
        const double rho = b.rho[n], vp = b.vp[n], vs = b.vs[n];
        auto fail = [&](const std::string& what) {
          throw Error(where + ": " + what + " at " + node_name(i, j, k, h));
        };
        if (!(rho > 0) || !std::isfinite(rho)) fail("density " + std::to_string(rho) + " (must be > 0)");
        if (!(vp > 0) || !std::isfinite(vp)) fail("Vp " + std::to_string(vp) + " (must be > 0)");
        if (!(vs > 0) || !std::isfinite(vs)) fail("Vs " + std::to_string(vs) + " (must be > 0; fluids are not supported)");
        if (vs > vp / std::sqrt(2.0) * (1 + 1e-6))
          fail("Vs " + std::to_string(vs) + " > Vp/sqrt(2) = " + std::to_string(vp / std::sqrt(2.0)) +
               " (negative Lame lambda)");
        if (!(b.qp[n] > 0)) fail("Qp " + std::to_string(b.qp[n]) + " (must be > 0, inf for elastic)");
        if (!(b.qs[n] > 0)) fail("Qs " + std::to_string(b.qs[n]) + " (must be > 0, inf for elastic)");
      }
}

}  // namespace

MediumBlock sample_medium(const MediumSpec& spec, const GridSpec& grid, int k_begin, int k_end) {
  MediumBlock b;
  b.nx = grid.nx;
  b.ny = grid.ny;
  b.k0 = k_begin;
  b.nk = k_end - k_begin;
  const std::size_t plane = std::size_t(grid.nx) * grid.ny;
  const std::size_t n = plane * b.nk;
  if (spec.kind == MediumSpec::Kind::layered) {
    require(!spec.layers.empty(), "medium: no layers given");
    require(spec.layers.front().top <= 0, "medium: the first layer must start at depth 0, got top = " +
                                              std::to_string(spec.layers.front().top) + " m");
    for (std::size_t l = 1; l < spec.layers.size(); ++l)
      require(spec.layers[l].top > spec.layers[l - 1].top,
              "medium: layer " + std::to_string(l) + " top " + std::to_string(spec.layers[l].top) +
                  " m is not below the previous layer's top " + std::to_string(spec.layers[l - 1].top) + " m");
    b.rho.resize(n);
    b.vp.resize(n);
    b.vs.resize(n);
    b.qp.resize(n);
    b.qs.resize(n);
    for (int k = k_begin; k < k_end; ++k) {
      const double z = k * grid.h;
      std::size_t l = 0;
      // A node exactly on an interface takes the lower layer's properties.
      while (l + 1 < spec.layers.size() && spec.layers[l + 1].top <= z + 1e-9 * grid.h) ++l;
      const Layer& L = spec.layers[l];
      const std::size_t o = plane * (k - k_begin);
      std::fill_n(b.rho.begin() + o, plane, float(L.rho));
      std::fill_n(b.vp.begin() + o, plane, float(L.vp));
      std::fill_n(b.vs.begin() + o, plane, float(L.vs));
      std::fill_n(b.qp.begin() + o, plane, float(L.qp));
      std::fill_n(b.qs.begin() + o, plane, float(L.qs));
    }
    check_values(b, grid.h, "medium");
  } else {
    require(!spec.rho_file.empty() && !spec.vp_file.empty() && !spec.vs_file.empty(),
            "medium: files for rho, vp and vs are required");
    b.rho = read_npy_planes(spec.rho_file, grid.nx, grid.ny, grid.nz, k_begin, k_end);
    b.vp = read_npy_planes(spec.vp_file, grid.nx, grid.ny, grid.nz, k_begin, k_end);
    b.vs = read_npy_planes(spec.vs_file, grid.nx, grid.ny, grid.nz, k_begin, k_end);
    b.qp = spec.qp_file.empty() ? std::vector<float>(n, float(spec.qp))
                                : read_npy_planes(spec.qp_file, grid.nx, grid.ny, grid.nz, k_begin, k_end);
    b.qs = spec.qs_file.empty() ? std::vector<float>(n, float(spec.qs))
                                : read_npy_planes(spec.qs_file, grid.nx, grid.ny, grid.nz, k_begin, k_end);
    check_values(b, grid.h, "medium files (" + spec.rho_file + ", " + spec.vp_file + ", " + spec.vs_file + ")");
  }
  return b;
}

}  // namespace panoptes::seismic
