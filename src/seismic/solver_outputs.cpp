#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "core/error.hpp"
#include "seismic/denormals.hpp"
#include "seismic/solver_impl.hpp"

namespace panoptes::seismic {

// ==================================================================== outputs: receivers, snapshots, seismograms

void Solver::Impl::record() {
  rec_time.push_back((nsteps + 0.5) * dt);
  const std::array<const Vec*, 3> f = {&vx, &vy, &vz};
  for (std::size_t r = 0; r < recv.size(); ++r)
    for (int c = 0; c < 3; ++c) {
      const ReceiverComp& rc = recv[r][c];
      double v = 0;
      if (rc.owned)
        for (int q = 0; q < 8; ++q) v += rc.w[q] * (*f[c])[rc.n[q]];
      rec[r][c].push_back(v);
    }
}

namespace {
// Forward staggered 4th-order difference (times h) of f at i + ½·st.
[[gnu::always_inline]] inline float dfwd(const float* f, long i, long st) {
  return C1 * (f[i + st] - f[i]) + C2 * (f[i + 2 * st] - f[i - st]);
}

// φp and φs of one row of the two planes under a free surface, computed like the stress update
// computes its strains there (PANOPTES_STRAIN), so no velocity above the surface is read (the ghost
// planes above z = 0 hold no model value; the interior stencil read them and made φ on the surface
// plane 10-30x the interior's). Zm = 1, the surface plane z = 0: ∂z vz = −λ/(λ+2μ)(∂x vx + ∂y vy)
// (σzz = 0, as in the stress update); the x and y curl components from σxz = σyz = 0, i.e.
// ∂z vx = −∂x vz and ∂z vy = −∂y vz, so ωx = 2 ∂y vz, ωy = −2 ∂x vz on the two edges at z = 0 around
// the node (the stress images make σxz, σyz antisymmetric about z = 0: the same condition), with vz
// at z = 0 extrapolated linearly from its planes at h/2 and 3h/2 (2nd order; vz at h/2 alone would be
// 1st order, ∂z vz ≠ 0 at the surface). ωz lies in the plane and keeps the interior stencil.
// Zm = 2, the plane z = h: 2nd-order ∂z vz (as the stress update) and 2nd-order ∂z vx, ∂z vy on the
// edges at z = h/2 (as the stress update's σxz, σyz there); the edges at 3h/2 keep 4th order.
template <int Zm, class M>
[[gnu::always_inline]] inline void derived_surface_row(const M& m, int nx, long Y, long Z, float ih,
                                                       const float* __restrict ux, const float* __restrict uy,
                                                       const float* __restrict uz, float* __restrict pp,
                                                       float* __restrict ps) {
#pragma omp simd
  for (int i = 0; i < nx; ++i) {
    const float exx = C1 * (ux[i] - ux[i - 1]) + C2 * (ux[i + 1] - ux[i - 2]);
    const float eyy = C1 * (uy[i] - uy[i - Y]) + C2 * (uy[i + Y] - uy[i - 2 * Y]);
    float ezz, wx = 0, wy = 0, wz = 0;
    if constexpr (Zm == 1) {
      const float la = m(LAM, i), tm = m(TWOMU, i);
      ezz = -la / (la + tm) * (exx + eyy);
      // ∂ of vz(z = 0) = 1.5 vz(h/2) − 0.5 vz(3h/2) on the two edges at ±½ around the node, times 2
      // (ω = ±2 ∂vz) and times 2 again (two edges instead of the interior's four: 0.25·sum is the node value).
      wx = 4.0f * (1.5f * (dfwd(uz, i, Y) + dfwd(uz, i - Y, Y)) - 0.5f * (dfwd(uz, i + Z, Y) + dfwd(uz, i + Z - Y, Y)));
      wy = -4.0f * (1.5f * (dfwd(uz, i, 1) + dfwd(uz, i - 1, 1)) - 0.5f * (dfwd(uz, i + Z, 1) + dfwd(uz, i + Z - 1, 1)));
    } else {
      ezz = uz[i] - uz[i - Z];
      wx += dfwd(uz, i, Y) - dfwd(uy, i, Z);
      wx += dfwd(uz, i - Z, Y) - (uy[i] - uy[i - Z]);
      wx += dfwd(uz, i - Y, Y) - dfwd(uy, i - Y, Z);
      wx += dfwd(uz, i - Y - Z, Y) - (uy[i - Y] - uy[i - Y - Z]);
      wy += dfwd(ux, i, Z) - dfwd(uz, i, 1);
      wy += (ux[i] - ux[i - Z]) - dfwd(uz, i - Z, 1);
      wy += dfwd(ux, i - 1, Z) - dfwd(uz, i - 1, 1);
      wy += (ux[i - 1] - ux[i - 1 - Z]) - dfwd(uz, i - 1 - Z, 1);
    }
    wz += dfwd(uy, i, 1) - dfwd(ux, i, Y);
    wz += dfwd(uy, i - Y, 1) - dfwd(ux, i - Y, Y);
    wz += dfwd(uy, i - 1, 1) - dfwd(ux, i - 1, Y);
    wz += dfwd(uy, i - 1 - Y, 1) - dfwd(ux, i - 1 - Y, Y);
    pp[i] = ih * (exx + eyy + ezz);
    ps[i] = 0.25f * ih * std::sqrt(wx * wx + wy * wy + wz * wz);
  }
}
}  // namespace

void Solver::compute_derived() {
  Impl& s = *impl_;
  if (s.phip.size() != s.N) {
    s.phip.assign(s.N, 0.0f);
    s.phis.assign(s.N, 0.0f);
  }
  const long Y = s.sy, Z = s.sz;
  const float ih = float(1.0 / s.h);
  const int nx = s.nx, ny = s.ny, nzl = s.nzl;
#pragma omp parallel
  {
    const FlushSubnormals flush;  // as in step(): derivatives of tiny velocities can underflow
#pragma omp for collapse(2) schedule(static)
    for (int k = 0; k < nzl; ++k)
      for (int j = 0; j < ny; ++j) {
        const std::size_t b = s.idx(0, j, k);
        const float* __restrict ux = s.vx.data() + b;
        const float* __restrict uy = s.vy.data() + b;
        const float* __restrict uz = s.vz.data() + b;
        float* __restrict pp = s.phip.data() + b;
        float* __restrict ps = s.phis.data() + b;
        // Only the rank owning the global planes 0 and 1 (slabs have >= 2 planes) has surface rows.
        const int g = k + s.kb;
        if (s.free_surface && g <= 1) {
          const std::size_t r = std::size_t(k) * ny + j;
          if (g == 1) derived_surface_row<2>(UniformMat{nullptr}, nx, Y, Z, ih, ux, uy, uz, pp, ps);
          else if (const int u = s.row_mat[r]; u >= 0)
            derived_surface_row<1>(UniformMat{s.mat_tuples.data() + std::size_t(u) * s.K}, nx, Y, Z, ih, ux, uy, uz, pp, ps);
          else if (s.mat_table) derived_surface_row<1>(s.table_mat().row(b), nx, Y, Z, ih, ux, uy, uz, pp, ps);
          else derived_surface_row<1>(s.dense_mat().row(b), nx, Y, Z, ih, ux, uy, uz, pp, ps);
          continue;
        }
        auto d = [](const float* f, long i, long st) {  // forward staggered derivative at i + ½·st
          return C1 * (f[i + st] - f[i]) + C2 * (f[i + 2 * st] - f[i - st]);
        };
#pragma omp simd
        for (int i = 0; i < nx; ++i) {
          pp[i] = ih * (C1 * (ux[i] - ux[i - 1]) + C2 * (ux[i + 1] - ux[i - 2]) + C1 * (uy[i] - uy[i - Y]) +
                        C2 * (uy[i + Y] - uy[i - 2 * Y]) + C1 * (uz[i] - uz[i - Z]) + C2 * (uz[i + Z] - uz[i - 2 * Z]));
          // ωx = ∂y vz − ∂z vy on (0, ½, ½) edges, ωy = ∂z vx − ∂x vz on (½, 0, ½), ωz = ∂x vy − ∂y vx on (½, ½, 0);
          // each averaged over the four edges around the node.
          // Written out (not loops over offset lists) so that the i loop vectorizes; same terms, same order.
          float wx = 0, wy = 0, wz = 0;
          wx += d(uz, i, Y) - d(uy, i, Z);
          wx += d(uz, i - Z, Y) - d(uy, i - Z, Z);
          wx += d(uz, i - Y, Y) - d(uy, i - Y, Z);
          wx += d(uz, i - Y - Z, Y) - d(uy, i - Y - Z, Z);
          wy += d(ux, i, Z) - d(uz, i, 1);
          wy += d(ux, i - Z, Z) - d(uz, i - Z, 1);
          wy += d(ux, i - 1, Z) - d(uz, i - 1, 1);
          wy += d(ux, i - 1 - Z, Z) - d(uz, i - 1 - Z, 1);
          wz += d(uy, i, 1) - d(ux, i, Y);
          wz += d(uy, i - Y, 1) - d(ux, i - Y, Y);
          wz += d(uy, i - 1, 1) - d(ux, i - 1, Y);
          wz += d(uy, i - 1 - Y, 1) - d(ux, i - 1 - Y, Y);
          ps[i] = 0.25f * ih * std::sqrt(wx * wx + wy * wy + wz * wz);
        }
      }
  }
}

const std::vector<std::string>& Solver::field_names() {
  static const std::vector<std::string> names = {"vx",  "vy",  "vz",  "sxx",   "syy",  "szz",
                                                 "sxy", "sxz", "syz", "phi_p", "phi_s"};
  return names;
}

std::vector<float> Solver::gather_field(const std::string& name) {
  Impl& s = *impl_;
  const Vec* f = name == "vx" ? &s.vx : name == "vy" ? &s.vy : name == "vz" ? &s.vz : name == "sxx" ? &s.sxx
               : name == "syy" ? &s.syy : name == "szz" ? &s.szz : name == "sxy" ? &s.sxy : name == "sxz" ? &s.sxz
               : name == "syz" ? &s.syz : nullptr;
  if (name == "phi_p" || name == "phi_s") {
    compute_derived();
    f = name == "phi_p" ? &s.phip : &s.phis;
  }
  if (!f) {
    std::string list;
    for (const auto& n : field_names()) list += (list.empty() ? "" : ", ") + n;
    throw Error("unknown field '" + name + "' (expected one of " + list + ")");
  }
  // This rank's planes without ghosts, packed.
  const std::size_t plane = std::size_t(s.nx) * s.ny;
  if (plane * std::size_t(s.nz) > std::size_t(std::numeric_limits<int>::max()))
    throw Error("field '" + name + "' has more than 2^31 values: too large to gather on one rank");
  std::vector<float> local(plane * s.nzl);
  for (int k = 0; k < s.nzl; ++k)
    for (int j = 0; j < s.ny; ++j) {
      const float* src = f->data() + s.idx(0, j, k);
      std::copy(src, src + s.nx, local.begin() + std::ptrdiff_t((std::size_t(k) * s.ny + j) * s.nx));
    }
#ifdef PANOPTES_HAVE_MPI
  if (s.comm != MPI_COMM_NULL && s.size > 1) {
    // Slabs are contiguous in k and in rank order: a plain Gatherv assembles the global array.
    std::vector<int> counts(s.size), displs(s.size);
    for (int r = 0; r < s.size; ++r) {
      const int b = int((long long)s.nz * r / s.size), e = int((long long)s.nz * (r + 1) / s.size);
      counts[r] = int(plane * (e - b));
      displs[r] = int(plane * b);
    }
    std::vector<float> global(s.rank == 0 ? plane * s.nz : 0);
    MPI_Gatherv(local.data(), int(local.size()), MPI_FLOAT, global.data(), counts.data(), displs.data(), MPI_FLOAT, 0,
                s.comm);
    return global;
  }
#endif
  return local;
}

double Solver::energy() const {
  const Impl& s = *impl_;
  const int n = s.npml;
  const int i0 = n, i1 = s.nx - n, j0 = n, j1 = s.ny - n;
  const int g0 = s.free_surface ? 0 : n, g1 = s.nz - n;
  const int k0 = std::max(g0, s.kb) - s.kb, k1 = std::min(g1, s.ke) - s.kb;
  const double q = s.h / s.dt;  // stored coefficients are (dt/h)·modulus or (dt/h)/ρ
  double e = 0;
#pragma omp parallel for collapse(2) reduction(+ : e) schedule(static)
  for (int k = k0; k < std::max(k0, k1); ++k)
    for (int j = j0; j < j1; ++j)
      for (int i = i0; i < i1; ++i) {
        const std::size_t m = s.idx(i, j, k);
        const double rx = 1.0 / (q * s.mat(BX, m)), ry = 1.0 / (q * s.mat(BY, m)), rz = 1.0 / (q * s.mat(BZ, m));
        const double kin = 0.5 * (rx * s.vx[m] * s.vx[m] + ry * s.vy[m] * s.vy[m] + rz * s.vz[m] * s.vz[m]);
        const double mu = 0.5 * q * s.mat(TWOMU, m), la = q * s.mat(LAM, m);
        const double tr = double(s.sxx[m]) + s.syy[m] + s.szz[m];
        const double sq = double(s.sxx[m]) * s.sxx[m] + double(s.syy[m]) * s.syy[m] + double(s.szz[m]) * s.szz[m];
        double w = sq / (4 * mu) - la * tr * tr / (4 * mu * (3 * la + 2 * mu));
        w += double(s.sxy[m]) * s.sxy[m] / (2 * q * s.mat(MUXY, m)) +
             double(s.sxz[m]) * s.sxz[m] / (2 * q * s.mat(MUXZ, m)) + double(s.syz[m]) * s.syz[m] / (2 * q * s.mat(MUYZ, m));
        e += kin + w;
      }
  return s.allreduce_sum(e * s.h * s.h * s.h);
}

std::vector<Seismogram> Solver::gather_seismograms() const {
  const Impl& s = *impl_;
  const std::size_t T = s.rec_time.size(), R = s.rec.size();
  std::vector<double> buf(R * 3 * T);
  for (std::size_t r = 0; r < R; ++r)
    for (int c = 0; c < 3; ++c) std::copy(s.rec[r][c].begin(), s.rec[r][c].end(), buf.begin() + (r * 3 + c) * T);
#ifdef PANOPTES_HAVE_MPI
  // Exactly one rank owns each component; the others contribute zeros, so the sum is exact.
  if (s.comm != MPI_COMM_NULL && s.size > 1) {
    if (s.rank == 0)
      MPI_Reduce(MPI_IN_PLACE, buf.data(), int(buf.size()), MPI_DOUBLE, MPI_SUM, 0, s.comm);
    else
      MPI_Reduce(buf.data(), nullptr, int(buf.size()), MPI_DOUBLE, MPI_SUM, 0, s.comm);
  }
#endif
  std::vector<Seismogram> out;
  if (s.rank != 0) return out;
  for (std::size_t r = 0; r < R; ++r) {
    Seismogram g;
    g.name = s.cfg.receivers[r].name;
    g.position = s.cfg.receivers[r].position;
    g.time = s.rec_time;
    g.vx.assign(buf.begin() + (r * 3 + 0) * T, buf.begin() + (r * 3 + 1) * T);
    g.vy.assign(buf.begin() + (r * 3 + 1) * T, buf.begin() + (r * 3 + 2) * T);
    g.vz.assign(buf.begin() + (r * 3 + 2) * T, buf.begin() + (r * 3 + 3) * T);
    out.push_back(std::move(g));
  }
  return out;
}

void Solver::write_seismograms(const std::string& dir) const {
  const auto all = gather_seismograms();
  if (impl_->rank != 0) return;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw FileError(dir, "cannot create directory: " + ec.message());
  for (const auto& g : all) {
    const std::string path = dir + "/" + g.name + ".csv";
    std::ofstream out(path);
    if (!out) throw FileError(path, "cannot create file");
    out << "time,vx,vy,vz\n";
    out.precision(9);
    for (std::size_t t = 0; t < g.time.size(); ++t)
      out << g.time[t] << ',' << g.vx[t] << ',' << g.vy[t] << ',' << g.vz[t] << '\n';
    if (!out) throw FileError(path, "write error");
  }
}

}  // namespace panoptes::seismic
