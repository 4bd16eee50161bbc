#include <omp.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>
#include <unordered_map>

#include "core/error.hpp"
#include "seismic/attenuation.hpp"
#include "seismic/medium.hpp"
#include "seismic/solver_impl.hpp"

namespace panoptes::seismic {

// ==================================================================== setup

void Solver::Impl::init(const SolverConfig& c) {
  cfg = c;
  std::string err;
  try {
    cfg.validate();
  } catch (const Error& e) {
    err = e.what();
  }
  agree(err);
  nx = cfg.grid.nx;
  ny = cfg.grid.ny;
  nz = cfg.grid.nz;
  h = cfg.grid.h;
  npml = cfg.boundary.pml_cells;
  free_surface = cfg.boundary.free_surface;
  agree(nz / size >= 2 ? "" : "grid nz = " + std::to_string(nz) + " is too small for " + std::to_string(size) +
                                  " ranks: every rank needs at least 2 z planes");
  kb = int((long long)nz * rank / size);
  ke = int((long long)nz * (rank + 1) / size);
  nzl = ke - kb;
  sy = nx + 2 * G;
  sz = sy * (ny + 2 * G);
  N = std::size_t(sz) * (nzl + 2 * G);

  MediumBlock mb;
  try {
    mb = sample_medium(cfg.medium, cfg.grid, kb, std::min(ke + 1, nz));
  } catch (const Error& e) {
    err = e.what();
  }
  agree(err);
  const bool visco_local = mb.attenuating();
  const bool visco = allreduce_max(visco_local ? 1.0 : 0.0) > 0;
  L = visco ? cfg.attenuation.mechanisms : 0;
  // Largest P velocity: unrelaxed when attenuating (that is what the CFL condition sees).
  setup_materials(mb);  // also sets vpmax (global) and dt
  setup_pml();
  setup_sources();
  setup_receivers();
  const std::size_t reserve = std::size_t(cfg.steps / cfg.record_every + 2);
  rec_time.reserve(reserve);
  for (auto& r : rec)
    for (auto& c3 : r) c3.reserve(reserve);
  rowbuf.assign(std::size_t(omp_get_max_threads()), Vec(6 * std::size_t(nx)));
  // The sweep keeps about 28 rows-planes per block row in cache (σ: 3 fields × 5 planes + 3, v:
  // 3 × 5, material ids): aim at 1 MiB, half of an L2.
  yblock = std::clamp(int((1 << 20) / (28 * 4 * sy)), 8, 64);
}

void Solver::Impl::setup_materials(const MediumBlock& mb) {
  const double fdom = cfg.dominant_frequency();
  double fmin = cfg.attenuation.fmin, fmax = cfg.attenuation.fmax;
  if (fmin <= 0) fmin = fdom / 10;
  if (fmax <= 0) fmax = fdom * 10;
  const double fref = cfg.attenuation.fref > 0 ? cfg.attenuation.fref : fdom;
  std::string err;
  if (L > 0 && !(fmin > 0 && fmax > fmin))
    err = "attenuation band [" + std::to_string(fmin) + ", " + std::to_string(fmax) + "] Hz is invalid";
  agree(err);
  std::map<float, ZenerFit> fits;
  auto fit_for = [&](float q) -> const ZenerFit& {
    auto it = fits.find(q);
    if (it == fits.end()) it = fits.emplace(q, fit_constant_q(q, fmin, fmax, std::max(L, 1))).first;
    return it->second;
  };
  // Unrelaxed moduli on the sampled planes [kb, kb + mb.nk).
  const std::size_t nn = mb.rho.size();
  std::vector<double> rho(nn), piU(nn), muU(nn);
  std::vector<double> ya, yb;  // per node per mechanism: πU·Yα, μU·Yβ
  if (L > 0) {
    ya.resize(nn * L);
    yb.resize(nn * L);
  }
  const double wref = 2 * std::numbers::pi * fref;
  double vmax = 0;
  for (std::size_t n = 0; n < nn; ++n) {
    rho[n] = mb.rho[n];
    double fa = 1, fb = 1;
    if (L > 0) {
      const ZenerFit& a = fit_for(mb.qp[n]);
      const ZenerFit& b = fit_for(mb.qs[n]);
      fa = a.unrelaxed_factor(wref);
      fb = b.unrelaxed_factor(wref);
      piU[n] = rho[n] * double(mb.vp[n]) * mb.vp[n] * fa;
      muU[n] = rho[n] * double(mb.vs[n]) * mb.vs[n] * fb;
      for (int l = 0; l < L; ++l) {
        ya[n * L + l] = piU[n] * a.weight[l];
        yb[n * L + l] = muU[n] * b.weight[l];
      }
    } else {
      piU[n] = rho[n] * double(mb.vp[n]) * mb.vp[n];
      muU[n] = rho[n] * double(mb.vs[n]) * mb.vs[n];
    }
    vmax = std::max(vmax, std::sqrt(piU[n] / rho[n]));
  }
  vpmax = allreduce_max(vmax);
  const double dtmax = stable_time_step(h, vpmax);
  if (cfg.dt > 0) {
    if (cfg.dt > dtmax * (1 + 1e-12)) {
      std::ostringstream s;
      s << "time step dt = " << cfg.dt << " s violates the CFL stability condition: the largest stable time step is "
        << dtmax << " s (h = " << h << " m, max unrelaxed Vp = " << vpmax << " m/s, limit Vp*dt/h <= "
        << 1.0 / (std::sqrt(3.0) * (9.0 / 8.0 + 1.0 / 24.0)) << ")";
      err = s.str();
    }
    dt = cfg.dt;
  } else {
    dt = cfg.courant * dtmax;
  }
  agree(err);

  const int mx = mb.nx, my = mb.ny, mk = mb.nk;
  auto m = [&](int i, int j, int k) {  // clamped node index into the sampled block (global k)
    i = std::clamp(i, 0, mx - 1);
    j = std::clamp(j, 0, my - 1);
    k = std::clamp(k, kb, kb + mk - 1);
    return mb.index(i, j, k);
  };
  for (Vec* v : {&vx, &vy, &vz, &sxx, &syy, &szz, &sxy, &sxz, &syz}) v->assign(N, 0.0f);
  const double s = dt / h;
  auto harm4 = [&](std::size_t a, std::size_t b, std::size_t c, std::size_t d) {
    return 4.0 / (1.0 / muU[a] + 1.0 / muU[b] + 1.0 / muU[c] + 1.0 / muU[d]);
  };
  if (L > 0) {
    relax_a.resize(L);
    relax_b.resize(L);
    const ZenerFit& any = fit_for(std::numeric_limits<float>::infinity());
    for (int l = 0; l < L; ++l) {
      const double wdt = any.omega[l] * dt;
      relax_a[l] = float((1 - wdt / 2) / (1 + wdt / 2));
      relax_b[l] = float(wdt / (1 + wdt / 2));
    }
    for (auto* v : {&rxx, &ryy, &rzz, &rxy, &rxz, &ryz}) v->assign(L, Vec(N, 0.0f));
  }
  K = MECH + 5 * L;
  // The coefficients of node (i, j, k) (global k).
  auto coefficients = [&](int i, int j, int k, float* t) {
    const auto c = m(i, j, k);
    t[BX] = float(s / (0.5 * (rho[c] + rho[m(i + 1, j, k)])));
    t[BY] = float(s / (0.5 * (rho[c] + rho[m(i, j + 1, k)])));
    t[BZ] = float(s / (0.5 * (rho[c] + rho[m(i, j, k + 1)])));
    t[LAM] = float(s * (piU[c] - 2 * muU[c]));
    t[TWOMU] = float(s * 2 * muU[c]);
    const std::array<std::size_t, 4> cxy = {c, m(i + 1, j, k), m(i, j + 1, k), m(i + 1, j + 1, k)};
    const std::array<std::size_t, 4> cxz = {c, m(i + 1, j, k), m(i, j, k + 1), m(i + 1, j, k + 1)};
    const std::array<std::size_t, 4> cyz = {c, m(i, j + 1, k), m(i, j, k + 1), m(i, j + 1, k + 1)};
    auto h4 = [&](const std::array<std::size_t, 4>& q) { return harm4(q[0], q[1], q[2], q[3]); };
    t[MUXY] = float(s * h4(cxy));
    t[MUXZ] = float(s * h4(cxz));
    t[MUYZ] = float(s * h4(cyz));
    for (int l = 0; l < L; ++l) {
      t[CL(l)] = float(s * (ya[c * L + l] - 2 * yb[c * L + l]));
      t[CM(l)] = float(s * 2 * yb[c * L + l]);
      auto avg = [&](const std::array<std::size_t, 4>& q) {
        double v = 0;
        for (auto x : q) v += yb[x * L + l];
        return s * v / 4;
      };
      t[CMXY(l)] = float(avg(cxy));
      t[CMXZ(l)] = float(avg(cxz));
      t[CMYZ(l)] = float(avg(cyz));
    }
  };
  // Table of distinct tuples (compared bytewise, so the stored floats are exactly the computed
  // ones); falls back to one array per coefficient beyond 65,536 tuples. Type 0 = all zero (ghosts).
  const std::size_t max_types = std::getenv("PANOPTES_SEISMIC_DENSE_MATERIALS") ? 1 : 65536;
  std::vector<float> t(std::size_t(K), 0.0f);
  const std::size_t tb = std::size_t(K) * sizeof(float);
  std::string key(tb, '\0'), last;
  std::unordered_map<std::string, std::uint16_t> ids;
  std::vector<float>& types = mat_tuples;
  types = t;
  ids.emplace(key, 0);
  mat_id.assign(N, 0);
  std::uint16_t last_id = 0;
  mat_table = true;
  for (int k = kb; k < ke && mat_table; ++k)
    for (int j = 0; j < ny && mat_table; ++j)
      for (int i = 0; i < nx; ++i) {
        coefficients(i, j, k, t.data());
        std::memcpy(key.data(), t.data(), tb);
        if (key != last) {  // layered media repeat the previous cell's tuple almost always
          auto it = ids.find(key);
          if (it == ids.end()) {
            if (ids.size() >= max_types) {
              mat_table = false;
              break;
            }
            it = ids.emplace(key, std::uint16_t(ids.size())).first;
            types.insert(types.end(), t.begin(), t.end());
          }
          last = key;
          last_id = it->second;
        }
        mat_id[idx(i, j, k - kb)] = last_id;
      }
  if (mat_table) {
    ntypes = ids.size();
    mat_tab.assign(std::size_t(K) * ntypes, 0.0f);
    for (std::size_t q = 0; q < ntypes; ++q)
      for (int f = 0; f < K; ++f) mat_tab[std::size_t(f) * ntypes + q] = types[q * K + f];
    row_mat.assign(std::size_t(nzl) * ny, -1);
    for (int k = 0; k < nzl; ++k)
      for (int j = 0; j < ny; ++j) {
        const std::uint16_t* r = mat_id.data() + idx(0, j, k);
        if (std::all_of(r, r + nx, [&](std::uint16_t v) { return v == r[0]; })) row_mat[std::size_t(k) * ny + j] = r[0];
      }
  } else {
    row_mat.assign(std::size_t(nzl) * ny, -1);
    mat_tuples.clear();
    std::vector<std::uint16_t>().swap(mat_id);
    mat_dense.assign(std::size_t(K), Vec(N, 0.0f));
    for (int k = kb; k < ke; ++k)
      for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
          coefficients(i, j, k, t.data());
          const std::size_t n = idx(i, j, k - kb);
          for (int f = 0; f < K; ++f) mat_dense[f][n] = t[f];
        }
    for (const Vec& v : mat_dense) mat_ptr.push_back(v.data());
  }
}

void Solver::Impl::setup_pml() {
  const double Lw = std::max(npml, 1) * h;
  const double d0 = -3.0 * vpmax * std::log(cfg.boundary.pml_reflection) / (2.0 * Lw);  // N = 2
  const double fa = cfg.boundary.pml_frequency > 0 ? cfg.boundary.pml_frequency : cfg.dominant_frequency();
  const double amax = std::numbers::pi * fa;
  // depth (0..1+) into the absorbing layer of the position x [in nodes] along an axis of n nodes.
  auto coef = [&](double x, int n, bool low, bool high, float& a, float& b) {
    double r = 0;
    if (low && x < npml) r = (npml - x) / std::max(npml, 1);
    if (high && x > n - 1 - npml) r = (x - (n - 1 - npml)) / std::max(npml, 1);
    const double d = d0 * r * r;
    const double al = amax * std::max(0.0, 1.0 - r);
    b = float(std::exp(-(d + al) * dt));
    a = (d + al) > 0 ? float(d * (double(b) - 1.0) / (d + al)) : 0.0f;
  };
  auto build = [&](PmlAxis& p, int n, int offset, int count, bool low, bool high) {
    p.slot.assign(count, -1);
    p.a_full.assign(count, 0);
    p.b_full.assign(count, 1);
    p.a_half.assign(count, 0);
    p.b_half.assign(count, 1);
    if (npml == 0) return;
    for (int l = 0; l < count; ++l) {
      const int g = l + offset;
      const bool in = (low && g < npml) || (high && g >= n - npml - 1);
      if (!in) continue;
      p.slot[l] = int(p.indices.size());
      p.indices.push_back(l);
      coef(g, n, low, high, p.a_full[l], p.b_full[l]);
      coef(g + 0.5, n, low, high, p.a_half[l], p.b_half[l]);
    }
  };
  build(pmlx, nx, 0, nx, true, true);
  // The x layers are two runs of consecutive cells per row: their corrections are simd loops.
  for (int s = 0; s < pmlx.count(); ++s)
    if (s == 0 || pmlx.indices[s] != pmlx.indices[s - 1] + 1) pmlx.runs.push_back({pmlx.indices[s], pmlx.indices[s] + 1, s});
    else pmlx.runs.back()[1] = pmlx.indices[s] + 1;
  build(pmly, ny, 0, ny, true, true);
  build(pmlz, nz, kb, nzl, !free_surface, true);
  for (auto& v : psix) v.assign(std::size_t(pmlx.count()) * ny * nzl, 0.0f);
  for (auto& v : psiy) v.assign(std::size_t(pmly.count()) * nx * nzl, 0.0f);
  for (auto& v : psiz) v.assign(std::size_t(pmlz.count()) * nx * ny, 0.0f);
}

void Solver::Impl::setup_sources() {
  sources = cfg.sources;
  // Point sources are spread onto each staggered grid with a Kaiser-windowed sinc (Hicks 2002,
  // half-width 4 nodes, b = 6.31, weights normalised per axis): it represents an off-grid δ with
  // far less smoothing than trilinear weights, which matters for the shear components of a moment
  // tensor (they never sit on the source point). Within 4 nodes of a free surface the sinc would
  // need ghost nodes, so such sources use trilinear weights; weights that would fall above the
  // surface are dropped and the rest renormalised (total moment / force kept).
  auto kaiser_sinc = [](double d) {
    const double r = 4.0, b = 6.31;
    if (std::abs(d) >= r) return 0.0;
    const double x = std::numbers::pi * d;
    const double sinc = std::abs(d) < 1e-12 ? 1.0 : std::sin(x) / x;
    const double q = 1 - (d / r) * (d / r);
    return sinc * std::cyl_bessel_i(0.0, b * std::sqrt(q)) / std::cyl_bessel_i(0.0, b);
  };
  auto spread = [&](const std::array<double, 3>& p, std::array<double, 3> st, Vec& field, double amp, int src,
                    std::vector<Injection>& out, int mat = -1) {
    const bool sinc = !free_surface || p[2] / h >= 4.5;
    std::array<std::vector<std::pair<int, double>>, 3> ax;
    const int dims[3] = {nx, ny, nz};
    for (int a = 0; a < 3; ++a) {
      const double g = p[a] / h - st[a];
      const int i0 = int(std::floor(g));
      double sum = 0;
      if (sinc) {
        for (int i = i0 - 3; i <= i0 + 4; ++i) {
          const double w = kaiser_sinc(i - g);
          if (w != 0 && i >= 0 && i < dims[a]) ax[a].push_back({i, w});
          sum += w;
        }
      } else {
        const double f = g - i0;
        for (int i : {i0, i0 + 1}) {
          const double w = i == i0 ? 1 - f : f;
          if (w != 0 && i >= 0 && i < dims[a]) {
            ax[a].push_back({i, w});
            sum += w;
          }
        }
      }
      for (auto& [i, w] : ax[a]) w /= sum;
    }
    for (const auto& [k, wz] : ax[2])
      if (k >= kb && k < ke)
        for (const auto& [j, wy] : ax[1])
          for (const auto& [i, wx] : ax[0]) out.push_back({field.data(), idx(i, j, k - kb), k - kb, amp * wx * wy * wz, src, mat});
  };
  const double h3 = h * h * h;
  for (int s = 0; s < int(sources.size()); ++s) {
    const auto& S = sources[s];
    if (S.kind == SourceSpec::Kind::moment) {
      // σ_ij −= dt·Ṁ_ij(t)·δ_h: amplitude dt·M_ij/h³ times the rate of S.
      const auto& M = S.moment;
      const double a = dt / h3;
      spread(S.position, {0, 0, 0}, sxx, -a * M[0], s, stress_inj);
      spread(S.position, {0, 0, 0}, syy, -a * M[1], s, stress_inj);
      spread(S.position, {0, 0, 0}, szz, -a * M[2], s, stress_inj);
      spread(S.position, {0.5, 0.5, 0}, sxy, -a * M[3], s, stress_inj);
      spread(S.position, {0.5, 0, 0.5}, sxz, -a * M[4], s, stress_inj);
      spread(S.position, {0, 0.5, 0.5}, syz, -a * M[5], s, stress_inj);
    } else {
      // v += dt·F·S(t)/(ρ h³) = F·S(t)·b/h² with b = dt/(ρ h) the stored buoyancy.
      spread(S.position, {0.5, 0, 0}, vx, S.force[0] / (h * h), s, force_inj, BX);
      spread(S.position, {0, 0.5, 0}, vy, S.force[1] / (h * h), s, force_inj, BY);
      spread(S.position, {0, 0, 0.5}, vz, S.force[2] / (h * h), s, force_inj, BZ);
    }
  }
  std::erase_if(stress_inj, [](const Injection& q) { return q.weight == 0; });
  std::erase_if(force_inj, [](const Injection& q) { return q.weight == 0; });
  // σzz on the free-surface plane is set to 0 after each update: a moment there has no effect.
  if (free_surface && kb == 0)
    std::erase_if(stress_inj, [&](const Injection& q) { return q.field == szz.data() && q.k == 0; });
  // Per row, in the original order (several entries may hit the same cell).
  auto by_row = [&](const std::vector<Injection>& in, std::vector<Injection>& out, std::vector<int>& first) {
    auto row = [&](const Injection& q) { return long(q.n / std::size_t(sy)) - long(G) - long(sz / sy) * (q.k + G) + long(q.k) * ny; };
    out = in;
    std::stable_sort(out.begin(), out.end(), [&](const Injection& a, const Injection& b) { return row(a) < row(b); });
    first.assign(std::size_t(nzl) * ny + 1, 0);
    for (const auto& q : out) ++first[row(q) + 1];
    for (std::size_t r = 1; r < first.size(); ++r) first[r] += first[r - 1];
  };
  by_row(force_inj, force_rows, force_first);
  by_row(stress_inj, stress_rows, stress_first);
}

void Solver::Impl::setup_receivers() {
  recv.resize(cfg.receivers.size());
  rec.resize(cfg.receivers.size());
  const std::array<std::array<double, 3>, 3> st = {{{0.5, 0, 0}, {0, 0.5, 0}, {0, 0, 0.5}}};
  for (std::size_t r = 0; r < cfg.receivers.size(); ++r) {
    const auto& p = cfg.receivers[r].position;
    for (int c = 0; c < 3; ++c) {
      double g[3];
      int lo[3];
      const int dims[3] = {nx, ny, nz};
      for (int a = 0; a < 3; ++a) {
        g[a] = p[a] / h - st[c][a];
        lo[a] = int(std::floor(g[a]));
        // Below the first node of a staggered grid (at a free surface): take the first node.
        if (lo[a] < 0) {
          lo[a] = 0;
          g[a] = 0;
        }
        if (lo[a] > dims[a] - 2) {
          lo[a] = dims[a] - 2;
          g[a] = lo[a] + 1;
        }
      }
      ReceiverComp& rc = recv[r][c];
      rc.owned = lo[2] >= kb && lo[2] < ke;
      if (!rc.owned) continue;
      for (int q = 0; q < 8; ++q) {
        const int i = lo[0] + (q & 1), j = lo[1] + ((q >> 1) & 1), k = lo[2] + ((q >> 2) & 1);
        const double fx = g[0] - lo[0], fy = g[1] - lo[1], fz = g[2] - lo[2];
        rc.w[q] = ((q & 1) ? fx : 1 - fx) * (((q >> 1) & 1) ? fy : 1 - fy) * (((q >> 2) & 1) ? fz : 1 - fz);
        rc.n[q] = idx(i, j, k - kb);  // k − kb may be nzl (halo plane)
      }
    }
  }
}

}  // namespace panoptes::seismic
