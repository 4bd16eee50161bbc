// `panoptes render VOLUME... --rig SPEC --task TASK... --size WxH --out DB`: renders a volume, or a
// time series of volumes, from every camera of a rig for every task, into a movie database. A replay
// through the in-situ pipeline (issue 30): the options become a session configuration (the --task
// shorthand is the TOML [[task]] table it stands for, insitu/task_plan.hpp) and every volume is one
// snapshot of a one-rank insitu::Session, so rig, references, windows and frames are the ones
// `panoptes run`, the C API and Python give for the same configuration.
#include <glob.h>
#include <unistd.h>

#include <chrono>
#include <climits>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <exception>
#include <filesystem>
#include <algorithm>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <omp.h>

#include "app/command.hpp"
#include "app/render_grid.hpp"
#include "app/series_sidecars.hpp"
#include "app/volume_file.hpp"
#include "camera/navigation.hpp"
#include "camera/rig_spec.hpp"
#include "core/dims_text.hpp"
#include "core/error.hpp"
#include "core/stop_request.hpp"
#include "core/file_read.hpp"
#include "core/memory.hpp"
#include "insitu/resources.hpp"
#include "insitu/session.hpp"
#include "insitu/task_plan.hpp"
#include "render/renderer.hpp"
#include "store/database.hpp"
#include "video/writer_memory.hpp"

namespace cmd_render {  // named, not anonymous: the unity build joins the command units

using namespace panoptes;

struct Args {
  std::vector<std::string> inputs;
  std::string rig = "yinyang";
  std::vector<std::string> tasks;
  std::string size = "920x896";
  std::string out;
  bool overwrite = false;
  double sample_distance = 0.5;
  bool adaptive = true;  // pays where images have more pixels than voxels across (docs/rendering.md, Round 4)
  double percentile = 0.999;
  std::string reference = "running";  // the session's default (issue 41: colours keep their value along a movie)
  double reference_value = 0;         // --reference fixed: the physical reference of the field
  bool print_tasks = false;
  std::string spacing, origin, background = "0,0,0";
  bool no_outline = false;
  std::string title;
  int crf = -1;
  bool force = false;
  std::string up_axis;  // "" = the volumes' sidecars say, or z_up
  std::string projection = "perspective";
  bool quiet = false;
  std::string grid_file;  // --grid: a non-uniform grid (app/render_grid.hpp)
};

// Quotes a command-line word for a POSIX shell when it needs it, so the recorded line can be run again.
std::string shell_word(const std::string& w) {
  if (!w.empty() && w.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-+=/.,:@%") ==
                        std::string::npos)
    return w;
  std::string q = "'";
  for (char c : w) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string number_text(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

// The command line recorded in the manifest: every option that changes the pixels, with its value
// (defaults included, so a later change of a default does not change what the line means).
std::string recorded_command_line(const Args& a) {
  std::string cl = "panoptes render";
  for (const auto& i : a.inputs) cl += " " + shell_word(i);
  cl += " --rig " + shell_word(a.rig);
  for (const auto& t : a.tasks) cl += " --task " + shell_word(t);
  cl += " --size " + shell_word(a.size);
  cl += " --sample-distance " + number_text(a.sample_distance);
  cl += a.adaptive ? " --adaptive" : " --no-adaptive";
  cl += " --percentile " + number_text(a.percentile);
  cl += " --reference " + a.reference;
  if (a.reference_value != 0) cl += " --reference-value " + number_text(a.reference_value);
  if (!a.spacing.empty()) cl += " --spacing " + shell_word(a.spacing);
  if (!a.origin.empty()) cl += " --origin " + shell_word(a.origin);
  if (!a.grid_file.empty()) cl += " --grid " + shell_word(a.grid_file);
  cl += " --background " + shell_word(a.background);
  if (a.no_outline) cl += " --no-outline";
  if (a.crf >= 0) cl += " --crf " + std::to_string(a.crf);
  cl += " --up-axis " + a.up_axis;
  if (a.projection != "perspective") cl += " --projection " + a.projection;
  if (!a.title.empty()) cl += " --title " + shell_word(a.title);
  cl += " --out " + shell_word(a.out);
  return cl;
}

// An all-NaN (or all-infinite) volume renders as empty frames: say so rather than write them silently.
void warn_if_not_finite(const std::string& file, const std::vector<float>& values) {
  std::size_t finite = 0;
  for (float v : values) finite += std::isfinite(v) ? 1 : 0;
  if (finite == 0 && !values.empty())
    std::fprintf(stderr, "panoptes: warning: %s: none of its %zu values is a finite number (all NaN or infinite); "
                 "its frames will be empty\n", file.c_str(), values.size());
  else if (finite < values.size())
    std::fprintf(stderr, "panoptes: warning: %s: %zu of %zu values are NaN or infinite; they are rendered as empty\n",
                 file.c_str(), values.size() - finite, values.size());
}

std::vector<double> parse_numbers(const std::string& text, std::size_t count, const std::string& option) {
  std::vector<double> v;
  std::string s = text;
  std::replace(s.begin(), s.end(), ',', ' ');
  std::istringstream ss(s);
  double x;
  while (ss >> x) v.push_back(x);
  if (v.size() != count || !ss.eof())
    throw Error(option + " \"" + text + "\": expected " + std::to_string(count) + " comma-separated numbers");
  return v;
}

// Expands globs; a plain path is kept as is (a missing file is reported by the reader).
std::vector<std::string> expand_inputs(const std::vector<std::string>& inputs) {
  std::vector<std::string> files;
  for (const std::string& in : inputs) {
    if (in.find_first_of("*?[") == std::string::npos) {
      files.push_back(in);
      continue;
    }
    glob_t g{};
    const int rc = ::glob(in.c_str(), 0, nullptr, &g);
    if (rc == GLOB_NOMATCH) {
      globfree(&g);
      throw FileError(in, "the pattern matches no file");
    }
    std::vector<std::string> matched(g.gl_pathv, g.gl_pathv + g.gl_pathc);  // sorted by glob()
    globfree(&g);
    // A pattern such as 'snapshots/phi_p_*' also matches the volumes' sidecars (phi_p_000020.json beside
    // phi_p_000020.npy): they describe volumes, they are not volumes.
    for (const std::string& m : matched) {
      const std::filesystem::path p(m);
      const bool sidecar = p.extension() == ".json" &&
                           std::find(matched.begin(), matched.end(), std::filesystem::path(p).replace_extension(".npy").string()) !=
                               matched.end();
      if (!sidecar) files.push_back(m);
    }
  }
  return files;
}

// A bar on a terminal; otherwise (logs, pipes) one line per tenth of the work.
void progress(bool tty, long long done, long long total, double elapsed) {
  if (!tty) {
    static long long last_tenth = -1;
    const long long tenth = total ? 10 * done / total : 10;
    if (tenth == last_tenth) return;
    last_tenth = tenth;
    const double eta = done ? elapsed * double(total - done) / double(done) : 0;
    std::fprintf(stderr, "render: %lld/%lld images (%d%%), %.0f s elapsed, ETA %.0f s\n", done, total,
                 int(total ? 100 * done / total : 100), elapsed, eta);
    return;
  }
  const int width = 30;
  const int filled = total ? int(width * done / total) : width;
  const double eta = done ? elapsed * double(total - done) / double(done) : 0;
  std::fprintf(stderr, "\rrender: [%.*s%*s] %lld/%lld images  %3d%%  ETA %4.0f s ", filled,
               "##############################", width - filled, "", done, total, int(total ? 100 * done / total : 100), eta);
  std::fflush(stderr);
}

// The session configuration `render`'s options stand for (the grid comes from the first volume).
insitu::SessionConfig session_config(const Args& a, const std::string& first_file, const std::string& command_line,
                                     const std::string& field = "volume") {
  const auto size = parse_dims_text(a.size, 2, 5);
  if (!size) throw Error("--size \"" + a.size + "\": expected WIDTHxHEIGHT, e.g. 920x896");
  insitu::SessionConfig cfg;
  cfg.width = (*size)[0];
  cfg.height = (*size)[1];
  if (cfg.width < 2 || cfg.height < 2 || cfg.width > insitu::kMaxImageSide || cfg.height > insitu::kMaxImageSide)
    throw Error("--size \"" + a.size + "\": expected 2.." + std::to_string(insitu::kMaxImageSide) + " pixels per side");
  const auto bg = parse_numbers(a.background, 3, "--background");
  for (double c : bg)
    if (!(c >= 0 && c <= 1)) throw Error("--background \"" + a.background + "\": expected three values in [0, 1]");
  cfg.background = {float(bg[0]), float(bg[1]), float(bg[2])};
  cfg.outline = !a.no_outline;
  cfg.output_dir = a.out;
  cfg.mode = a.overwrite ? insitu::OutputMode::overwrite : insitu::OutputMode::create;
  cfg.keep_interrupted = false;  // --overwrite is asked for on the command line
  cfg.title = a.title.empty() ? "panoptes render " + first_file : a.title;
  cfg.program = "panoptes render";
  cfg.existing_database_advice = "add --overwrite to replace it, or give another --out";
  cfg.command_line = command_line;
  cfg.rig = a.rig;
  (void)camera::RigSpec::parse(a.rig);  // a bad --rig is reported before any volume is read
  cfg.up_axis = a.up_axis.empty() ? "z_up" : a.up_axis;
  cfg.projection = a.projection;
  cfg.tasks = insitu::tasks_from_shorthand(a.tasks.empty() ? std::vector<std::string>{"volume:hot"} : a.tasks, field);
  cfg.schedule.every_steps = 1;  // every volume is a snapshot
  if (a.crf > 51) throw Error("--crf " + std::to_string(a.crf) + ": expected an x264 quality 0..51");
  if (a.crf >= 0) cfg.video.crf = a.crf;
  cfg.render.sample_distance = a.sample_distance;
  cfg.render.adaptive = a.adaptive;
  cfg.render.equirect_adaptive = a.adaptive;  // --no-adaptive marches every pixel of 360° frames too
  cfg.percentile = a.percentile;
  const insitu::ReferenceMode mode = insitu::parse_reference_mode(a.reference, "--reference");
  if (mode == insitu::ReferenceMode::fixed) {
    if (!(a.reference_value > 0)) throw Error("--reference fixed: give the field's physical reference with --reference-value V (> 0)");
    for (const insitu::TaskConfig& t : cfg.tasks)
      for (const std::string& f : t.fields) cfg.field_scales[f] = {mode, a.reference_value};
  } else {
    if (a.reference_value != 0) throw Error("--reference-value is the value of --reference fixed (the reference is " + a.reference + ")");
    cfg.reference = mode;
  }
  cfg.check_memory = !a.force;
  cfg.validate();
  return cfg;
}

// What the volumes' sidecars say (issue 41) against the options: an option that contradicts a sidecar is
// an error (which of the two is right cannot be told), an option the sidecars leave open is used. Returns
// the options with the up axis resolved (the recorded command line shows the one rendered).
Args resolve_with_sidecars(const Args& a, const app::SeriesSidecars& series) {
  Args r = a;
  if (!series.present()) {
    if (r.up_axis.empty()) r.up_axis = "z_up";
    return r;
  }
  const FieldSidecar& s = series.first();
  if (!a.grid_file.empty())
    throw FileError(series.paths.front(), "describes a volume on a uniform grid, but --grid \"" + a.grid_file +
                                              "\" says the volumes hold the points of a non-uniform grid; leave out one of the two");
  if (!a.up_axis.empty() && a.up_axis != s.up_axis)
    throw FileError(series.paths.front(), "up_axis: \"" + s.up_axis + "\" contradicts --up-axis " + a.up_axis +
                                              "; leave --up-axis out (the sidecar says which way is up) or correct the sidecar");
  r.up_axis = s.up_axis;
  auto check = [&](const std::string& option, const std::string& text, const std::string& key, const Vec3& recorded) {
    if (text.empty()) return;
    const auto v = parse_numbers(text, 3, option);
    if (!app::series_detail::same(Vec3(v[0], v[1], v[2]), recorded))
      throw FileError(series.paths.front(), key + ": " + app::series_detail::vec_text(recorded) + " contradicts " + option + " " +
                                                text + "; leave " + option + " out (the sidecar gives it) or correct the sidecar");
  };
  check("--spacing", a.spacing, "spacing", s.spacing);
  if (s.origin) check("--origin", a.origin, "origin", *s.origin);
  return r;
}

void run(const Args& args) {
  if (args.print_tasks) {
    for (const insitu::TaskConfig& t :
         insitu::tasks_from_shorthand(args.tasks.empty() ? std::vector<std::string>{"volume:hot"} : args.tasks, "volume"))
      std::printf("%s\n", insitu::task_table_toml(t).c_str());
    return;
  }
  const std::vector<std::string> files = expand_inputs(args.inputs);
  if (files.empty()) throw Error("no input volume given");
  // Sidecars (<volume>.json beside a .npy, written by `panoptes seismic`): grid, units, time, up axis.
  const app::SeriesSidecars series = app::read_series_sidecars(files);
  const Args a = resolve_with_sidecars(args, series);
  const std::string field = series.present() && !series.first().field.empty() ? series.first().field : "volume";
  insitu::SessionConfig cfg = session_config(a, files[0], recorded_command_line(a), field);
  if (series.present()) {
    const FieldSidecar& s = series.first();
    cfg.units = s.length_units;
    if (series.times()) cfg.time_units = s.time_units;
    if (!s.field_units.empty()) cfg.field_units[field] = s.field_units;
  }
  if (!a.force) {
    // Reading a volume holds its bytes and its float values at once: refuse before, not with bad_alloc.
    MemoryEstimate read;
    read.add("volume file", double(regular_file_size(files[0], UINT64_MAX, "volume file")) * 2);
    check_memory(read, available_memory(), 1, "reading " + files[0], "pass --force");
  }

  // --grid: the volumes hold values at the points of a non-uniform grid, resampled by the in-situ grid
  // stage onto a uniform grid over its bounding box (one process: every patch is one whole block).
  std::optional<app::RenderGrid> source;
  if (!a.grid_file.empty()) {
    if (!a.spacing.empty() || !a.origin.empty())
      throw Error("--grid places the points itself; --spacing and --origin are for uniform volumes");
    source = app::read_render_grid(a.grid_file);
  }
  // The first volume fixes the grid of the whole series.
  app::Volume first = source ? app::Volume{} : app::read_volume(files[0]);
  render::GridGeometry grid = source ? insitu::GridAdapter::cover(source->source, source->resample)
                                     : render::GridGeometry{first.dims, first.origin, first.spacing};
  if (series.present()) {
    app::check_volume_against_sidecar(files[0], first, series.first(), series.paths.front());
    grid.spacing = series.first().spacing;
    if (series.first().origin) grid.origin = *series.first().origin;
  }
  if (!a.spacing.empty()) {
    const auto s = parse_numbers(a.spacing, 3, "--spacing");
    grid.spacing = {s[0], s[1], s[2]};
  }
  if (!a.origin.empty()) {
    const auto o = parse_numbers(a.origin, 3, "--origin");
    grid.origin = {o[0], o[1], o[2]};
  }
  grid.validate();
  if (!a.force) {
    // The session's own estimate, worded for this command (it would say [resources] check_memory).
    const double points = double(grid.dims[0]) * grid.dims[1] * grid.dims[2];
    MemoryEstimate e = insitu::estimate_session_memory(cfg, points, insitu::rig_camera_count(cfg, grid), 1,
                                                       omp_get_max_threads());
    if (!source) e.add("volumes read", points * 4 * (files.size() > 1 ? 2 : 1));
    if (source) {  // the grid stage, and each source volume read whole (2x: its bytes and its floats)
      const double source_points = double(source->source.points_per_patch()) * source->source.patches();
      e.add(insitu::estimate_grid_stage_memory(source_points, points, 1, 1));
      e.add("source volumes read", source_points * 8 * (files.size() > 1 ? 2 : 1));
    }
    check_memory(e, available_memory(), 1, "this render", "pass --force");
    cfg.check_memory = false;
  }

  // A source grid: the session's grid stage resamples it (every patch is one whole block here).
  std::vector<insitu::GridBlock> blocks;
  if (source)
    for (int p = 0; p < source->source.patches(); ++p) blocks.push_back(insitu::GridBlock::whole(source->source, p));
  insitu::Session session = source ? insitu::Session(cfg, source->source, blocks, source->resample)
                                   : insitu::Session(cfg, grid, insitu::LocalBlock::whole(grid));
  const bool tty = ::isatty(STDERR_FILENO) && !a.quiet;
  const long long total = (long long)files.size() * session.camera_count() * (long long)session.task_count();
  long long done = 0;
  const auto t0 = std::chrono::steady_clock::now();
  if (!a.quiet)
    session.set_frame_observer([&](int, int, int, const Image&) {
      progress(tty, ++done, total, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    });
  // Snapshot f at the time its sidecar records, or at time f.
  const std::vector<double> times = series.times().value_or(std::vector<double>{});
  auto time_of = [&](std::size_t f) { return times.empty() ? double(f) : times[f]; };
  for (std::size_t f = 0; f < files.size(); ++f) {
    if (source) {
      const std::vector<float> values = app::read_grid_volume(files[f], source->source);
      warn_if_not_finite(files[f], values);
      std::vector<insitu::FieldInput> patches;
      for (int p = 0; p < source->source.patches(); ++p)
        patches.push_back({field, values.data() + p * source->source.points_per_patch(), insitu::ScalarType::f32, {0, 0, 0}});
      session.snapshot(time_of(f), patches);
      continue;
    }
    app::Volume vol = f == 0 ? std::move(first) : app::read_volume(files[f]);
    warn_if_not_finite(files[f], vol.values);
    if (series.present()) app::check_volume_against_sidecar(files[f], vol, series.sidecars[f], series.paths[f]);
    if (vol.dims != grid.dims)
      throw FileError(files[f], "volume of " + std::to_string(vol.dims[0]) + "x" + std::to_string(vol.dims[1]) + "x" +
                                    std::to_string(vol.dims[2]) + " points; expected " + std::to_string(grid.dims[0]) + "x" +
                                    std::to_string(grid.dims[1]) + "x" + std::to_string(grid.dims[2]) + " like " + files[0]);
    // A stop request (SIGINT/SIGTERM) throws Interrupted before the next snapshot and the database keeps
    // the snapshots taken, marked interrupted.
    session.snapshot(time_of(f), {{field, vol.values.data(), insitu::ScalarType::f32, {0, 0, 0}}});
  }
  if (const int sig = stop_requested()) {
    if (tty) std::fprintf(stderr, "\n");
    throw Interrupted(sig, a.out + ": stopped by " + signal_name(sig) + "; " + std::to_string(session.snapshots()) +
                               " complete snapshot(s) kept, the database is marked interrupted");
  }
  session.finalize();
  if (tty) std::fprintf(stderr, "\n");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("wrote %s: %d cameras x %d tasks = %lld streams, %zu frames of %dx%d, in %.1f s\n", a.out.c_str(),
              session.camera_count(), session.task_count(), (long long)session.camera_count() * session.task_count(),
              files.size(), cfg.width, cfg.height, seconds);
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto args = std::make_shared<Args>();
  auto* sub = root.add_subcommand(
      "render",
      "Render a volume (or a time series of volumes) from every camera of a rig for every task into a movie "
      "database. Inputs: NumPy .npy (3-D float32/float64; C order = shape (nz, ny, nx)) or VTK legacy "
      "STRUCTURED_POINTS .vtk (ASCII or BINARY); several files or a quoted glob make a time series. A .npy's sidecar "
      "(the same name with .json, as `panoptes seismic` writes: grid, units, time, up axis) is read when present.");
  sub->add_option("VOLUME", args->inputs, "Volume file(s) or glob pattern(s), one frame each, in order (required)");
  sub->add_option("--rig", args->rig,
                  "Camera rig: yinyang[:NTxNP], latlon[:NLATxNLON[+poles]], fibonacci[:N], file:PATH; "
                  "optional @R1,R2,... shell radii in bounding-sphere radii; or cameras inside the volume: "
                  "lattice:NXxNYxNZ[@MARGIN] (lattice nodes, walk along world axes) or path:FILE (x y z per line)")
      ->capture_default_str();
  sub->add_option("--task", args->tasks,
                  "Visualization task (repeatable): " + insitu::task_shorthand_syntax() + "; "
                  "shorthand for the TOML [[task]] tables of `panoptes run` (--print-tasks shows them; several iso: "
                  "form one isovalue sweep). Presets: p-wave, s-wave, diverging, grayscale, hot, rainbow. Without "
                  "LO:HI the window is relative to the --reference (default task: volume:hot)")
      ->allow_extra_args(false);
  sub->add_option("--size", args->size, "Image size WIDTHxHEIGHT")->capture_default_str();
  sub->add_option("--out", args->out, "Output database directory (required)");
  sub->add_flag("--overwrite", args->overwrite, "Replace an existing database in --out");
  sub->add_option("--sample-distance", args->sample_distance, "Ray sample distance in voxels")
      ->check(CLI::Range(0.01, 16.0))->capture_default_str();
  sub->add_flag("--adaptive,!--no-adaptive", args->adaptive,
                "Adaptive image-space sampling: march every 4th pixel and interpolate where the image is smooth "
                "(default: on; 360° frames are sampled on the sphere: a lattice about 1.5° apart whose columns "
                "widen toward the poles; --no-adaptive marches every pixel of every frame)");
  sub->add_option("--percentile", args->percentile,
                  "Reference for relative windows: this quantile of |v| (sampled as in situ: a lattice of about "
                  "65,536 points, at least 0.001 x the maximum)")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  sub->add_option("--reference", args->reference,
                  "What relative windows are multiples of: running (the largest quantile so far: a colour keeps its "
                  "value along the movie, decaying waves darken; as `panoptes run`'s default), snapshot (each "
                  "volume's own quantile: every frame fills its window) or fixed (--reference-value V, a physical "
                  "value in the field's units)")
      ->check(CLI::IsMember({"snapshot", "running", "running-max", "fixed"}))
      ->capture_default_str();
  sub->add_option("--reference-value", args->reference_value,
                  "With --reference fixed: the reference in the field's units (relative windows are multiples of it)");
  sub->add_flag("--print-tasks", args->print_tasks,
                "Print the TOML [[task]] tables the --task options stand for (as `panoptes run` reads them) and exit");
  sub->add_option("--spacing", args->spacing,
                  "Grid spacing sx,sy,sz (default: from the file or its sidecar, or 1,1,1; must agree with a sidecar)");
  sub->add_option("--origin", args->origin,
                  "Grid origin x,y,z (default: from the file or its sidecar, or 0,0,0; must agree with a sidecar)");
  sub->add_option("--grid", args->grid_file,
                  "TOML file of a non-uniform grid: [grid] kind = rectilinear (x, y, z) | spherical | yinyang (r, theta, "
                  "phi), each key a 1-D .npy of coordinates (relative to the file), optional points (longest axis of "
                  "the uniform grid rendered) and outside (value outside the domain). The volumes are .npy of the "
                  "grid's points, shape (n2, n1, n0) (Yin-Yang: (2, n2, n1, n0), Yin then Yang); they are resampled as "
                  "in situ (docs/instrumenting.md, Grids)");
  sub->add_option("--background", args->background, "Background colour r,g,b in [0, 1]")->capture_default_str();
  sub->add_flag("--no-outline", args->no_outline, "Do not draw the domain's outline box");
  sub->add_option("--title", args->title, "Title stored in the manifest");
  sub->add_option("--crf", args->crf, "x264 quality 0..51 (default: the video default)");
  sub->add_flag("--force", args->force, "Start even when the estimated memory exceeds what is available");
  sub->add_option("--up-axis", args->up_axis,
                  "Which way is up in the volume: z_up, or z_down (z is depth, as in seismology); the rig's poles, "
                  "latitudes, the images' up and the player's Up key follow it. Default: what the volumes' sidecars "
                  "say (an error if they say otherwise), else z_up")
      ->check(CLI::IsMember({"z_up", "z_down"}));
  sub->add_option("--projection", args->projection,
                  "perspective, or equirectangular: 360x180-degree frames (use a 2:1 --size, e.g. 1920x960) that the "
                  "player looks around in; no outline box is drawn then")
      ->check(CLI::IsMember({"perspective", "equirectangular"}))
      ->capture_default_str();
  sub->add_flag("-q,--quiet", args->quiet, "No progress output");
  sub->callback([args] {
    install_stop_handlers();
    if (!args->print_tasks && args->inputs.empty()) throw Error("render: VOLUME is required (a volume file or a glob)");
    if (!args->print_tasks && args->out.empty()) throw Error("render: --out is required (the database directory)");
    run(*args);
  });
});

}  // namespace
