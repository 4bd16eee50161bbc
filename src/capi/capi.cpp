// The C API over insitu::Session: errors become return codes + a thread-local message.
#include "panoptes.h"

#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "core/error.hpp"
#include "insitu/session.hpp"

using namespace panoptes;

struct panoptes_session {
  insitu::SessionConfig config;
  int fortran_comm = PANOPTES_COMM_WORLD;
  std::optional<render::GridGeometry> grid;
  std::optional<insitu::LocalBlock> block;
  std::map<std::string, insitu::FieldInput> fields;
  std::unique_ptr<insitu::Session> session;
  bool finalized = false;  // the overhead report is printed by the first panoptes_finalize only
};

namespace {

thread_local std::string g_error;

struct UsageError : Error {
  using Error::Error;
};
struct ConfigError : Error {
  using Error::Error;
};

template <class F>
int guarded(F&& f) {
  try {
    f();
    g_error.clear();
    return PANOPTES_OK;
  } catch (const ConfigError& e) {
    g_error = e.what();
    return PANOPTES_ERROR_CONFIG;
  } catch (const UsageError& e) {
    g_error = e.what();
    return PANOPTES_ERROR_USAGE;
  } catch (const std::exception& e) {
    g_error = e.what();
    return PANOPTES_ERROR_RUN;
  } catch (...) {
    g_error = "unknown error";
    return PANOPTES_ERROR_RUN;
  }
}

void need(bool ok, const std::string& what) {
  if (!ok) throw UsageError(what);
}

insitu::Session& session_of(panoptes_session* s) {
  need(s, "null session");
  if (s->session) return *s->session;
  need(s->grid.has_value(), "panoptes_set_grid must be called before the first snapshot");
  need(s->block.has_value(), "panoptes_set_block must be called before the first snapshot");
#ifdef PANOPTES_HAVE_MPI
  int init = 0;
  MPI_Initialized(&init);
  if (init) {
    MPI_Comm comm = s->fortran_comm == PANOPTES_COMM_WORLD ? MPI_COMM_WORLD : MPI_Comm_f2c(s->fortran_comm);
    s->session = std::make_unique<insitu::Session>(s->config, *s->grid, *s->block, comm);
    return *s->session;
  }
#endif
  s->session = std::make_unique<insitu::Session>(s->config, *s->grid, *s->block);
  return *s->session;
}

std::vector<insitu::FieldInput> inputs(const panoptes_session* s) {
  std::vector<insitu::FieldInput> v;
  for (const auto& [name, f] : s->fields) v.push_back(f);
  return v;
}

}  // namespace

extern "C" {

int panoptes_create(const char* config, int config_is_file, int fortran_comm, panoptes_session** out) {
  return guarded([&] {
    need(config && out, "panoptes_create: null config or output pointer");
    *out = nullptr;
    auto s = std::make_unique<panoptes_session>();
    try {
      s->config = config_is_file ? insitu::load_session_config(config)
                                 : insitu::parse_session_config_text(config, "configuration text");
      s->config.validate();
    } catch (const std::exception& e) {
      throw ConfigError(e.what());
    }
    s->config.program = "panoptes C API";
    s->fortran_comm = fortran_comm;
    *out = s.release();
  });
}

int panoptes_set_grid(panoptes_session* s, const int dims[3], const double origin[3], const double spacing[3]) {
  return guarded([&] {
    need(s && dims && origin && spacing, "panoptes_set_grid: null argument");
    need(!s->session, "panoptes_set_grid: the grid cannot change after the first snapshot");
    render::GridGeometry g{{dims[0], dims[1], dims[2]}, {origin[0], origin[1], origin[2]}, {spacing[0], spacing[1], spacing[2]}};
    try {
      g.validate();
    } catch (const std::exception& e) {
      throw UsageError(std::string("panoptes_set_grid: ") + e.what());
    }
    s->grid = g;
  });
}

int panoptes_set_block(panoptes_session* s, const int offset[3], const int extent[3], const int ghost_lo[3],
                       const int ghost_hi[3]) {
  return guarded([&] {
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
  });
}

int panoptes_set_field(panoptes_session* s, const char* name, const void* data, int type, const long long strides[3]) {
  return guarded([&] {
    need(s && name && data, "panoptes_set_field: null session, name or data");
    need(type == PANOPTES_FLOAT32 || type == PANOPTES_FLOAT64,
         "panoptes_set_field: type " + std::to_string(type) + "; expected PANOPTES_FLOAT32 or PANOPTES_FLOAT64");
    need(s->block.has_value(), "panoptes_set_field: call panoptes_set_block first");
    const insitu::LocalBlock& b = *s->block;
    std::array<std::int64_t, 3> st{};
    if (strides) {
      st = {strides[0], strides[1], strides[2]};
    } else {
      const std::int64_t nx = b.extent[0] + b.ghost_lo[0] + b.ghost_hi[0];
      const std::int64_t ny = b.extent[1] + b.ghost_lo[1] + b.ghost_hi[1];
      st = {1, nx, nx * ny};
    }
    const std::int64_t shift = b.ghost_lo[0] * st[0] + b.ghost_lo[1] * st[1] + b.ghost_lo[2] * st[2];
    const std::size_t elem = type == PANOPTES_FLOAT64 ? sizeof(double) : sizeof(float);
    insitu::FieldInput in;
    in.name = name;
    in.data = static_cast<const char*>(data) + shift * std::int64_t(elem);
    in.type = type == PANOPTES_FLOAT64 ? insitu::ScalarType::f64 : insitu::ScalarType::f32;
    in.stride = st;
    s->fields[in.name] = in;
  });
}

int panoptes_process(panoptes_session* s, long long step, double time, int* taken) {
  return guarded([&] {
    insitu::Session& ss = session_of(s);
    const bool t = ss.process(step, time, inputs(s));
    if (taken) *taken = t ? 1 : 0;
  });
}

int panoptes_snapshot(panoptes_session* s, double time) {
  return guarded([&] { session_of(s).snapshot(time, inputs(s)); });
}

int panoptes_finalize(panoptes_session* s) {
  return guarded([&] {
    insitu::Session& ss = session_of(s);
    const bool first = !s->finalized;
    ss.finalize();
    s->finalized = true;
    // The in-situ overhead, once, on rank 0 (stderr: the simulation's own output stays on stdout).
    if (first) {
      const std::string report = insitu::overhead_report(ss.overhead());
      if (ss.rank() == 0) std::fprintf(stderr, "panoptes: %s", report.c_str());
    }
  });
}

void panoptes_destroy(panoptes_session* s) {
  try {
    delete s;
  } catch (...) {
  }
}

const char* panoptes_last_error(void) { return g_error.c_str(); }

}  // extern "C"
