// `panoptes synth-db OUT ...`: writes a synthetic database whose every frame carries a machine-readable
// stamp of (camera, task, frame), for tests and benchmarks of the player.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <climits>
#include <thread>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <vector>
#include <string>

#include "app/command.hpp"
#include "core/dims_text.hpp"
#include "core/error.hpp"
#include "core/stop_request.hpp"
#include "core/memory.hpp"
#include "video/writer_memory.hpp"
#include "store/database.hpp"
#include "store/synthetic.hpp"

namespace cmd_synth_db {  // named, not anonymous: the unity build joins the command units

struct Args {
  std::string out;
  int cameras = 8, tasks = 2, frames = 10;
  std::string size = "64x64";
  bool overwrite = false;
  int gop = 10, crf = -1, threads = 0;
  std::string preset, title = "synthetic database";
  bool force = false;
  std::string lattice, projection = "perspective";
  int shells = 1;
  std::string axes;  // "3x2x2": value counts of up to 4 parameter axes
  std::string layout;  // "" (the writer's choice: auto), "auto", "files" or "packed"
  bool gop_given = false;
};

// The packed layout written as a simulation writes it (docs/formats.md, Packed layout): snapshot by
// snapshot, every stream's frame then a checkpoint, so each pack holds one fragment per stream and
// snapshot and a stream's fragments lie between the others' (what a packed database's readers meet).
void write_packed(const Args& a, const panoptes::store::SyntheticOptions& o,
                  const std::function<void(std::int64_t, std::int64_t)>& progress) {
  using namespace panoptes;
  const store::Manifest m = store::synthetic_manifest(o);
  store::WriterOptions w;
  w.overwrite = o.overwrite;
  w.overwrite_option = o.overwrite_option;
  w.layout = store::LayoutChoice::packed;
  store::DatabaseWriter writer = store::DatabaseWriter::create(a.out, m, w);
  Image img(o.width, o.height, 4);
  const std::int64_t streams = m.stream_count();
  for (int f = 0; f < o.frames; ++f) {
    for (int c = 0; c < m.camera_count(); ++c)
      for (int t = 0; t < m.task_count(); ++t) {
        store::draw_synthetic_frame(img, c, t, f);
        writer.append(c, t, img);
      }
    writer.checkpoint();
    if (progress) progress(streams * (f + 1) / o.frames, streams);
    if (const int sig = stop_requested())
      throw Interrupted(sig, a.out + ": stopped by " + signal_name(sig) + " after " + std::to_string(f + 1) + " of " +
                                 std::to_string(o.frames) + " snapshots; the database is marked interrupted");
  }
  writer.finalize();
}

void run(const Args& a, const std::string& command_line) {
  using namespace panoptes;
  const auto size = parse_dims_text(a.size, 2, 6);
  if (!size) throw Error("--size \"" + a.size + "\": expected WIDTHxHEIGHT, e.g. 64x64 or 920x896");
  store::SyntheticOptions o;
  o.cameras = a.cameras;
  o.tasks = a.tasks;
  o.frames = a.frames;
  o.width = (*size)[0];
  o.height = (*size)[1];
  o.overwrite = a.overwrite;
  o.overwrite_option = "--overwrite";
  o.layout = a.layout.empty() ? "auto" : a.layout;
  if (!a.lattice.empty()) {
    const auto l = parse_dims_text(a.lattice, 3, 4);
    if (!l || (*l)[0] < 1 || (*l)[1] < 1 || (*l)[2] < 1)
      throw Error("--lattice \"" + a.lattice + "\": expected NXxNYxNZ with positive counts, e.g. 4x4x3");
    o.lattice = {(*l)[0], (*l)[1], (*l)[2]};
  }
  if (!a.axes.empty()) {
    std::optional<std::vector<int>> counts;
    for (int parts = 1; parts <= 4 && !counts; ++parts) counts = parse_dims_text(a.axes, parts, 5);
    if (!counts || std::any_of(counts->begin(), counts->end(), [](int n) { return n < 1; }))
      throw Error("--axes \"" + a.axes + "\": expected 1 to 4 positive value counts, e.g. 3x2x2");
    o.axes = *counts;
    o.tasks = 1;
    for (int n : o.axes) o.tasks = int(checked_product(o.tasks, n, "--axes (tasks)", 65536));
  }
  o.shells = a.shells;
  o.projection = a.projection;
  o.threads = a.threads;
  o.title = a.title;
  o.command_line = command_line;
  if (!a.layout.empty() && a.layout != "auto" && a.layout != "files" && a.layout != "packed")
    throw Error("--layout \"" + a.layout + "\": expected auto, files or packed");
  const bool packed = a.layout == "packed";
  // The packed writer encodes keyframes only: gop 1 unless asked otherwise (then the writer refuses).
  o.video.gop = packed && !a.gop_given ? 1 : a.gop;
  if (a.crf >= 0) o.video.crf = a.crf;
  if (!a.preset.empty()) o.video.preset = a.preset;
  o.video.validate();
  const long long cameras = o.lattice[0] > 0 ? (long long)o.lattice[0] * o.lattice[1] * o.lattice[2]
                                              : checked_product(a.cameras, a.shells, "--cameras x --shells", 1 << 24);
  const long long streams = checked_product(cameras, o.tasks, "--cameras x --tasks (movies)", INT_MAX);
  if (o.width > 16384 || o.height > 16384)
    throw Error("--size \"" + a.size + "\": expected at most 16384 pixels per side");
  if (!a.force) {
    // Streams are written a few at a time (one encoder each); the manifest and camera table grow
    // with the cameras.
    const double px = double(o.width) * o.height;
    const int parallel = a.threads > 0 ? a.threads : int(std::thread::hardware_concurrency());
    MemoryEstimate e;
    e.add("encoders", std::max(parallel, 1) * (video::open_writer_bytes(px, o.video.gop) +
                                               video::live_encoder_bytes(px) + px * 3));
    e.add("manifest", double(cameras) * 1500 + double(streams) * 16);
    check_memory(e, available_memory(), 1, "this synthetic database", "pass --force");
  }

  const bool tty = ::isatty(STDERR_FILENO);
  const auto t0 = std::chrono::steady_clock::now();
  const auto progress = [&](std::int64_t done, std::int64_t total) {
    if (!tty) return;
    std::fprintf(stderr, "\rsynth-db: %lld / %lld streams (%d%%)", (long long)done, (long long)total,
                 int(total ? 100 * done / total : 100));
    std::fflush(stderr);
  };
  if (packed) {
    write_packed(a, o, progress);
  } else {
    store::write_synthetic_database(a.out, o, progress);
  }
  if (tty) std::fprintf(stderr, "\n");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("wrote %s: %d cameras x %d tasks = %lld streams, %d frames of %dx%d each, in %.2f s (%.0f streams/s)\n",
              a.out.c_str(), int(cameras), o.tasks, streams, a.frames, o.width, o.height, seconds, streams / seconds);
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto args = std::make_shared<Args>();
  auto* sub = root.add_subcommand(
      "synth-db",
      "Write a synthetic movie database: cameras on a sphere, tasks on an 'isovalue' axis, every frame stamped "
      "with a machine-readable (camera, task, frame) code in its top-left corner (for tests and benchmarks)");
  sub->add_option("OUT", args->out, "Output database directory")->required();
  sub->add_option("--cameras", args->cameras, "Number of cameras (Fibonacci sphere, ring navigation graph)")
      ->check(CLI::Range(1, 1 << 24))->capture_default_str();
  sub->add_option("--tasks", args->tasks, "Number of tasks (one 'isovalue' axis)")
      ->check(CLI::Range(1, 1 << 16))->capture_default_str();
  sub->add_option("--frames", args->frames, "Frames per movie")->check(CLI::Range(1, 1 << 20))->capture_default_str();
  sub->add_option("--size", args->size, "Frame size WIDTHxHEIGHT (at least 40x32 for the stamp)")->capture_default_str();
  sub->add_flag("--overwrite", args->overwrite, "Replace an existing database in OUT");
  // Not the video default (1): an intra-only writer opens an x264 encoder per frame, which for tiny
  // frames costs 2.6x the CPU of one encoder per movie (measured: 10 vs 3.8 ms per 64x64 10-frame stream).
  sub->add_option("--gop", args->gop, "Keyframe interval in frames")->check(CLI::Range(1, 100000))->capture_default_str();
  sub->add_option("--crf", args->crf, "x264 constant rate factor 0..51 (default: the video default)");
  sub->add_option("--preset", args->preset, "x264 preset (default: the video default)");
  sub->add_option("--threads", args->threads, "Streams encoded in parallel (0 = all cores)")->capture_default_str();
  sub->add_option("--title", args->title, "Title stored in the manifest")->capture_default_str();
  sub->add_option("--lattice", args->lattice,
                  "Cameras on an NXxNYxNZ lattice inside the domain with world-axis navigation (replaces --cameras)");
  sub->add_option("--shells", args->shells,
                  "Camera shells of the sphere: --cameras on each, 'in'/'out' graph edges between them (not with --lattice)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  sub->add_option("--axes", args->axes,
                  "Parameter axes as value counts, e.g. 3x2x2 (isovalue, opacity, window, blend): one task per "
                  "combination (replaces --tasks)");
  sub->add_option("--projection", args->projection, "Projection recorded in the manifest: perspective or equirectangular")
      ->check(CLI::IsMember({"perspective", "equirectangular"}))
      ->capture_default_str();
  sub->add_option("--layout", args->layout,
                  "auto (packed from 1024 streams at gop 1, the default), files (one movie per stream) or packed "
                  "(packs written snapshot by snapshot, as in situ; gop 1 unless --gop says otherwise); "
                  "docs/formats.md")
      ->check(CLI::IsMember({"auto", "files", "packed"}));
  sub->add_flag("--force", args->force, "Start even when the estimated memory exceeds what is available");
  sub->callback([args, sub] {
    panoptes::install_stop_handlers();
    args->gop_given = sub->get_option("--gop")->count() > 0;
    // The effective settings, so the provenance reproduces the database.
    const std::string command_line = "panoptes synth-db " + args->out + " --cameras " + std::to_string(args->cameras) + " --tasks " +
                   std::to_string(args->tasks) + " --frames " + std::to_string(args->frames) + " --size " + args->size +
                   (args->lattice.empty() ? "" : " --lattice " + args->lattice) +
                   (args->shells == 1 ? "" : " --shells " + std::to_string(args->shells)) +
                   (args->axes.empty() ? "" : " --axes " + args->axes) +
                   (args->projection == "perspective" ? "" : " --projection " + args->projection) +
                   (args->layout.empty() ? "" : " --layout " + args->layout);
    run(*args, command_line);
  });
});

}  // namespace
