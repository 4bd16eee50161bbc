#pragma once
// The solver's private state, shared by its rooms (not installed, included only by solver*.cpp):
// solver.cpp the public API, solver_setup.cpp the model set up (materials, CPML, sources,
// receivers), solver_kernels.cpp the time step (velocity and stress kernels, halo exchange),
// solver_outputs.cpp what leaves the solver (receivers' traces, seismograms, snapshots of fields,
// the derived fields, energy).
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "seismic/medium.hpp"
#include "seismic/solver.hpp"

namespace panoptes::seismic {

namespace solver_detail {

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


}  // namespace solver_detail
using namespace solver_detail;

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

}  // namespace panoptes::seismic
