// The C API over insitu::Session: errors become return codes + a thread-local message.
// Sections: the handle | errors: codes, messages, remembered failures | the session, built at the first
// collective call | grids | field bindings: layouts, strides, counts | the C functions (create, grid,
// patch, resample, block, halo, fields, process/due/snapshot/finalize, destroy, errors).
#include "panoptes.h"

#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/strided.hpp"
#include "core/version.hpp"
#include "grid/grid_description.hpp"
#include "insitu/grid_adapter.hpp"
#include "insitu/rank_agreement.hpp"
#include "insitu/session.hpp"

using namespace panoptes;

// --- the handle ---
struct panoptes_session {
  insitu::SessionConfig config;
  int fortran_comm = PANOPTES_COMM_WORLD;
  int rank = 0, ranks = 1;  // of the communicator, known from panoptes_create on (error messages)
  std::optional<render::GridGeometry> grid;
  std::optional<insitu::LocalBlock> block;
  std::map<std::string, insitu::FieldInput> fields;
  std::unique_ptr<insitu::Session> session;
  // Agreements before the session exists (panoptes_create, the first snapshot's start), and a call of
  // this rank's that failed since the last collective call: the next one is refused on every rank
  // (issue 42: a field one rank could not bind left the others waiting, or kept its stale binding).
  // Keyed by what the call sets ("grid", "block", "field T", ...): a later call that sets it right
  // clears the failure.
  insitu::RankAgreement agreement;
  std::map<std::string, std::string> failed_calls;
  std::string failures() const {
    std::string all;
    for (const auto& [what, message] : failed_calls)
      all += (all.empty() ? "" : "; ") + ("field \"" + what.substr(6) + "\" is not bound: its binding failed (" + message + ")");
    return all;
  }
  // A non-uniform grid (panoptes_set_grid_rectilinear / _spherical / _yinyang): the blocks and fields
  // of the patch not selected by panoptes_set_patch wait in `other_patches`; the adapter resamples
  // them onto the uniform grid the session renders.
  std::optional<grid::GridDescription> source;
  insitu::ResampleOptions resample;
  int patch = 0;
  struct PatchState {
    std::optional<insitu::LocalBlock> block;
    std::map<std::string, insitu::FieldInput> fields;
  };
  std::map<int, PatchState> other_patches;
  bool finalized = false;  // the overhead report is printed by the first panoptes_finalize only
  // Counts every call on this handle as Panoptes' CPU time, not only the session's own: binding fields,
  // the grid adapter's resampling and the schedule check of panoptes_process run outside the session's
  // calls, and codes make them every step. Shared with the session (nested calls count once).
  std::shared_ptr<insitu::OverheadMeter> meter = std::make_shared<insitu::OverheadMeter>();
};

namespace {

// --- errors: codes, messages, remembered failures ---
thread_local std::string g_error;

struct UsageError : Error {
  using Error::Error;
};
struct ConfigError : Error {
  using Error::Error;
};

int error_mode_from_env() {
  const char* v = std::getenv("PANOPTES_ERRORS");
  const std::string m = v ? v : "";
  if (m == "rank0") return PANOPTES_ERRORS_RANK0;
  if (m == "none") return PANOPTES_ERRORS_NONE;
  return PANOPTES_ERRORS_ALL;
}
std::atomic<int> g_error_mode{error_mode_from_env()};

// The rank that prints: the session's when there is one, else MPI_COMM_WORLD's (or 0 without MPI).
void rank_of(const panoptes_session* s, int& rank, int& ranks) {
  rank = 0;
  ranks = 1;
  if (s) {
    rank = s->rank;
    ranks = s->ranks;
    return;
  }
#ifdef PANOPTES_HAVE_MPI
  int init = 0, done = 0;
  MPI_Initialized(&init);
  MPI_Finalized(&done);
  if (init && !done) {
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  }
#endif
}

// One line on stderr (the simulation's own output stays on stdout), as the error mode says.
void report(const panoptes_session* s, const std::string& message) {
  const int mode = g_error_mode.load();
  if (mode == PANOPTES_ERRORS_NONE) return;
  int rank = 0, ranks = 1;
  rank_of(s, rank, ranks);
  if (mode == PANOPTES_ERRORS_RANK0 && rank != 0) return;
  const std::string who = mode == PANOPTES_ERRORS_ALL && ranks > 1 ? "rank " + std::to_string(rank) + ": " : "";
  const std::string line = "panoptes: " + who + "error: " + message + "\n";
  std::fputs(line.c_str(), stderr);
  std::fflush(stderr);
}

// A field binding's failure is remembered until the next collective call, which every rank then refuses
// (C and Fortran codes often ignore ierr; the binding is gone, not stale). The other setters leave their
// state as it was when they fail, and the session's start agrees on what is missing: their key is "".
std::string field_key(const char* name) { return std::string("field ") + (name ? name : ""); }

// Runs f, turning exceptions into a return code, the thread's last error and one printed line.
// A call that sets `key` on this rank only has its failure remembered (and a success forgets an
// earlier failure of the same key): the next collective call is refused on every rank.
template <class F>
int guarded(panoptes_session* s, F&& f, const std::string& key) {
  int code = PANOPTES_OK;
  std::optional<insitu::OverheadMeter::Scope> counted;
  if (s && s->meter) counted.emplace(*s->meter);
  try {
    f();
    g_error.clear();
    if (s && !key.empty()) s->failed_calls.erase(key);
    return PANOPTES_OK;
  } catch (const ConfigError& e) {
    g_error = e.what();
    code = PANOPTES_ERROR_CONFIG;
  } catch (const UsageError& e) {
    g_error = e.what();
    code = PANOPTES_ERROR_USAGE;
  } catch (const insitu::UsageError& e) {  // the session's argument checks (times)
    g_error = e.what();
    code = PANOPTES_ERROR_USAGE;
  } catch (const std::exception& e) {
    g_error = e.what();
    code = PANOPTES_ERROR_RUN;
  } catch (...) {
    g_error = "unknown error";
    code = PANOPTES_ERROR_RUN;
  }
  report(s, g_error);
  if (s && !key.empty()) s->failed_calls[key] = g_error;
  return code;
}

void need(bool ok, const std::string& what) {
  if (!ok) throw UsageError(what);
}

// Every patch's state, the selected one included, in patch order (non-uniform grids).
// --- the session, built at the first collective call ---
std::map<int, panoptes_session::PatchState> all_patches(const panoptes_session* s) {
  std::map<int, panoptes_session::PatchState> all = s->other_patches;
  all[s->patch] = {s->block, s->fields};
  return all;
}

std::vector<insitu::GridBlock> grid_blocks(const panoptes_session* s) {
  std::vector<insitu::GridBlock> v;
  for (const auto& [patch, st] : all_patches(s))
    if (st.block) v.push_back({patch, st.block->offset, st.block->extent, st.block->ghost_lo, st.block->ghost_hi});
  return v;
}

#ifdef PANOPTES_HAVE_MPI
MPI_Comm comm_of(int fortran_comm) {
  return fortran_comm == PANOPTES_COMM_WORLD ? MPI_COMM_WORLD : MPI_Comm_f2c(fortran_comm);
}
#endif

// The session, built at the first collective call. Its preconditions and this rank's failed calls
// are agreed with the other ranks first: a rank that cannot start refuses the call on every rank
// (naming itself) instead of leaving them in the session's first collective.
insitu::Session& session_of(panoptes_session* s) {
  need(s, "null session");
  if (s->session) {
    if (!s->failed_calls.empty()) {
      s->session->refuse_next_call(s->failures());
      s->failed_calls.clear();
    }
    return *s->session;
  }
  std::exception_ptr local;
  try {
    need(s->failed_calls.empty(), s->failures());
    need(s->grid.has_value() || s->source.has_value(),
         "panoptes_set_grid (or _rectilinear, _spherical, _yinyang) must be called before the first snapshot");
    need(s->block.has_value() || (s->source && !grid_blocks(s).empty()),
         "panoptes_set_block must be called before the first snapshot");
  } catch (...) {
    local = std::current_exception();
  }
  s->failed_calls.clear();
  s->agreement.agree(insitu::CallRecord{}, local, insitu::Failure::refused);
#ifdef PANOPTES_HAVE_MPI
  int init = 0;
  MPI_Initialized(&init);
  if (init) {
    const MPI_Comm comm = comm_of(s->fortran_comm);
    if (s->source) {
      s->session = std::make_unique<insitu::Session>(s->config, *s->source, grid_blocks(s), s->resample, comm, s->meter);
    } else {
      s->session = std::make_unique<insitu::Session>(s->config, *s->grid, *s->block, comm, s->meter);
    }
    return *s->session;
  }
#endif
  if (s->source) {
    s->session = std::make_unique<insitu::Session>(s->config, *s->source, grid_blocks(s), s->resample, s->meter);
  } else {
    s->session = std::make_unique<insitu::Session>(s->config, *s->grid, *s->block, s->meter);
  }
  return *s->session;
}

// The bound fields; on a source grid one input per field and block, blocks in patch order (as
// grid_blocks() gave them to the session's grid stage, which resamples them at snapshots only).
std::vector<insitu::FieldInput> inputs(const panoptes_session* s) {
  std::vector<insitu::FieldInput> v;
  if (!s->source) {
    for (const auto& [name, f] : s->fields) v.push_back(f);
    return v;
  }
  for (const auto& [patch, st] : all_patches(s))
    if (st.block)
      for (const auto& [name, f] : st.fields) v.push_back(f);
  return v;
}

// The three non-uniform grid calls: coordinates per axis, validated.
// --- grids ---
int set_source_grid(panoptes_session* s, const char* call, grid::GridKind kind, const int dims[3], const double* a,
                    const double* b, const double* c) {
  return guarded(s, [&] {
    need(s && dims && a && b && c, std::string(call) + ": null argument");
    need(!s->session, std::string(call) + ": the grid cannot change after the first snapshot");
    for (int d = 0; d < 3; ++d)
      need(dims[d] >= 2 && dims[d] <= 65535, std::string(call) + ": dims[" + std::to_string(d) + "] = " +
                                                 std::to_string(dims[d]) + "; expected 2 to 65535 points");
    std::vector<double> x(a, a + dims[0]), y(b, b + dims[1]), z(c, c + dims[2]);
    grid::GridDescription g = grid::GridDescription::of_kind(kind, std::move(x), std::move(y), std::move(z));
    try {
      g.validate();
    } catch (const std::exception& e) {
      throw UsageError(std::string(call) + ": " + e.what());
    }
    s->source = std::move(g);
    s->grid.reset();
  }, "");
}

// --- field bindings: layouts, strides, counts ---
std::string shape_text(const std::array<long long, 3>& v) {
  std::string text = "(";  // appended, not "(" + ...: GCC 12 warns falsely (-Wrestrict) on the latter
  for (int d = 0; d < 3; ++d) text.append(std::to_string(v[d])).append(d < 2 ? ", " : ")");
  return text;
}

// Grid axis (0 = x, 1 = y, 2 = z) of each array dimension, from "xyz", "zxy", ... (any case).
std::array<int, 3> parse_layout(const char* layout, const std::string& call) {
  const std::string text = layout ? layout : "";
  std::array<int, 3> axis{-1, -1, -1};
  bool ok = text.size() == 3;
  for (std::size_t d = 0; ok && d < 3; ++d) {
    const char c = char(std::tolower(static_cast<unsigned char>(text[d])));
    axis[d] = c == 'x' ? 0 : c == 'y' ? 1 : c == 'z' ? 2 : -1;
    ok = axis[d] >= 0;
    for (std::size_t e = 0; ok && e < d; ++e) ok = axis[e] != axis[d];
  }
  need(ok, call + ": layout \"" + text + "\"; expected the three axes x, y, z in the order of the array's dimensions, e.g. \"xyz\" or \"zxy\"");
  return axis;
}

std::array<long long, 3> ghosted_extent(const insitu::LocalBlock& b) {
  return {(long long)b.extent[0] + b.ghost_lo[0] + b.ghost_hi[0], (long long)b.extent[1] + b.ghost_lo[1] + b.ghost_hi[1],
          (long long)b.extent[2] + b.ghost_lo[2] + b.ghost_hi[2]};
}

// Binds `data` (first STORED element) with strides per grid axis x, y, z. Every binding is checked for
// strides whose reach over the ghosted block overflows 64 bits (a wrapped offset would pass any bounds
// check and read elsewhere); with a `count` (the _n calls), the reach must also lie in data[0 .. count-1].
void bind_field(panoptes_session* s, const std::string& call, const char* name, const void* data, int type,
                const std::array<std::int64_t, 3>& st, std::optional<long long> count = std::nullopt) {
  const insitu::LocalBlock& b = *s->block;
  const auto n = ghosted_extent(b);
  const std::size_t elem = type == PANOPTES_FLOAT64 ? sizeof(double) : sizeof(float);
  for (int a = 0; a < 3; ++a)
    need(st[a] != 0 || n[a] <= 1, call + ": field \"" + name + "\" has stride 0 on axis " + "xyz"[a]);
  const std::string what = call + ": field \"" + name + "\": the block with its stored ghosts " + shape_text(n) +
                           " (x, y, z) at strides " + shape_text({st[0], st[1], st[2]});
  const auto reach = strided_reach({n[0], n[1], n[2]}, st, std::int64_t(elem));
  need(reach.has_value(), what + " reaches further than 64-bit offsets can address; expected the strides of an array in memory");
  if (count) {
    const long long c = *count;
    need(reach->lo >= 0 && reach->hi < c,
         what + " reaches elements " + std::to_string(reach->lo) + " .. " + std::to_string(reach->hi) +
             " of the buffer, which holds " + std::to_string(c) + (c > 0 ? " (0 .. " + std::to_string(c - 1) + ")" : "") +
             (reach->lo < 0 ? "; a negative stride reaches before data, which must be the buffer's first element" : ""));
  }
  // Within the reach (ghost_lo < the ghosted extent), so neither this offset nor its bytes overflow.
  const std::int64_t shift = b.ghost_lo[0] * st[0] + b.ghost_lo[1] * st[1] + b.ghost_lo[2] * st[2];
  insitu::FieldInput in;
  in.name = name;
  in.data = static_cast<const char*>(data) + shift * std::int64_t(elem);
  in.type = type == PANOPTES_FLOAT64 ? insitu::ScalarType::f64 : insitu::ScalarType::f32;
  in.stride = st;
  s->fields[in.name] = in;
}

// The common checks of the set_field calls; returns the strides per axis (default: contiguous x-fastest).
std::array<std::int64_t, 3> field_strides(panoptes_session* s, const std::string& call, const char* name, const void* data,
                                          int type, const long long strides[3]) {
  need(s && name, call + ": null session or name");
  // A binding that fails leaves none (not the previous step's array: a stale picture, issue 42).
  s->fields.erase(name);
  need(data, call + ": field \"" + std::string(name) + "\": null data");
  need(type == PANOPTES_FLOAT32 || type == PANOPTES_FLOAT64,
       call + ": type " + std::to_string(type) + "; expected PANOPTES_FLOAT32 or PANOPTES_FLOAT64");
  need(s->block.has_value(), call + ": call panoptes_set_block first");
  if (strides) return {strides[0], strides[1], strides[2]};
  const auto n = ghosted_extent(*s->block);
  return {1, n[0], n[0] * n[1]};
}

// panoptes_set_field_layout and its _n form (count: the buffer's elements from data on).
void set_field_layout(panoptes_session* s, const std::string& call, const char* name, const void* data, int type,
                      const char* layout, const long long extents[3], const long long strides[3],
                      std::optional<long long> count) {
  {
    need(s && name, call + ": null session or name");
    s->fields.erase(name);  // a binding that fails leaves none (not a stale one)
    need(extents && strides, call + ": field \"" + std::string(name) + "\": null extents or strides");
    need(s->block.has_value(), call + ": call panoptes_set_block first");
    // No layout (NULL or ""; the Fortran module's panoptes_field without layout=): "xyz", but only
    // where the shape tells it from every other order (issue 42: a z-fastest array on a ghosted cube
    // fitted "xyz" too and was taken for it without a word).
    const bool defaulted = !layout || !*layout;
    if (defaulted) layout = "xyz";
    const auto axis = parse_layout(layout, call);
    const std::string lay = std::string("\"") + layout + "\"";
    const auto n = ghosted_extent(*s->block);
    const std::array<long long, 3> got{extents[0], extents[1], extents[2]};
    std::array<long long, 3> want{};
    for (int d = 0; d < 3; ++d) want[d] = n[axis[d]];
    if (got != want) {
      std::string msg = call + ": field \"" + name + "\" has shape " + shape_text(got) + "; the block with its stored ghosts is " +
                        shape_text(n) + " points (x, y, z), which in layout " + lay + " is the shape " + shape_text(want);
      // A hint when the array fits the block in another axis order (the usual mistake: z fastest).
      // Every order that fits is named: when two extents are equal the shape cannot tell their axes
      // apart, and naming only the first sent a user to a layout that was silently wrong (issue 42).
      static const char* const orders[] = {"xyz", "xzy", "yxz", "yzx", "zxy", "zyx"};
      std::vector<std::string> fits;
      for (const char* o : orders) {
        const auto ax = parse_layout(o, call);
        if (std::array<long long, 3>{n[ax[0]], n[ax[1]], n[ax[2]]} == got && ax != axis) fits.push_back(o);
      }
      if (fits.size() == 1) msg += "; the array fits layout \"" + fits[0] + "\": is that its axis order?";
      if (fits.size() > 1) {
        msg += "; the array fits layouts ";
        for (std::size_t i = 0; i < fits.size(); ++i)
          msg += (i == 0 ? "\"" : i + 1 == fits.size() ? "\" and \"" : "\", \"") + fits[i];
        msg += "\" alike (its shape cannot tell their axes apart): give the one that is the array's axis order";
      }
      throw UsageError(msg);
    }
    if (defaulted) {
      std::vector<std::string> fits;
      for (const char* o : {"xyz", "xzy", "yxz", "yzx", "zxy", "zyx"}) {
        const auto ax = parse_layout(o, call);
        if (std::array<long long, 3>{n[ax[0]], n[ax[1]], n[ax[2]]} == got) fits.push_back(o);
      }
      if (fits.size() > 1) {
        std::string list;
        for (std::size_t i = 0; i < fits.size(); ++i) list += (i ? ", \"" : "\"") + fits[i] + "\"";
        throw UsageError(call + ": field \"" + name + "\" has shape " + shape_text(got) + ", which fits the block " +
                         shape_text(n) + " (x, y, z) in the layouts " + list +
                         " alike: the shape cannot tell its axis order, so give it (Fortran: layout='xyz' for a(i,j,k), "
                         "layout='zxy' for a z-fastest v(k,i,j))");
      }
    }
    need(data, call + ": field \"" + std::string(name) + "\": null data");
    std::array<std::int64_t, 3> st{};
    for (int d = 0; d < 3; ++d) {
      need(strides[d] != 0 || got[d] <= 1, call + ": field \"" + std::string(name) + "\" has stride 0 along dimension " + std::to_string(d + 1));
      st[axis[d]] = strides[d];
    }
    bind_field(s, call, name, data, type,
               field_strides(s, call, name, data, type, std::array<long long, 3>{st[0], st[1], st[2]}.data()), count);
  }
}

}  // namespace

// --- the C functions ---
extern "C" {

int panoptes_create(const char* config, int config_is_file, int fortran_comm, panoptes_session** out) {
  return guarded(nullptr, [&] {
    need(out, "panoptes_create: null output pointer");
    *out = nullptr;
    auto s = std::make_unique<panoptes_session>();
    insitu::OverheadMeter::Scope counted(*s->meter);  // reading the configuration is Panoptes' too
    s->fortran_comm = fortran_comm;
    std::exception_ptr local;
    try {
      need(config, "panoptes_create: null config");
      try {
        s->config = config_is_file ? insitu::load_session_config(config)
                                   : insitu::parse_session_config_text(config, "configuration text");
        s->config.validate();
      } catch (const std::exception& e) {
        throw ConfigError(e.what());
      }
    } catch (...) {
      local = std::current_exception();
    }
#ifdef PANOPTES_HAVE_MPI
    int init = 0;
    MPI_Initialized(&init);
    if (init) {
      const MPI_Comm comm = comm_of(fortran_comm);
      MPI_Comm_rank(comm, &s->rank);
      MPI_Comm_size(comm, &s->ranks);
      // Collective: a rank whose configuration is refused makes every rank's panoptes_create fail (the
      // others would start a session and wait for it at the first snapshot).
      s->agreement = insitu::RankAgreement(comm, s->config.mpi_timeout);
    }
#endif
    s->agreement.agree(insitu::CallRecord{}, local, insitu::Failure::failed);
    s->config.program = "panoptes C API";
    *out = s.release();
  }, "");
}

int panoptes_set_grid(panoptes_session* s, const int dims[3], const double origin[3], const double spacing[3]) {
  return guarded(s, [&] {
    need(s && dims && origin && spacing, "panoptes_set_grid: null argument");
    need(!s->session, "panoptes_set_grid: the grid cannot change after the first snapshot");
    render::GridGeometry g{{dims[0], dims[1], dims[2]}, {origin[0], origin[1], origin[2]}, {spacing[0], spacing[1], spacing[2]}};
    try {
      g.validate();
    } catch (const std::exception& e) {
      throw UsageError(std::string("panoptes_set_grid: ") + e.what());
    }
    s->grid = g;
    s->source.reset();
  }, "");
}

int panoptes_set_grid_rectilinear(panoptes_session* s, const int dims[3], const double* x, const double* y,
                                  const double* z) {
  return set_source_grid(s, "panoptes_set_grid_rectilinear", grid::GridKind::rectilinear, dims, x, y, z);
}

int panoptes_set_grid_spherical(panoptes_session* s, const int dims[3], const double* r, const double* theta,
                                const double* phi) {
  return set_source_grid(s, "panoptes_set_grid_spherical", grid::GridKind::spherical, dims, r, theta, phi);
}

int panoptes_set_grid_yinyang(panoptes_session* s, const int dims[3], const double* r, const double* theta,
                              const double* phi) {
  return set_source_grid(s, "panoptes_set_grid_yinyang", grid::GridKind::yinyang, dims, r, theta, phi);
}

int panoptes_set_patch(panoptes_session* s, int patch) {
  return guarded(s, [&] {
    need(s, "panoptes_set_patch: null session");
    need(s->source && s->source->kind == grid::GridKind::yinyang,
         "panoptes_set_patch: only a Yin-Yang grid has patches (call panoptes_set_grid_yinyang first)");
    need(patch == 0 || patch == 1,
         "panoptes_set_patch: patch " + std::to_string(patch) + "; expected 0 (Yin) or 1 (Yang)");
    if (patch == s->patch) return;
    // After the first snapshot the blocks are fixed, but a rank holding both patches must still be able
    // to re-bind each patch's fields every step (issue 42: refused, Yin kept rendering step 0's array).
    // So selecting a patch stays allowed; only one that had no block then would be a new block.
    if (s->session) {
      const auto it = s->other_patches.find(patch);
      need(it != s->other_patches.end() && it->second.block.has_value(),
           "panoptes_set_patch: patch " + std::to_string(patch) +
               " had no block on this rank at the first snapshot; the blocks cannot change after it");
    }
    s->other_patches[s->patch] = {s->block, s->fields};
    panoptes_session::PatchState next = s->other_patches[patch];
    s->other_patches.erase(patch);
    s->block = next.block;
    s->fields = next.fields;
    s->patch = patch;
  }, "");
}

int panoptes_set_resample(panoptes_session* s, int longest_axis_points, double outside_value) {
  return guarded(s, [&] {
    need(s, "panoptes_set_resample: null session");
    need(!s->session, "panoptes_set_resample: the resampling cannot change after the first snapshot");
    need(longest_axis_points == 0 || (longest_axis_points >= 2 && longest_axis_points <= 4096),
         "panoptes_set_resample: " + std::to_string(longest_axis_points) +
             " points; expected 2 to 4096 along the longest axis (0 = the source's largest dimension)");
    need(std::isfinite(outside_value), "panoptes_set_resample: the outside value is not finite");
    s->resample = {longest_axis_points, float(outside_value)};
  }, "");
}

int panoptes_set_block(panoptes_session* s, const int offset[3], const int extent[3], const int ghost_lo[3],
                       const int ghost_hi[3]) {
  return guarded(s, [&] {
    need(s && offset && extent && ghost_lo && ghost_hi, "panoptes_set_block: null argument");
    need(!s->session, "panoptes_set_block: the block cannot change after the first snapshot");
    insitu::LocalBlock b;
    for (int a = 0; a < 3; ++a) {
      need(offset[a] >= 0 && extent[a] >= 0 && ghost_lo[a] >= 0 && ghost_hi[a] >= 0,
           "panoptes_set_block: negative offset, extent or ghost width on axis " + std::to_string(a));
      b.offset[a] = offset[a];
      b.extent[a] = extent[a];
      b.ghost_lo[a] = ghost_lo[a];
      b.ghost_hi[a] = ghost_hi[a];
    }
    s->block = b;
    s->fields.clear();  // bound against the old block's shape
  }, "");
}

int panoptes_set_halo(panoptes_session* s, const int valid_lo[3], const int valid_hi[3], int edges_valid) {
  return guarded(s, [&] {
    need(s, "panoptes_set_halo: null session");
    need(s->block.has_value(), "panoptes_set_halo: call panoptes_set_block first");
    need(!s->session, "panoptes_set_halo: the halo cannot change after the first snapshot");
    insitu::LocalBlock& b = *s->block;
    static const char* const axes = "xyz";
    for (int a = 0; a < 3; ++a) {
      const int lo = valid_lo ? valid_lo[a] : -1, hi = valid_hi ? valid_hi[a] : -1;
      need(lo >= -1 && lo <= b.ghost_lo[a] && hi >= -1 && hi <= b.ghost_hi[a],
           std::string("panoptes_set_halo: valid ghost layers ") + std::to_string(lo) + " below / " + std::to_string(hi) +
               " above on axis " + axes[a] + "; expected -1 (every stored layer) or 0 .. the stored " +
               std::to_string(b.ghost_lo[a]) + " / " + std::to_string(b.ghost_hi[a]) + " (panoptes_set_block)");
      b.valid_lo[a] = lo;
      b.valid_hi[a] = hi;
    }
    b.edges_valid = edges_valid != 0;
  }, "");
}

int panoptes_set_field(panoptes_session* s, const char* name, const void* data, int type, const long long strides[3]) {
  return guarded(s, [&] {
    const std::string call = "panoptes_set_field";
    // {0, 0, 0} always meant what NULL means here (FieldInput's "contiguous x-fastest"), and codes pass it.
    const bool contiguous = strides && strides[0] == 0 && strides[1] == 0 && strides[2] == 0;
    bind_field(s, call, name, data, type, field_strides(s, call, name, data, type, contiguous ? nullptr : strides));
  }, field_key(name));
}

int panoptes_set_field_n(panoptes_session* s, const char* name, const void* data, int type, const long long strides[3],
                         long long count) {
  return guarded(s, [&] {
    const std::string call = "panoptes_set_field_n";
    bind_field(s, call, name, data, type, field_strides(s, call, name, data, type, strides), count);
  }, field_key(name));
}

int panoptes_set_field_layout(panoptes_session* s, const char* name, const void* data, int type, const char* layout,
                              const long long extents[3], const long long strides[3]) {
  return guarded(s, [&] {
    set_field_layout(s, "panoptes_set_field_layout", name, data, type, layout, extents, strides, std::nullopt);
  }, field_key(name));
}

int panoptes_set_field_layout_n(panoptes_session* s, const char* name, const void* data, int type, const char* layout,
                                const long long extents[3], const long long strides[3], long long count) {
  return guarded(s, [&] {
    set_field_layout(s, "panoptes_set_field_layout_n", name, data, type, layout, extents, strides, count);
  }, field_key(name));
}

int panoptes_process(panoptes_session* s, long long step, double time, int* taken) {
  return guarded(s, [&] {
    if (taken) *taken = 0;  // also when refused
    insitu::Session& ss = session_of(s);
    const bool t = ss.process(step, time, inputs(s));
    if (taken) *taken = t ? 1 : 0;
  }, "");
}

int panoptes_due(panoptes_session* s, long long step, double time, int* due) {
  return guarded(s, [&] {
    need(due, "panoptes_due: null output pointer");
    *due = session_of(s).due(step, time) ? 1 : 0;
  }, "");
}

int panoptes_snapshot(panoptes_session* s, double time) {
  return guarded(s, [&] { session_of(s).snapshot(time, inputs(s)); }, "");
}

int panoptes_finalize(panoptes_session* s) {
  return guarded(s, [&] {
    insitu::Session& ss = session_of(s);
    const bool first = !s->finalized;
    ss.finalize();
    s->finalized = true;
    // The in-situ overhead, once, on rank 0 (stderr: the simulation's own output stays on stdout).
    if (first) {
      const std::string report = insitu::overhead_report(ss.overhead());
      if (ss.rank() == 0) std::fprintf(stderr, "panoptes: %s", report.c_str());
    }
  }, "");
}

void panoptes_destroy(panoptes_session* s) {
  try {
    delete s;
  } catch (...) {
  }
}

const char* panoptes_last_error(void) { return g_error.c_str(); }

const char* panoptes_version(void) { return panoptes::kVersion; }

void panoptes_set_error_output(int mode) {
  if (mode == PANOPTES_ERRORS_ALL || mode == PANOPTES_ERRORS_RANK0 || mode == PANOPTES_ERRORS_NONE) g_error_mode = mode;
}

}  // extern "C"
