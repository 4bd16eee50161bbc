// Compositing traffic of the in-situ session, measured and modelled (issue 46: past one machine).
//
//   mpirun -np P compositing_traffic measure W H [RIG]
//                                                  one snapshot through insitu::Session on P z-slabs of a
//                                                  64x128x40 grid, 130 Yin-Yang cameras (or RIG) x 3 tasks at WxH;
//                                                  every point-to-point message is counted (MPI_Send/Isend/
//                                                  Recv are interposed below) and compared with the model
//   compositing_traffic model                      the model at the paper's scale: 256x512x160 points,
//                                                  130 cameras x 3 tasks at 920x896, 10^2..10^4 ranks on a
//                                                  3-D block decomposition, direct send against bands
//                                                  (the session's schedule when ranks outnumber cameras)
//                                                  and binary swap
//   compositing_traffic blend LAYERS               CPU-ns per pixel and layer of the owner's blending
//
// The model is the session's own rule (session_frames.cpp): per camera, every rank with a brick sends
// its K partial images - each the brick's projected bounding rectangle (render_brick's rule: the 8 corner
// projections, one pixel of margin, clipped to the image; the whole image when a corner does not
// project) with 20 bytes per pixel and a 20-byte header - to the camera's owner, rank c mod P, which
// composites and encodes. Output: Markdown tables (scripts/bench runs bench/compositing_bench).
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "camera/rig_spec.hpp"
#include "insitu/halo.hpp"
#include "insitu/session.hpp"
#include "render/field_view.hpp"
#include "render/partial_image.hpp"
#include "render/synthetic_fields.hpp"

using namespace panoptes;

// ---- Counting every point-to-point message (PMPI interposition: these definitions replace the MPI
// library's for the whole process, the session's calls included). Tags 11-13 are the session's compositing
// (partial images, band partials, finished band rows); a message to oneself is not counted.
namespace {
constexpr int kCompositingTag = 11, kBandTag = 12, kRowsTag = 13;
struct Count {
  long long msgs = 0, bytes = 0;
};
Count g_sent[2], g_recv[2];  // [0] partial images (tag 11), [1] every other point-to-point message
long long g_collectives = 0;

void add(Count* table, int tag, long long count, MPI_Datatype type, int peer = -1, MPI_Comm comm = MPI_COMM_NULL) {
  if (comm != MPI_COMM_NULL) {  // a message to oneself is a copy, not traffic
    int me = -1;
    PMPI_Comm_rank(comm, &me);
    if (peer == me) return;
  }
  int size = 0;
  PMPI_Type_size(type, &size);
  Count& c = table[tag == kCompositingTag || tag == kBandTag || tag == kRowsTag ? 0 : 1];
  ++c.msgs;
  c.bytes += count * size;
}
}  // namespace

extern "C" {
int MPI_Send(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm) {
  add(g_sent, tag, count, type, dest, comm);
  return PMPI_Send(buf, count, type, dest, tag, comm);
}
int MPI_Isend(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm, MPI_Request* req) {
  add(g_sent, tag, count, type, dest, comm);
  return PMPI_Isend(buf, count, type, dest, tag, comm, req);
}
int MPI_Recv(void* buf, int count, MPI_Datatype type, int source, int tag, MPI_Comm comm, MPI_Status* status) {
  MPI_Status own;
  MPI_Status* st = status == MPI_STATUS_IGNORE ? &own : status;
  const int rc = PMPI_Recv(buf, count, type, source, tag, comm, st);
  int got = 0;
  PMPI_Get_count(st, type, &got);
  add(g_recv, st->MPI_TAG, got, type, st->MPI_SOURCE, comm);
  return rc;
}
int MPI_Allreduce(const void* s, void* r, int n, MPI_Datatype t, MPI_Op op, MPI_Comm comm) {
  ++g_collectives;
  return PMPI_Allreduce(s, r, n, t, op, comm);
}
int MPI_Iallreduce(const void* s, void* r, int n, MPI_Datatype t, MPI_Op op, MPI_Comm comm, MPI_Request* req) {
  ++g_collectives;
  return PMPI_Iallreduce(s, r, n, t, op, comm, req);
}
int MPI_Allgather(const void* s, int sn, MPI_Datatype st, void* r, int rn, MPI_Datatype rt, MPI_Comm comm) {
  ++g_collectives;
  return PMPI_Allgather(s, sn, st, r, rn, rt, comm);
}
int MPI_Allgatherv(const void* s, int sn, MPI_Datatype st, void* r, const int* rc, const int* d, MPI_Datatype rt,
                   MPI_Comm comm) {
  ++g_collectives;
  return PMPI_Allgatherv(s, sn, st, r, rc, d, rt, comm);
}
int MPI_Bcast(void* b, int n, MPI_Datatype t, int root, MPI_Comm comm) {
  ++g_collectives;
  return PMPI_Bcast(b, n, t, root, comm);
}
int MPI_Ibcast(void* b, int n, MPI_Datatype t, int root, MPI_Comm comm, MPI_Request* req) {
  ++g_collectives;
  return PMPI_Ibcast(b, n, t, root, comm, req);
}
}

namespace {

// ---- The model.
struct RankTraffic {
  double sent_msgs = 0, sent_bytes = 0, recv_msgs = 0, recv_bytes = 0;
};

/// render_brick's footprint rule (renderer.cpp), as pixels.
std::int64_t footprint_pixels(const camera::Camera& cam, const render::GridGeometry& g, const render::Brick& b,
                              render::PixelRect* out = nullptr) {
  const int W = cam.width(), H = cam.height();
  render::PixelRect r{W, H, 0, 0};
  bool all = false;
  for (int c = 0; c < 8 && !all; ++c) {
    Vec3 p;
    for (int a = 0; a < 3; ++a) p[a] = g.origin[a] + ((c >> a) & 1 ? b.hi[a] : b.lo[a]) * g.spacing[a];
    double px, py;
    if (!cam.project(p, px, py)) {
      all = true;
      break;
    }
    r.x0 = std::min(r.x0, int(std::floor(std::max(px, -1.0))) - 1);
    r.y0 = std::min(r.y0, int(std::floor(std::max(py, -1.0))) - 1);
    r.x1 = std::max(r.x1, int(std::ceil(std::min(px, W + 1.0))) + 1);
    r.y1 = std::max(r.y1, int(std::ceil(std::min(py, H + 1.0))) + 1);
  }
  if (all) r = {0, 0, W, H};
  r.x0 = std::clamp(r.x0, 0, W);
  r.x1 = std::clamp(r.x1, r.x0, W);
  r.y0 = std::clamp(r.y0, 0, H);
  r.y1 = std::clamp(r.y1, r.y0, H);
  if (out) *out = r;
  return std::int64_t(r.width()) * r.height();
}

struct Setting {
  render::GridGeometry grid;
  std::vector<render::Brick> bricks;  // one per rank (cells; empty = no brick)
  std::vector<camera::Camera> cameras;
  int tasks = 3;
};

bool has_cells(const render::Brick& b) { return b.hi[0] > b.lo[0] && b.hi[1] > b.lo[1] && b.hi[2] > b.lo[2]; }

/// Today's schedule: every brick's K partials of camera c go to rank c mod P.
std::vector<RankTraffic> direct_send(const Setting& s) {
  const int P = int(s.bricks.size()), K = s.tasks;
  std::vector<RankTraffic> t(std::size_t(P), RankTraffic{});
  for (int c = 0; c < int(s.cameras.size()); ++c) {
    const int owner = c % P;
    for (int r = 0; r < P; ++r) {
      if (r == owner || !has_cells(s.bricks[std::size_t(r)])) continue;
      const double bytes = K * (20.0 + 20.0 * double(footprint_pixels(s.cameras[std::size_t(c)], s.grid, s.bricks[std::size_t(r)])));
      t[std::size_t(r)].sent_msgs += 1;
      t[std::size_t(r)].sent_bytes += bytes;
      t[std::size_t(owner)].recv_msgs += 1;
      t[std::size_t(owner)].recv_bytes += bytes;
    }
  }
  return t;
}

/// The session's schedule when ranks outnumber cameras (Session::Impl::render_snapshot_banded): each
/// camera's image is cut into T = ceil(P / C) bands of
/// rows, band j of camera c composited by rank (c·T + j) mod P; a brick sends each band its rect meets
/// the part of its rect inside it, and each band's owner sends the finished band (RGBA8, K tasks) to the
/// camera's encoder (rank c mod P). Sending is what direct send sends (plus headers); receiving and
/// compositing are spread over T ranks per camera.
std::vector<RankTraffic> tiled_direct_send(const Setting& s) {
  const int P = int(s.bricks.size()), K = s.tasks, C = int(s.cameras.size());
  const int T = std::max(1, (P + C - 1) / C);
  std::vector<RankTraffic> t(std::size_t(P), RankTraffic{});
  for (int c = 0; c < C; ++c) {
    const camera::Camera& cam = s.cameras[std::size_t(c)];
    const int H = cam.height(), W = cam.width();
    const int encoder = c % P;
    const auto band_y0 = [&](int j) { return int(std::int64_t(H) * j / T); };
    const auto band_owner = [&](int j) { return int((std::int64_t(c) * T + j) % P); };
    for (int r = 0; r < P; ++r) {
      if (!has_cells(s.bricks[std::size_t(r)])) continue;
      render::PixelRect rect;
      footprint_pixels(cam, s.grid, s.bricks[std::size_t(r)], &rect);
      if (rect.width() <= 0 || rect.height() <= 0) continue;  // a band never hears from a brick that misses it
      for (int j = int(std::int64_t(rect.y0) * T / H); j < T && band_y0(j) < rect.y1; ++j) {
        const int a = std::max(rect.y0, band_y0(j)), b = std::min(rect.y1, band_y0(j + 1));
        if (b <= a || band_owner(j) == r) continue;
        const double bytes = 8.0 + K * (20.0 + 20.0 * double(rect.width()) * (b - a));
        t[std::size_t(r)].sent_msgs += 1;
        t[std::size_t(r)].sent_bytes += bytes;
        t[std::size_t(band_owner(j))].recv_msgs += 1;
        t[std::size_t(band_owner(j))].recv_bytes += bytes;
      }
    }
    for (int j = 0; j < T; ++j) {
      if (band_owner(j) == encoder) continue;
      const double bytes = 8.0 + K * 4.0 * W * (band_y0(j + 1) - band_y0(j));
      t[std::size_t(band_owner(j))].sent_msgs += 1;
      t[std::size_t(band_owner(j))].sent_bytes += bytes;
      t[std::size_t(encoder)].recv_msgs += 1;
      t[std::size_t(encoder)].recv_bytes += bytes;
    }
  }
  return t;
}

/// Binary swap over all P ranks per camera (IceT's classic schedule, full images, P a power of two or
/// the largest one below): log2 P rounds, each rank sends half of its current region each round, then
/// the P pieces (RGBA8) are gathered to the encoder. Per rank and camera: A·20·K·(1 − 1/P') bytes in
/// log2 P' messages (P' = 2^floor(log2 P)); the encoder receives P' − 1 pieces.
std::vector<RankTraffic> binary_swap(const Setting& s) {
  const int P = int(s.bricks.size()), K = s.tasks, C = int(s.cameras.size());
  int Pp = 1, rounds = 0;
  while (Pp * 2 <= P) Pp *= 2, ++rounds;
  std::vector<RankTraffic> t(std::size_t(P), RankTraffic{});
  for (int c = 0; c < C; ++c) {
    const double A = double(s.cameras[std::size_t(c)].width()) * s.cameras[std::size_t(c)].height();
    const int encoder = c % P;
    for (int r = 0; r < Pp; ++r) {
      t[std::size_t(r)].sent_msgs += rounds;
      t[std::size_t(r)].recv_msgs += rounds;
      t[std::size_t(r)].sent_bytes += A * 20.0 * K * (1.0 - 1.0 / Pp);
      t[std::size_t(r)].recv_bytes += A * 20.0 * K * (1.0 - 1.0 / Pp);
      if (r != encoder) {
        t[std::size_t(r)].sent_msgs += 1;
        t[std::size_t(r)].sent_bytes += A * 4.0 * K / Pp;
        t[std::size_t(encoder)].recv_msgs += 1;
        t[std::size_t(encoder)].recv_bytes += A * 4.0 * K / Pp;
      }
    }
  }
  return t;
}

struct Summary {
  double max_sent_msgs = 0, max_sent_mb = 0, mean_sent_mb = 0, max_recv_msgs = 0, max_recv_mb = 0, receivers = 0;
};
Summary summarize(const std::vector<RankTraffic>& t) {
  Summary s;
  for (const RankTraffic& r : t) {
    s.max_sent_msgs = std::max(s.max_sent_msgs, r.sent_msgs);
    s.max_sent_mb = std::max(s.max_sent_mb, r.sent_bytes / 1e6);
    s.mean_sent_mb += r.sent_bytes / 1e6 / double(t.size());
    s.max_recv_msgs = std::max(s.max_recv_msgs, r.recv_msgs);
    s.max_recv_mb = std::max(s.max_recv_mb, r.recv_bytes / 1e6);
    if (r.recv_msgs > 0) s.receivers += 1;
  }
  return s;
}

/// P = px·py·pz as close to cubic as the grid's cells allow (largest factor on the longest axis).
std::vector<render::Brick> blocks_3d(const render::GridGeometry& g, int P) {
  int best[3] = {1, 1, P};
  double best_cost = 1e300;
  for (int px = 1; px <= P; ++px) {
    if (P % px) continue;
    for (int py = 1; py <= P / px; ++py) {
      if ((P / px) % py) continue;
      const int pz = P / px / py;
      const int n[3] = {px, py, pz};
      double surface = 0;  // brick surface: what a near-cubic split minimizes
      bool ok = true;
      double e[3];
      for (int a = 0; a < 3; ++a) {
        e[a] = double(g.dims[a] - 1) / n[a];
        if (e[a] < 1) ok = false;
      }
      if (!ok) continue;
      surface = e[0] * e[1] + e[1] * e[2] + e[0] * e[2];
      if (surface < best_cost) best_cost = surface, best[0] = px, best[1] = py, best[2] = pz;
    }
  }
  std::vector<render::Brick> out;
  for (int k = 0; k < best[2]; ++k)
    for (int j = 0; j < best[1]; ++j)
      for (int i = 0; i < best[0]; ++i) {
        render::Brick b;
        const int idx[3] = {i, j, k};
        for (int a = 0; a < 3; ++a) {
          const int cells = g.dims[a] - 1;
          b.lo[a] = int(std::int64_t(cells) * idx[a] / best[a]);
          b.hi[a] = int(std::int64_t(cells) * (idx[a] + 1) / best[a]);
        }
        out.push_back(b);
      }
  return out;
}

std::vector<camera::Camera> yinyang_cameras(const render::GridGeometry& g, int w, int h) {
  const camera::Rig rig = camera::make_rig("yinyang", camera::Domain{g.domain_lo(), g.domain_hi() - g.domain_lo()});
  std::vector<camera::Camera> cams;
  for (int c = 0; c < rig.size(); ++c) cams.push_back(rig.camera(c, w, h));
  return cams;
}

int model() {
  const render::GridGeometry g{{256, 512, 160}, {0, 0, 0}, {1, 1, 1}};
  const std::vector<camera::Camera> cams = yinyang_cameras(g, 920, 896);
  std::printf("| ranks | decomposition | schedule | msgs sent/rank (max) | MB sent/rank (mean) | MB sent/rank (max) | "
              "ranks receiving | msgs received/rank (max) | MB received/rank (max) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|\n");
  for (int P : {16, 128, 1024, 4096, 10000}) {
    Setting s{g, blocks_3d(g, P), cams, 3};
    int n[3] = {0, 0, 0};  // brick counts per axis, for the table
    for (const render::Brick& b : s.bricks) {
      if (b.lo[1] == 0 && b.lo[2] == 0) ++n[0];
      if (b.lo[0] == 0 && b.lo[2] == 0) ++n[1];
      if (b.lo[0] == 0 && b.lo[1] == 0) ++n[2];
    }
    const struct {
      const char* name;
      std::vector<RankTraffic> t;
    } rows[] = {{"direct send (the session when P <= C)", direct_send(s)}, {"bands (the session when P > C)", tiled_direct_send(s)}, {"binary swap", binary_swap(s)}};
    for (const auto& row : rows) {
      const Summary m = summarize(row.t);
      std::printf("| %d | %dx%dx%d | %s | %.0f | %.2f | %.2f | %.0f | %.0f | %.1f |\n", P, n[0], n[1], n[2], row.name,
                  m.max_sent_msgs, m.mean_sent_mb, m.max_sent_mb, m.receivers, m.max_recv_msgs, m.max_recv_mb);
    }
    std::fflush(stdout);
  }
  return 0;
}

/// CPU-nanoseconds per received pixel-layer of composite_into (the owner's blending): `layers` partial
/// images of 920x896 with random depths and colours, one thread, median of 5.
int blend(int layers) {
  const int W = 920, H = 896;
  std::vector<render::PartialImage> parts(static_cast<std::size_t>(layers));
  std::uint32_t x = 12345;
  const auto rnd = [&x] {
    x = x * 1664525u + 1013904223u;
    return float(x >> 8) / float(1u << 24);
  };
  for (render::PartialImage& p : parts) {
    p.resize(W, H, {0, 0, W, H});
    for (std::size_t i = 0; i < p.depth.size(); ++i) {
      const float a = rnd() * 0.5f;
      p.rgba[4 * i] = a * rnd(), p.rgba[4 * i + 1] = a * rnd(), p.rgba[4 * i + 2] = a * rnd(), p.rgba[4 * i + 3] = a;
      p.depth[i] = rnd() * 100;
    }
  }
  std::vector<const render::PartialImage*> ptr;
  for (const render::PartialImage& p : parts) ptr.push_back(&p);
  render::PartialImage out;
  std::vector<double> ns;
  for (int rep = 0; rep < 5; ++rep) {
    timespec a{}, b{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &a);
    render::composite_into(render::TaskKind::volume, ptr, out);
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &b);
    ns.push_back(((b.tv_sec - a.tv_sec) * 1e9 + (b.tv_nsec - a.tv_nsec)) / (double(W) * H * layers));
  }
  std::sort(ns.begin(), ns.end());
  std::printf("| %d | %.2f |\n", layers, ns[2]);
  return 0;
}

int measure(int width, int height, const std::string& rig) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  const render::GridGeometry g{{64, 128, 40}, {0, 0, 0}, {1, 1, 1}};
  // The brick split, whatever "auto" would pick: on this small grid it picks the cameras split (every
  // rank gathers the whole grid, no partial images), and this program counts what compositing sends.
  const std::string cfg_text = "[output]\ntitle = \"compositing traffic\"\noverwrite = true\n[image]\nwidth = " +
                               std::to_string(width) + "\nheight = " + std::to_string(height) +
                               "\n[rig]\nspec = \"" + rig + "\"\n[resources]\nparallel = \"bricks\"\n[schedule]\nevery_steps = 1\n[video]\ncrf = 30\n"
                               "[[task]]\nname = \"p\"\ntype = \"volume\"\nfield = \"p\"\npreset = \"p-wave\"\n"
                               "[[task]]\nname = \"s\"\ntype = \"volume\"\nfield = \"s\"\npreset = \"s-wave\"\n"
                               "[[task]]\nname = \"p+s\"\ntype = \"volume2\"\nfields = [\"p\", \"s\"]\n";
  insitu::SessionConfig cfg = insitu::parse_session_config_text(cfg_text, "compositing_traffic");
  int pid = rank == 0 ? int(::getpid()) : 0;
  MPI_Bcast(&pid, 1, MPI_INT, 0, MPI_COMM_WORLD);
  cfg.output_dir = (std::filesystem::temp_directory_path() / ("compositing_traffic_" + std::to_string(pid))).string();
  const insitu::LocalBlock block = insitu::LocalBlock::slab(g, 2, size, rank, 2);
  const render::DenseWaveScene scene = render::dense_wave_scene(g);
  Count before_sent[2] = {g_sent[0], g_sent[1]}, before_recv[2] = {g_recv[0], g_recv[1]};
  {
    insitu::Session session(cfg, g, block, MPI_COMM_WORLD);
    before_sent[0] = g_sent[0], before_sent[1] = g_sent[1], before_recv[0] = g_recv[0], before_recv[1] = g_recv[1];
    const std::int64_t plane = std::int64_t(g.dims[0]) * g.dims[1];
    const int k0 = block.offset[2] - block.ghost_lo[2];
    const std::vector<insitu::FieldInput> inputs{
        {"p", scene.p.data() + (k0 + block.ghost_lo[2]) * plane, insitu::ScalarType::f32, {1, g.dims[0], plane}},
        {"s", scene.s.data() + (k0 + block.ghost_lo[2]) * plane, insitu::ScalarType::f32, {1, g.dims[0], plane}}};
    session.process(0, 0.0, inputs);
    session.finalize();
  }
  // Partial-image messages of the one snapshot (tag 11), and the rest (ghost exchange) for reference.
  long long mine[4] = {g_sent[0].msgs - before_sent[0].msgs, g_sent[0].bytes - before_sent[0].bytes,
                       g_recv[0].msgs - before_recv[0].msgs, g_recv[0].bytes - before_recv[0].bytes};
  long long other[2] = {g_sent[1].msgs - before_sent[1].msgs, g_sent[1].bytes - before_sent[1].bytes};
  std::vector<long long> all(4 * std::size_t(size)), all_other(2 * std::size_t(size));
  PMPI_Gather(mine, 4, MPI_LONG_LONG, all.data(), 4, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  PMPI_Gather(other, 2, MPI_LONG_LONG, all_other.data(), 2, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  if (rank == 0) {
    std::vector<render::Brick> bricks;
    for (int r = 0; r < size; ++r) bricks.push_back(insitu::halo::block_info(g, insitu::LocalBlock::slab(g, 2, size, r, 2)).brick);
    const camera::Rig r = camera::make_rig(rig, camera::Domain{g.domain_lo(), g.domain_hi() - g.domain_lo()});
    std::vector<camera::Camera> cams;
    for (int c = 0; c < r.size(); ++c) cams.push_back(r.camera(c, width, height));
    const Setting s{g, bricks, cams, 3};
    const std::vector<RankTraffic> model_t = size > r.size() ? tiled_direct_send(s) : direct_send(s);
    double meas_sent = 0, model_sent = 0, meas_recv_max = 0, model_recv_max = 0, msgs_max = 0, other_mb = 0;
    long long meas_msgs = 0, model_msgs = 0;
    for (int r = 0; r < size; ++r) {
      meas_sent += double(all[std::size_t(4 * r + 1)]);
      model_sent += model_t[std::size_t(r)].sent_bytes;
      meas_msgs += all[std::size_t(4 * r)];
      model_msgs += (long long)model_t[std::size_t(r)].sent_msgs;
      meas_recv_max = std::max(meas_recv_max, double(all[std::size_t(4 * r + 3)]));
      model_recv_max = std::max(model_recv_max, model_t[std::size_t(r)].recv_bytes);
      msgs_max = std::max(msgs_max, double(all[std::size_t(4 * r + 2)]));
      other_mb = std::max(other_mb, double(all_other[std::size_t(2 * r + 1)]) / 1e6);
    }
    std::printf("| %d | %s | %dx%d | %lld | %lld | %.3f | %.3f | %.3f | %.3f | %.0f | %.3f |\n", size, rig.c_str(), width, height, meas_msgs,
                model_msgs, meas_sent / 1e6 / size, model_sent / 1e6 / size, meas_recv_max / 1e6, model_recv_max / 1e6,
                msgs_max, other_mb);
    std::filesystem::remove_all(cfg.output_dir);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "--help" || mode == "-h" || (mode != "model" && mode != "measure" && mode != "blend")) {
    std::printf("usage: compositing_traffic model\n       compositing_traffic blend LAYERS\n"
                "       mpirun -np P compositing_traffic measure [W H [RIG]]\n");
    return mode == "--help" || mode == "-h" ? 0 : 2;
  }
  if (mode == "model") return model();
  if (mode == "blend") return blend(argc > 2 ? std::atoi(argv[2]) : 8);
  MPI_Init(&argc, &argv);
  int rc = 0;
  try {
    rc = measure(argc > 2 ? std::atoi(argv[2]) : 184, argc > 3 ? std::atoi(argv[3]) : 180, argc > 4 ? argv[4] : "yinyang");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "compositing_traffic: %s\n", e.what());
    rc = 1;
  }
  MPI_Finalize();
  return rc;
}
