#include "seismic/solver.hpp"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <cstdlib>
#include <cstring>
#include <map>
#include <unordered_map>
#include <numbers>
#include <sstream>

#include "core/error.hpp"
#include "core/log.hpp"
#include "seismic/attenuation.hpp"
#include "seismic/medium.hpp"

namespace panoptes::seismic {

namespace {

// 4th-order staggered first-derivative coefficients (times h).
constexpr float C1 = 9.0f / 8.0f;
constexpr float C2 = -1.0f / 24.0f;
constexpr int G = 2;  // ghost layers on every side

// Large arrays are each shifted by a different multiple of 4160 bytes from a page boundary, so that
// the same cell of different arrays does not fall into the same L1/L2 cache set: the blocked sweep
// touches ~30 arrays × 5 planes at once, and arrays that all start at the same page offset (as
// malloc returns them) thrash the sets. (Transparent huge pages were tried: no measurable gain.)
template <class T>
struct ShiftedAllocator {
  using value_type = T;
  static constexpr std::size_t page = 4096, small_limit = std::size_t(1) << 20;
  ShiftedAllocator() = default;
  template <class U>
  ShiftedAllocator(const ShiftedAllocator<U>&) {}
  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < small_limit) return std::allocator<T>().allocate(n);
    static std::atomic<unsigned> counter{0};
    const std::size_t shift = 64 + std::size_t(counter++ % 31) * 4160;  // < 128 KiB, the L2 set period
    const std::size_t rounded = (bytes + shift + page - 1) / page * page;
    auto* p = static_cast<char*>(std::aligned_alloc(page, rounded));
    if (!p) throw std::bad_alloc();
    std::memcpy(p + shift - sizeof(std::size_t), &shift, sizeof(std::size_t));
    return reinterpret_cast<T*>(p + shift);
  }
  void deallocate(T* q, std::size_t n) {
    if (n * sizeof(T) < small_limit) return std::allocator<T>().deallocate(q, n);
    std::size_t shift = 0;
    std::memcpy(&shift, reinterpret_cast<char*>(q) - sizeof(std::size_t), sizeof(std::size_t));
    std::free(reinterpret_cast<char*>(q) - shift);
  }
  template <class U>
  bool operator==(const ShiftedAllocator<U>&) const { return true; }
};
using Vec = std::vector<float, ShiftedAllocator<float>>;

/// CPML coefficients and slots along one axis (local indices).
struct PmlAxis {
  std::vector<int> slot;            // per local index: slot in ψ arrays, −1 outside the layers
  std::vector<int> indices;         // local indices with a slot, ascending
  std::vector<float> a_full, b_full, a_half, b_half;
  std::vector<std::array<int, 3>> runs;  // contiguous runs of indices: {first, end, first slot}
  int count() const { return int(indices.size()); }
};

struct Injection {
  float* field;      // base of the target array
  std::size_t n;     // linear index
  int k;             // local plane
  double weight;     // kernel weight × amplitude (see Impl::inject_*)
  int source;        // source index
  int mat;           // buoyancy coefficient of a force's velocity component (BX, BY, BZ)
};

// Material coefficients per cell, all premultiplied by dt/h: buoyancy at the three velocity
// points, λ and 2μ at the node, μ at the three shear-stress edges, and per relaxation mechanism l
// the memory-variable coefficients at index MECH + 5l + {0: λY^λ, 1: 2μY^μ, 2..4: μY^μ at xy, xz, yz}.
enum : int { BX, BY, BZ, LAM, TWOMU, MUXY, MUXZ, MUYZ, MECH };
constexpr int CL(int l) { return MECH + 5 * l; }
constexpr int CM(int l) { return MECH + 5 * l + 1; }
constexpr int CMXY(int l) { return MECH + 5 * l + 2; }
constexpr int CMXZ(int l) { return MECH + 5 * l + 3; }
constexpr int CMYZ(int l) { return MECH + 5 * l + 4; }

// The kernels read the material through one of two row accessors, chosen once per run: a table of
// the distinct coefficient tuples indexed by a 16-bit id per cell (piecewise-constant media: 2 bytes
// per cell instead of 32 elastic / 92 viscoelastic, which is most of the memory traffic saved), or
// one array per coefficient (media with more than 65,536 distinct cells, e.g. from files).
struct TableMat {
  const std::uint16_t* id;
  const float* tab;  // coefficient-major: tab[f·nt + id]
  std::size_t nt;
  TableMat row(std::size_t b) const { return {id + b, tab, nt}; }
  float operator()(int f, long i) const { return tab[std::size_t(f) * nt + id[i]]; }
};
// A row of one material (every row of a layered medium): the coefficients are loop constants, so
// the row streams no material data at all.
struct UniformMat {
  const float* c;  // K coefficients
  UniformMat row(std::size_t) const { return *this; }
  float operator()(int f, long) const { return c[f]; }
};
struct DenseMat {
  const float* const* base;  // one array per coefficient
  std::size_t b;
  DenseMat row(std::size_t r) const { return {base, b + r}; }
  float operator()(int f, long i) const { return base[f][b + i]; }
};

struct ReceiverComp {
  bool owned = false;
  std::array<std::size_t, 8> n{};
  std::array<double, 8> w{};
};

}  // namespace

double stable_time_step(double h, double vp_max) {
  return h / (std::sqrt(3.0) * (9.0 / 8.0 + 1.0 / 24.0) * vp_max);
}

struct Solver::Impl {
  SolverConfig cfg;
#ifdef PANOPTES_HAVE_MPI
  MPI_Comm comm = MPI_COMM_NULL;
#endif
  int rank = 0, size = 1;
  int nx = 0, ny = 0, nz = 0, kb = 0, ke = 0, nzl = 0;
  long sy = 0, sz = 0;
  std::size_t N = 0;
  double h = 0, dt = 0, vpmax = 0;
  int nsteps = 0;
  bool free_surface = true;
  int npml = 0;

  Vec vx, vy, vz, sxx, syy, szz, sxy, sxz, syz;
  // Material coefficients (see the enum above): K = MECH + 5L per cell.
  int K = MECH;
  bool mat_table = true;
  std::size_t ntypes = 0;
  std::vector<std::uint16_t> mat_id;  // per cell (table mode); ghost cells have id 0 (all zero)
  std::vector<float> mat_tab;         // K × ntypes
  std::vector<float> mat_tuples;      // ntypes × K (tuple-major)
  std::vector<int> row_mat;           // per row (k·ny + j): its id when all its cells share it, else −1
  std::vector<Vec> mat_dense;         // K arrays of N (dense mode)
  std::vector<const float*> mat_ptr;  // mat_dense[f].data()
  float mat(int f, std::size_t n) const { return mat_table ? mat_tab[std::size_t(f) * ntypes + mat_id[n]] : mat_dense[f][n]; }
  TableMat table_mat() const { return {mat_id.data(), mat_tab.data(), ntypes}; }
  DenseMat dense_mat() const { return {mat_ptr.data(), 0}; }
  // Attenuation (empty when elastic).
  int L = 0;
  std::vector<float> relax_a, relax_b;
  std::vector<Vec> rxx, ryy, rzz, rxy, rxz, ryz;
  std::vector<Vec> rowbuf;  // per thread: 6 rows of nx strain rates
  // CPML.
  PmlAxis pmlx, pmly, pmlz;
  std::array<Vec, 6> psix, psiy, psiz;
  // Sources and receivers.
  std::vector<SourceSpec> sources;
  std::vector<Injection> stress_inj, force_inj;
  std::vector<std::array<ReceiverComp, 3>> recv;
  std::vector<double> rec_time;
  std::vector<std::array<std::vector<double>, 3>> rec;
  // Derived fields.
  Vec phip, phis;

  FieldView view(const Vec& v, std::array<double, 3> stagger) const {
    FieldView f;
    f.data = v.data() + idx(0, 0, 0);
    f.nx = nx;
    f.ny = ny;
    f.nz = nzl;
    f.stride_y = sy;
    f.stride_z = sz;
    f.k_offset = kb;
    f.global_dims = {nx, ny, nz};
    f.stagger = stagger;
    f.h = h;
    return f;
  }

  std::size_t idx(int i, int j, int k) const {
    return std::size_t(i + G) + std::size_t(sy) * std::size_t(j + G) + std::size_t(sz) * std::size_t(k + G);
  }

  // ---------------------------------------------------------------- setup
  void init(const SolverConfig& c);
  void setup_materials(const MediumBlock& mb);
  void setup_pml();
  void setup_sources();
  void setup_receivers();

  // ---------------------------------------------------------------- stepping
  void step();
  // One z plane of the velocity (stress) update: plain update, CPML corrections, sources. Called
  // inside an OpenMP parallel region (worksharing over rows).
  void velocity_plane(int k, double t) { velocity_rows(k, 0, ny, t); }
  void stress_plane(int k, double t) { stress_rows_(k, 0, ny, t); }
  template <class M>
  void velocity_row(int k, int j, const M& mat0);
  template <int Z, class M>
  void stress_row(int k, int j, const M& mat0);
  // Sources per row (k, j): entries [first[k·ny + j], first[k·ny + j + 1]) in their original order.
  std::vector<Injection> force_rows, stress_rows;
  std::vector<int> force_first, stress_first;
  // Rows per cache block of the fused sweep (see step()).
  int yblock = 32;
  void sweep(int kv0, int kv1, int ks0, int ks1, double tv, double ts);
  void velocity_rows(int k, int j0, int j1, double t);
  void stress_rows_(int k, int j0, int j1, double t);
  void velocity_row_at(int k, int j, double t);
  void stress_row_at(int k, int j, double t);
  // Memory variables see the stretched derivative inside the CPML too: when ψ is added to a strain
  // rate, their update (linear in the rate) and the stress they relax get the matching increments.
  // For cells [i0, i1) of the row at base b: psi_n is the normal-strain correction along `axis`,
  // psi1 / psi2 those of the shear stresses s1 / s2 (memory variables r1 / r2, coefficients c1 / c2
  // of mechanism 0), all indexed from i0.
  template <class M>
  void visco_pml(const M& m, std::size_t b, int i0, int i1, const float* psi_n, int axis, const float* psi1, Vec& s1,
                 std::vector<Vec>& r1, int c1, const float* psi2, Vec& s2, std::vector<Vec>& r2, int c2) {
    for (int l = 0; l < L; ++l) {
      const float B = relax_b[l];
      float* __restrict n0 = sxx.data() + b;
      float* __restrict n1 = syy.data() + b;
      float* __restrict n2 = szz.data() + b;
      float* __restrict q0 = rxx[l].data() + b;
      float* __restrict q1 = ryy[l].data() + b;
      float* __restrict q2 = rzz[l].data() + b;
      float* __restrict S1 = s1.data() + b;
      float* __restrict R1 = r1[l].data() + b;
      float* __restrict S2 = s2.data() + b;
      float* __restrict R2 = r2[l].data() + b;
      const int fl = CL(l), fm = CM(l), f1 = c1 + 5 * l, f2 = c2 + 5 * l;
#pragma omp simd
      for (int i = i0; i < i1; ++i) {
        const float a = psi_n[i - i0];
        const float base = B * m(fl, i) * a;
        const float da = B * m(fm, i) * a;
        const float d0 = base + (axis == 0 ? da : 0.0f);
        const float d1 = base + (axis == 1 ? da : 0.0f);
        const float d2 = base + (axis == 2 ? da : 0.0f);
        q0[i] += d0;
        n0[i] -= 0.5f * d0;
        q1[i] += d1;
        n1[i] -= 0.5f * d1;
        q2[i] += d2;
        n2[i] -= 0.5f * d2;
        const float e1 = B * m(f1, i) * psi1[i - i0];
        R1[i] += e1;
        S1[i] -= 0.5f * e1;
        const float e2 = B * m(f2, i) * psi2[i - i0];
        R2[i] += e2;
        S2[i] -= 0.5f * e2;
      }
    }
  }

  void free_surface_images();
  void record();

#ifdef PANOPTES_HAVE_MPI
  std::vector<MPI_Request> reqs;
#endif
  void start_exchange(std::initializer_list<Vec*> fields);
  void finish_exchange();

  double allreduce_max(double v) const {
#ifdef PANOPTES_HAVE_MPI
    if (comm != MPI_COMM_NULL) MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_MAX, comm);
#endif
    return v;
  }
  double allreduce_sum(double v) const {
#ifdef PANOPTES_HAVE_MPI
    if (comm != MPI_COMM_NULL) MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_SUM, comm);
#endif
    return v;
  }
  /// Throws the same error on every rank when any rank failed (so no rank is left in a collective).
  void agree(const std::string& local_error) const {
    int bad = local_error.empty() ? 0 : 1;
#ifdef PANOPTES_HAVE_MPI
    if (comm != MPI_COMM_NULL) {
      int first = bad ? rank : size;
      MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, comm);
      if (first == size) return;
      int len = int(local_error.size());
      MPI_Bcast(&len, 1, MPI_INT, first, comm);
      std::string msg = local_error;
      msg.resize(len);
      MPI_Bcast(msg.data(), len, MPI_CHAR, first, comm);
      throw Error(msg);
    }
#endif
    if (bad) throw Error(local_error);
  }
};

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

// ==================================================================== kernels

// One row (k, j) of the velocity update, followed by its CPML corrections (x, then y, then z: the
// same order per cell as separate passes) while the row is in cache. The corrections of v read
// only σ, so doing them row by row is exact.
template <class M>
void Solver::Impl::velocity_row(int k, int j, const M& mat0) {
  const std::size_t b = idx(0, j, k);
  const M m = mat0.row(b);
  const long Y = sy, Z = sz;
  float* __restrict ux = vx.data() + b;
  float* __restrict uy = vy.data() + b;
  float* __restrict uz = vz.data() + b;
  const float* __restrict xx = sxx.data() + b;
  const float* __restrict yy = syy.data() + b;
  const float* __restrict zz = szz.data() + b;
  const float* __restrict xy = sxy.data() + b;
  const float* __restrict xz = sxz.data() + b;
  const float* __restrict yz = syz.data() + b;
#pragma omp simd
  for (int i = 0; i < nx; ++i) {
    ux[i] += m(BX, i) * (C1 * (xx[i + 1] - xx[i]) + C2 * (xx[i + 2] - xx[i - 1]) + C1 * (xy[i] - xy[i - Y]) +
                         C2 * (xy[i + Y] - xy[i - 2 * Y]) + C1 * (xz[i] - xz[i - Z]) + C2 * (xz[i + Z] - xz[i - 2 * Z]));
    uy[i] += m(BY, i) * (C1 * (xy[i] - xy[i - 1]) + C2 * (xy[i + 1] - xy[i - 2]) + C1 * (yy[i + Y] - yy[i]) +
                         C2 * (yy[i + 2 * Y] - yy[i - Y]) + C1 * (yz[i] - yz[i - Z]) + C2 * (yz[i + Z] - yz[i - 2 * Z]));
    uz[i] += m(BZ, i) * (C1 * (xz[i] - xz[i - 1]) + C2 * (xz[i + 1] - xz[i - 2]) + C1 * (yz[i] - yz[i - Y]) +
                         C2 * (yz[i + Y] - yz[i - 2 * Y]) + C1 * (zz[i + Z] - zz[i]) + C2 * (zz[i + 2 * Z] - zz[i - Z]));
  }
  // CPML: ψ ← b·ψ + a·∂f and f += coefficient·ψ after the plain update (κ = 1), layers only.
  const int cx = pmlx.count();
  // Not a structured binding: clang 14 (the fuzz build) cannot capture those in "omp simd".
  for (const auto& run : pmlx.runs) {
    const int i0 = run[0], i1 = run[1], s0 = run[2];
    const std::size_t p = (std::size_t(k) * ny + j) * cx + s0;
    float* __restrict q0 = psix[0].data() + p;
    float* __restrict q1 = psix[1].data() + p;
    float* __restrict q2 = psix[2].data() + p;
    const float* __restrict bh = pmlx.b_half.data();
    const float* __restrict ah = pmlx.a_half.data();
    const float* __restrict bf = pmlx.b_full.data();
    const float* __restrict af = pmlx.a_full.data();
#pragma omp simd
    for (int i = i0; i < i1; ++i) {
      const int q = i - i0;
      q0[q] = bh[i] * q0[q] + ah[i] * (C1 * (xx[i + 1] - xx[i]) + C2 * (xx[i + 2] - xx[i - 1]));
      ux[i] += m(BX, i) * q0[q];
      q1[q] = bf[i] * q1[q] + af[i] * (C1 * (xy[i] - xy[i - 1]) + C2 * (xy[i + 1] - xy[i - 2]));
      uy[i] += m(BY, i) * q1[q];
      q2[q] = bf[i] * q2[q] + af[i] * (C1 * (xz[i] - xz[i - 1]) + C2 * (xz[i + 1] - xz[i - 2]));
      uz[i] += m(BZ, i) * q2[q];
    }
  }
  if (const int s = pmly.count() > 0 ? pmly.slot[j] : -1; s >= 0) {
    const float bf = pmly.b_full[j], af = pmly.a_full[j], bh = pmly.b_half[j], ah = pmly.a_half[j];
    float* __restrict p0 = psiy[0].data() + (std::size_t(k) * pmly.count() + s) * nx;
    float* __restrict p1 = psiy[1].data() + (std::size_t(k) * pmly.count() + s) * nx;
    float* __restrict p2 = psiy[2].data() + (std::size_t(k) * pmly.count() + s) * nx;
#pragma omp simd
    for (int i = 0; i < nx; ++i) {
      p0[i] = bf * p0[i] + af * (C1 * (xy[i] - xy[i - Y]) + C2 * (xy[i + Y] - xy[i - 2 * Y]));
      ux[i] += m(BX, i) * p0[i];
      p1[i] = bh * p1[i] + ah * (C1 * (yy[i + Y] - yy[i]) + C2 * (yy[i + 2 * Y] - yy[i - Y]));
      uy[i] += m(BY, i) * p1[i];
      p2[i] = bf * p2[i] + af * (C1 * (yz[i] - yz[i - Y]) + C2 * (yz[i + Y] - yz[i - 2 * Y]));
      uz[i] += m(BZ, i) * p2[i];
    }
  }
  if (const int s = pmlz.count() > 0 ? pmlz.slot[k] : -1; s >= 0) {
    const float bf = pmlz.b_full[k], af = pmlz.a_full[k], bh = pmlz.b_half[k], ah = pmlz.a_half[k];
    float* __restrict p0 = psiz[0].data() + (std::size_t(s) * ny + j) * nx;
    float* __restrict p1 = psiz[1].data() + (std::size_t(s) * ny + j) * nx;
    float* __restrict p2 = psiz[2].data() + (std::size_t(s) * ny + j) * nx;
#pragma omp simd
    for (int i = 0; i < nx; ++i) {
      p0[i] = bf * p0[i] + af * (C1 * (xz[i] - xz[i - Z]) + C2 * (xz[i + Z] - xz[i - 2 * Z]));
      ux[i] += m(BX, i) * p0[i];
      p1[i] = bf * p1[i] + af * (C1 * (yz[i] - yz[i - Z]) + C2 * (yz[i + Z] - yz[i - 2 * Z]));
      uy[i] += m(BY, i) * p1[i];
      p2[i] = bh * p2[i] + ah * (C1 * (zz[i + Z] - zz[i]) + C2 * (zz[i + 2 * Z] - zz[i - Z]));
      uz[i] += m(BZ, i) * p2[i];
    }
  }
}

// Velocity row (k, j) with its CPML corrections and body forces.
void Solver::Impl::velocity_row_at(int k, int j, double t) {
  const std::size_t r = std::size_t(k) * ny + j;
  if (const int u = row_mat[r]; u >= 0) velocity_row(k, j, UniformMat{mat_tuples.data() + std::size_t(u) * K});
  else if (mat_table) velocity_row(k, j, table_mat());
  else velocity_row(k, j, dense_mat());
  for (int e = force_first[r]; e < force_first[r + 1]; ++e) {
    const Injection& q = force_rows[e];
    q.field[q.n] += float(q.weight * sources[q.source].stf.value(t) * mat(q.mat, q.n));
  }
}

// Rows [j0, j1) of velocity plane k (worksharing when called inside a parallel region).
void Solver::Impl::velocity_rows(int k, int j0, int j1, double t) {
#pragma omp for schedule(static)
  for (int j = j0; j < j1; ++j) velocity_row_at(k, j, t);
}

// Strain-rate differences (times h) at node / edge positions of plane k. Z selects the z stencil:
// 0 interior, 1 the free-surface plane (ezz from σzz = 0; 2nd-order ∂z for the edges at z = h/2),
// 2 the plane below it (2nd-order ∂z vz: vz above the surface is not a model value).
// Expects la = λ, tm = 2μ of the cell.
#define PANOPTES_STRAIN(Zm)                                                                                       \
  const float exx = C1 * (ux[i] - ux[i - 1]) + C2 * (ux[i + 1] - ux[i - 2]);                                       \
  const float eyy = C1 * (uy[i] - uy[i - Y]) + C2 * (uy[i + Y] - uy[i - 2 * Y]);                                   \
  float ezz;                                                                                                       \
  if constexpr (Zm == 0) ezz = C1 * (uz[i] - uz[i - Z]) + C2 * (uz[i + Z] - uz[i - 2 * Z]);                         \
  else if constexpr (Zm == 1) ezz = -la / (la + tm) * (exx + eyy);                                                 \
  else ezz = uz[i] - uz[i - Z];                                                                                    \
  const float exy = C1 * (ux[i + Y] - ux[i]) + C2 * (ux[i + 2 * Y] - ux[i - Y]) + C1 * (uy[i + 1] - uy[i]) +        \
                    C2 * (uy[i + 2] - uy[i - 1]);                                                                  \
  float exz, eyz;                                                                                                  \
  if constexpr (Zm == 1) {                                                                                         \
    exz = (ux[i + Z] - ux[i]) + C1 * (uz[i + 1] - uz[i]) + C2 * (uz[i + 2] - uz[i - 1]);                           \
    eyz = (uy[i + Z] - uy[i]) + C1 * (uz[i + Y] - uz[i]) + C2 * (uz[i + 2 * Y] - uz[i - Y]);                       \
  } else {                                                                                                         \
    exz = C1 * (ux[i + Z] - ux[i]) + C2 * (ux[i + 2 * Z] - ux[i - Z]) + C1 * (uz[i + 1] - uz[i]) +                  \
          C2 * (uz[i + 2] - uz[i - 1]);                                                                            \
    eyz = C1 * (uy[i + Z] - uy[i]) + C2 * (uy[i + 2 * Z] - uy[i - Z]) + C1 * (uz[i + Y] - uz[i]) +                  \
          C2 * (uz[i + 2 * Y] - uz[i - Y]);                                                                        \
  }                                                                                                                \
  const float th = exx + eyy + ezz;

// One row of the stress update (plus memory variables when attenuating), then its CPML
// corrections x, y, z; on the free-surface plane σzz is set to 0 last. Corrections of σ read only v.
// CPML correction of one stress row for the derivatives along y or z (stride S between rows of that
// axis): ψ0 of the axis's own velocity component n feeds the normal stresses (λ + 2μ on the axis's
// own, λ on the two others); ψ1 and ψ2 of the other components a1, a2 feed the two shear stresses in
// the axis's plane. Restrict-qualified so the loop vectorizes; the same expressions as the interior
// update's, so results do not depend on which code path a row takes.
template <int Mu1, int Mu2, class M>
[[gnu::always_inline]] inline void pml_stress_row(const M& m, int nx, long S, float bf, float af, float bh, float ah, float* __restrict q0,
                           float* __restrict q1, float* __restrict q2, float* __restrict normal, float* __restrict other1,
                           float* __restrict other2, float* __restrict shear1, float* __restrict shear2,
                           const float* __restrict n, const float* __restrict a1, const float* __restrict a2) {
#pragma omp simd
  for (int i = 0; i < nx; ++i) {
    q0[i] = bf * q0[i] + af * (C1 * (n[i] - n[i - S]) + C2 * (n[i + S] - n[i - 2 * S]));
    normal[i] += (m(LAM, i) + m(TWOMU, i)) * q0[i];
    other1[i] += m(LAM, i) * q0[i];
    other2[i] += m(LAM, i) * q0[i];
    q1[i] = bh * q1[i] + ah * (C1 * (a1[i + S] - a1[i]) + C2 * (a1[i + 2 * S] - a1[i - S]));
    shear1[i] += m(Mu1, i) * q1[i];
    q2[i] = bh * q2[i] + ah * (C1 * (a2[i + S] - a2[i]) + C2 * (a2[i + 2 * S] - a2[i - S]));
    shear2[i] += m(Mu2, i) * q2[i];
  }
}

template <int Zm, class M>
void Solver::Impl::stress_row(int k, int j, const M& mat0) {
  const std::size_t b = idx(0, j, k);
  const M m = mat0.row(b);
  const long Y = sy, Z = sz;
  {
  // Restrict-qualified only here: the CPML part below also writes σ through visco_pml (own restrict scopes).
  const float* __restrict ux = vx.data() + b;
  const float* __restrict uy = vy.data() + b;
  const float* __restrict uz = vz.data() + b;
  float* __restrict xx = sxx.data() + b;
  float* __restrict yy = syy.data() + b;
  float* __restrict zz = szz.data() + b;
  float* __restrict xy = sxy.data() + b;
  float* __restrict xz = sxz.data() + b;
  float* __restrict yz = syz.data() + b;
  if (L == 0) {
#pragma omp simd
    for (int i = 0; i < nx; ++i) {
      const float la = m(LAM, i), tm = m(TWOMU, i);
      PANOPTES_STRAIN(Zm)
      xx[i] += la * th + tm * exx;
      yy[i] += la * th + tm * eyy;
      zz[i] += la * th + tm * ezz;
      xy[i] += m(MUXY, i) * exy;
      xz[i] += m(MUXZ, i) * exz;
      yz[i] += m(MUYZ, i) * eyz;
    }
  } else {
    float* rows = rowbuf[std::size_t(omp_get_thread_num())].data();
    float* __restrict rxx_ = rows;
    float* __restrict ryy_ = rows + nx;
    float* __restrict rzz_ = rows + 2 * nx;
    float* __restrict rxy_ = rows + 3 * nx;
    float* __restrict rxz_ = rows + 4 * nx;
    float* __restrict ryz_ = rows + 5 * nx;
#pragma omp simd
    for (int i = 0; i < nx; ++i) {
      const float la = m(LAM, i), tm = m(TWOMU, i);
      PANOPTES_STRAIN(Zm)
      xx[i] += la * th + tm * exx;
      yy[i] += la * th + tm * eyy;
      zz[i] += la * th + tm * ezz;
      xy[i] += m(MUXY, i) * exy;
      xz[i] += m(MUXZ, i) * exz;
      yz[i] += m(MUYZ, i) * eyz;
      rxx_[i] = exx;
      ryy_[i] = eyy;
      rzz_[i] = ezz;
      rxy_[i] = exy;
      rxz_[i] = exz;
      ryz_[i] = eyz;
    }
    for (int l = 0; l < L; ++l) {
      const float A = relax_a[l], B = relax_b[l];
      float* __restrict mx = rxx[l].data() + b;
      float* __restrict my = ryy[l].data() + b;
      float* __restrict mz = rzz[l].data() + b;
      float* __restrict mxy_ = rxy[l].data() + b;
      float* __restrict mxz_ = rxz[l].data() + b;
      float* __restrict myz_ = ryz[l].data() + b;
      const int fl = CL(l), fm = CM(l), fxy = CMXY(l), fxz = CMXZ(l), fyz = CMYZ(l);
#pragma omp simd
      for (int i = 0; i < nx; ++i) {
        const float th = rxx_[i] + ryy_[i] + rzz_[i];
        const float cl_ = m(fl, i), cm_ = m(fm, i);
        float o, n;
        o = mx[i]; n = A * o + B * (cl_ * th + cm_ * rxx_[i]); mx[i] = n; xx[i] -= 0.5f * (o + n);
        o = my[i]; n = A * o + B * (cl_ * th + cm_ * ryy_[i]); my[i] = n; yy[i] -= 0.5f * (o + n);
        o = mz[i]; n = A * o + B * (cl_ * th + cm_ * rzz_[i]); mz[i] = n; zz[i] -= 0.5f * (o + n);
        o = mxy_[i]; n = A * o + B * (m(fxy, i) * rxy_[i]); mxy_[i] = n; xy[i] -= 0.5f * (o + n);
        o = mxz_[i]; n = A * o + B * (m(fxz, i) * rxz_[i]); mxz_[i] = n; xz[i] -= 0.5f * (o + n);
        o = myz_[i]; n = A * o + B * (m(fyz, i) * ryz_[i]); myz_[i] = n; yz[i] -= 0.5f * (o + n);
      }
    }
  }
  }
  // CPML corrections.
  const float* ux = vx.data() + b;
  const float* uy = vy.data() + b;
  const float* uz = vz.data() + b;
  float* xx = sxx.data() + b;
  float* yy = syy.data() + b;
  float* zz = szz.data() + b;
  float* xy = sxy.data() + b;
  float* xz = sxz.data() + b;
  float* yz = syz.data() + b;
  const int cx = pmlx.count();
  {  // restrict-qualified so that it vectorizes; memory variables below
    float* __restrict X = xx;
    float* __restrict YY = yy;
    float* __restrict ZZ = zz;
    float* __restrict XY = xy;
    float* __restrict XZ = xz;
    const float* __restrict U = ux;
    const float* __restrict V = uy;
    const float* __restrict W = uz;
    const float* __restrict bh = pmlx.b_half.data();
    const float* __restrict ah = pmlx.a_half.data();
    const float* __restrict bf = pmlx.b_full.data();
    const float* __restrict af = pmlx.a_full.data();
    // Not a structured binding: clang 14 (the fuzz build) cannot capture those in "omp simd".
    for (const auto& run : pmlx.runs) {
      const int i0 = run[0], i1 = run[1], s0 = run[2];
      const std::size_t p = (std::size_t(k) * ny + j) * cx + s0;
      float* __restrict q0 = psix[3].data() + p;
      float* __restrict q1 = psix[4].data() + p;
      float* __restrict q2 = psix[5].data() + p;
#pragma omp simd
      for (int i = i0; i < i1; ++i) {
        const int q = i - i0;
        q0[q] = bf[i] * q0[q] + af[i] * (C1 * (U[i] - U[i - 1]) + C2 * (U[i + 1] - U[i - 2]));
        X[i] += (m(LAM, i) + m(TWOMU, i)) * q0[q];
        YY[i] += m(LAM, i) * q0[q];
        ZZ[i] += m(LAM, i) * q0[q];
        q1[q] = bh[i] * q1[q] + ah[i] * (C1 * (V[i + 1] - V[i]) + C2 * (V[i + 2] - V[i - 1]));
        XY[i] += m(MUXY, i) * q1[q];
        q2[q] = bh[i] * q2[q] + ah[i] * (C1 * (W[i + 1] - W[i]) + C2 * (W[i + 2] - W[i - 1]));
        XZ[i] += m(MUXZ, i) * q2[q];
      }
    }
  }
  if (L > 0)
    // Not a structured binding: clang 14 (the fuzz build) cannot capture those in "omp simd".
    for (const auto& run : pmlx.runs) {
      const int i0 = run[0], i1 = run[1], s0 = run[2];
      const std::size_t p = (std::size_t(k) * ny + j) * cx + s0;
      visco_pml(m, b, i0, i1, psix[3].data() + p, 0, psix[4].data() + p, sxy, rxy, CMXY(0), psix[5].data() + p, sxz, rxz,
                CMXZ(0));
    }
  if (const int s = pmly.count() > 0 ? pmly.slot[j] : -1; s >= 0) {
    const float bf = pmly.b_full[j], af = pmly.a_full[j], bh = pmly.b_half[j], ah = pmly.a_half[j];
    const std::size_t p = (std::size_t(k) * pmly.count() + s) * nx;
    float* p0 = psiy[3].data() + p;
    float* p1 = psiy[4].data() + p;
    float* p2 = psiy[5].data() + p;
    pml_stress_row<MUXY, MUYZ>(m, nx, Y, bf, af, bh, ah, p0, p1, p2, yy, xx, zz, xy, yz, uy, ux, uz);
    if (L > 0) visco_pml(m, b, 0, nx, p0, 1, p1, sxy, rxy, CMXY(0), p2, syz, ryz, CMYZ(0));
  }
  if (const int s = pmlz.count() > 0 ? pmlz.slot[k] : -1; s >= 0) {
    const float bf = pmlz.b_full[k], af = pmlz.a_full[k], bh = pmlz.b_half[k], ah = pmlz.a_half[k];
    const std::size_t p = (std::size_t(s) * ny + j) * nx;
    float* p0 = psiz[3].data() + p;
    float* p1 = psiz[4].data() + p;
    float* p2 = psiz[5].data() + p;
    pml_stress_row<MUXZ, MUYZ>(m, nx, Z, bf, af, bh, ah, p0, p1, p2, zz, xx, yy, xz, yz, uz, ux, uy);
    if (L > 0) visco_pml(m, b, 0, nx, p0, 2, p1, sxz, rxz, CMXZ(0), p2, syz, ryz, CMYZ(0));
  }
  if constexpr (Zm == 1)
    for (int i = 0; i < nx; ++i) zz[i] = 0.0f;
}

// Stress row (k, j) with its memory variables, CPML corrections and moment sources.
void Solver::Impl::stress_row_at(int k, int j, double t) {
  const int g = k + kb;
  const int zm = !free_surface ? 0 : g == 0 ? 1 : g == 1 ? 2 : 0;
  const std::size_t r = std::size_t(k) * ny + j;
  if (const int u = row_mat[r]; u >= 0) {
    const UniformMat um{mat_tuples.data() + std::size_t(u) * K};
    if (zm == 0) stress_row<0>(k, j, um);
    else if (zm == 1) stress_row<1>(k, j, um);
    else stress_row<2>(k, j, um);
  } else if (mat_table) {
    if (zm == 0) stress_row<0>(k, j, table_mat());
    else if (zm == 1) stress_row<1>(k, j, table_mat());
    else stress_row<2>(k, j, table_mat());
  } else {
    if (zm == 0) stress_row<0>(k, j, dense_mat());
    else if (zm == 1) stress_row<1>(k, j, dense_mat());
    else stress_row<2>(k, j, dense_mat());
  }
  for (int e = stress_first[r]; e < stress_first[r + 1]; ++e) {
    const Injection& q = stress_rows[e];
    q.field[q.n] += float(q.weight * sources[q.source].stf.rate(t));
  }
}

// Rows [j0, j1) of stress plane k (worksharing when called inside a parallel region).
void Solver::Impl::stress_rows_(int k, int j0, int j1, double t) {
#pragma omp for schedule(static)
  for (int j = j0; j < j1; ++j) stress_row_at(k, j, t);
}

// The fused, cache-blocked sweep over velocity planes [kv0, kv1) and stress planes [ks0, ks1)
// (every velocity plane a stress plane needs must be new, either in the range or already done).
// Along z, stress plane m follows velocity plane m+2. Along y the rows are cut into blocks of
// `yblock` rows, swept one after the other through all planes so that the z neighbourhood of a
// block (≈ 5 planes of each field) stays in L2; the stress rows of a block lag its velocity rows
// by 2 (stress row j needs velocity rows j−2 … j+2 and is read, old, by the same ones). Each
// OpenMP thread sweeps its own contiguous range of rows; the 4 stress rows around the seams
// between threads follow after a barrier.
void Solver::Impl::sweep(int kv0, int kv1, int ks0, int ks1, double tv, double ts) {
  const int nth = std::max(1, std::min(omp_get_num_threads(), ny / 16));
  const int t = omp_get_thread_num();
  if (t < nth) {
    const int J0 = int(long(ny) * t / nth), J1 = int(long(ny) * (t + 1) / nth);
    const int S0 = J0 == 0 ? 0 : J0 + 2, S1 = J1 == ny ? ny : J1 - 2;
    for (int jb = J0; jb < J1; jb += yblock) {
      const int v0 = jb, v1 = std::min(jb + yblock, J1);
      const int s0 = jb == J0 ? S0 : jb - 2, s1 = v1 == J1 ? S1 : v1 - 2;
      for (int k = kv0; k < kv1; ++k) {
        for (int j = v0; j < v1; ++j) velocity_row_at(k, j, tv);
        if (k - 2 >= ks0 && k - 2 < ks1)
          for (int j = s0; j < s1; ++j) stress_row_at(k - 2, j, ts);
      }
      for (int m = std::max(ks0, kv1 - 2); m < ks1; ++m)
        for (int j = s0; j < s1; ++j) stress_row_at(m, j, ts);
    }
  }
#pragma omp barrier
  if (t + 1 < nth) {
    const int J1 = int(long(ny) * (t + 1) / nth);
    for (int m = ks0; m < ks1; ++m)
      for (int j = J1 - 2; j < J1 + 2; ++j) stress_row_at(m, j, ts);
  }
#pragma omp barrier
}

// Stress imaging (Levander 1988): σzz is antisymmetric about the surface plane z = 0, as are σxz
// and σyz about it (their planes sit at z = ±h/2, ±3h/2).
void Solver::Impl::free_surface_images() {
  if (!free_surface || kb != 0) return;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      szz[idx(i, j, -1)] = -szz[idx(i, j, 1)];
      szz[idx(i, j, -2)] = -szz[idx(i, j, 2)];
      sxz[idx(i, j, -1)] = -sxz[idx(i, j, 0)];
      sxz[idx(i, j, -2)] = -sxz[idx(i, j, 1)];
      syz[idx(i, j, -1)] = -syz[idx(i, j, 0)];
      syz[idx(i, j, -2)] = -syz[idx(i, j, 1)];
    }
}

// ==================================================================== communication

void Solver::Impl::start_exchange(std::initializer_list<Vec*> fields) {
#ifdef PANOPTES_HAVE_MPI
  if (comm == MPI_COMM_NULL || size == 1) return;
  reqs.clear();
  const int up = rank - 1, down = rank + 1 < size ? rank + 1 : -1;
  const int count = int(2 * sz);
  int f = 0;
  for (Vec* v : fields) {
    float* d = v->data();
    if (up >= 0) {
      reqs.emplace_back();
      MPI_Irecv(d + idx(-G, -G, -2), count, MPI_FLOAT, up, 2 * f + 1, comm, &reqs.back());
      reqs.emplace_back();
      MPI_Isend(d + idx(-G, -G, 0), count, MPI_FLOAT, up, 2 * f, comm, &reqs.back());
    }
    if (down >= 0) {
      reqs.emplace_back();
      MPI_Irecv(d + idx(-G, -G, nzl), count, MPI_FLOAT, down, 2 * f, comm, &reqs.back());
      reqs.emplace_back();
      MPI_Isend(d + idx(-G, -G, nzl - 2), count, MPI_FLOAT, down, 2 * f + 1, comm, &reqs.back());
    }
    ++f;
  }
#else
  (void)fields;
#endif
}

void Solver::Impl::finish_exchange() {
#ifdef PANOPTES_HAVE_MPI
  if (!reqs.empty()) MPI_Waitall(int(reqs.size()), reqs.data(), MPI_STATUSES_IGNORE);
  reqs.clear();
#endif
}

// ==================================================================== stepping

// Fused sweep: stress plane m needs the new velocities of planes m−2 … m+2 and is needed (old)
// by the velocity planes m−2 … m+2, so it is updated right after velocity plane m+2. Each field
// plane is then read from memory about once per step instead of twice (velocity and stress
// passes), and the CPML corrections are applied while their row is in cache. Per cell the
// arithmetic (and its order) is that of separate passes, so results do not depend on the order
// of planes or on the decomposition.
void Solver::Impl::step() {
  const double tv = nsteps * dt;          // σ^n: body forces act at t_n
  const double ts = (nsteps + 0.5) * dt;  // v^{n+½}: moment rates act at t_{n+½}
  if (size == 1) {
#pragma omp parallel
    sweep(0, nzl, 0, nzl, tv, ts);
  } else {
    // Rank-boundary velocity planes first; their halos travel while the interior is swept (the
    // interior stress planes 2 … nzl−3 need no velocity halo). The stress halos (6 fields × 2 planes)
    // are exchanged after the boundary stress planes: the next step's boundary velocity planes need
    // them at once.
    std::vector<int> edge;
    for (int k : {0, 1, nzl - 2, nzl - 1})
      if (k >= 0 && k < nzl && std::find(edge.begin(), edge.end(), k) == edge.end()) edge.push_back(k);
#pragma omp parallel
    for (int k : edge) velocity_plane(k, tv);
    start_exchange({&vx, &vy, &vz});
    if (nzl > 4) {
#pragma omp parallel
      sweep(2, nzl - 2, 2, nzl - 2, tv, ts);
    }
    finish_exchange();
#pragma omp parallel
    for (int k : edge) stress_plane(k, ts);
    start_exchange({&sxx, &syy, &szz, &sxy, &sxz, &syz});
    finish_exchange();
  }
  free_surface_images();
  if (nsteps % cfg.record_every == 0) record();
  ++nsteps;
}

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

// ==================================================================== public API

Solver::Solver(const SolverConfig& config) : impl_(std::make_unique<Impl>()) {
#ifdef PANOPTES_HAVE_MPI
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (initialized) {
    impl_->comm = MPI_COMM_WORLD;
    MPI_Comm_rank(MPI_COMM_WORLD, &impl_->rank);
    MPI_Comm_size(MPI_COMM_WORLD, &impl_->size);
  }
#endif
  impl_->init(config);
}

#ifdef PANOPTES_HAVE_MPI
Solver::Solver(const SolverConfig& config, MPI_Comm comm) : impl_(std::make_unique<Impl>()) {
  impl_->comm = comm;
  MPI_Comm_rank(comm, &impl_->rank);
  MPI_Comm_size(comm, &impl_->size);
  impl_->init(config);
}
#endif

Solver::~Solver() = default;

void Solver::step() { impl_->step(); }
void Solver::run(int n) {
  for (int i = 0; i < n; ++i) impl_->step();
}
int Solver::steps_done() const { return impl_->nsteps; }
double Solver::dt() const { return impl_->dt; }
double Solver::velocity_time() const { return (impl_->nsteps - 0.5) * impl_->dt; }
const SolverConfig& Solver::config() const { return impl_->cfg; }
int Solver::rank() const { return impl_->rank; }
int Solver::ranks() const { return impl_->size; }
int Solver::k_begin() const { return impl_->kb; }
int Solver::k_end() const { return impl_->ke; }
bool Solver::viscoelastic() const { return impl_->L > 0; }
double Solver::vp_max() const { return impl_->vpmax; }


FieldView Solver::vx() const { return impl_->view(impl_->vx, {0.5, 0, 0}); }
FieldView Solver::vy() const { return impl_->view(impl_->vy, {0, 0.5, 0}); }
FieldView Solver::vz() const { return impl_->view(impl_->vz, {0, 0, 0.5}); }
FieldView Solver::phi_p() const { return impl_->view(impl_->phip, {0, 0, 0}); }
FieldView Solver::phi_s() const { return impl_->view(impl_->phis, {0, 0, 0}); }

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
#pragma omp parallel for collapse(2) schedule(static)
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

std::size_t Solver::memory_bytes() const {
  const Impl& s = *impl_;
  std::size_t b = 9 * s.N * sizeof(float);                              // fields
  b += std::size_t(s.L) * 6 * s.N * sizeof(float);                      // memory variables
  b += s.mat_id.size() * sizeof(std::uint16_t) + s.mat_tab.size() * sizeof(float);
  for (const auto& v : s.mat_dense) b += v.size() * sizeof(float);
  for (const auto* p : {&s.psix, &s.psiy, &s.psiz})
    for (const auto& v : *p) b += v.size() * sizeof(float);
  b += s.phip.size() * 2 * sizeof(float);
  return b;
}

}  // namespace panoptes::seismic
