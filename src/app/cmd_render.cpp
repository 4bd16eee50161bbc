// `panoptes render VOLUME... --rig SPEC --task TASK... --size WxH --out DB`: renders a volume, or a
// time series of volumes, from every camera of a rig for every task, into a movie database.
#include <glob.h>
#include <unistd.h>

#include <chrono>
#include <climits>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <exception>
#include <algorithm>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <omp.h>

#include "app/command.hpp"
#include "app/volume_file.hpp"
#include "camera/navigation.hpp"
#include "camera/rig_spec.hpp"
#include "core/error.hpp"
#include "core/stop_request.hpp"
#include "core/file_read.hpp"
#include "core/memory.hpp"
#include "render/renderer.hpp"
#include "store/database.hpp"
#include "core/version.hpp"
#include "video/writer_memory.hpp"

namespace {

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
  std::string spacing, origin, background = "0,0,0";
  bool no_outline = false;
  std::string title;
  int crf = -1;
  bool force = false;
  std::string up_axis = "z_up";
  std::string projection = "perspective";
  bool quiet = false;
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
  if (!a.spacing.empty()) cl += " --spacing " + shell_word(a.spacing);
  if (!a.origin.empty()) cl += " --origin " + shell_word(a.origin);
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
    for (std::size_t i = 0; i < g.gl_pathc; ++i) files.push_back(g.gl_pathv[i]);  // sorted by glob()
    globfree(&g);
  }
  return files;
}

// A task given on the command line, with what the manifest records about it.
struct CliTask {
  render::TaskSpec spec;
  bool relative = false;  // window resolved against the running reference each snapshot
  store::TaskEntry entry;
};

// Syntax: volume:PRESET[:LO:HI] | iso:VALUE | slice:x|y|z:FRACTION[:PRESET[:LO:HI]].
CliTask parse_task(const std::string& text, const render::GridGeometry& grid) {
  std::vector<std::string> parts;
  std::size_t b = 0;
  while (true) {
    const auto e = text.find(':', b);
    parts.push_back(text.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (e == std::string::npos) break;
    b = e + 1;
  }
  auto number = [&](const std::string& s) {
    try {
      std::size_t used = 0;
      const double v = std::stod(s, &used);
      if (used != s.size() || !std::isfinite(v)) throw std::invalid_argument("");
      return v;
    } catch (const std::exception&) {
      throw Error("--task \"" + text + "\": \"" + s + "\" is not a number");
    }
  };
  const std::string usage = "; expected volume:PRESET[:LO:HI], iso:VALUE or slice:x|y|z:FRACTION[:PRESET[:LO:HI]]";
  CliTask t;
  t.entry.name = text;
  t.entry.fields = {"volume"};
  if (parts[0] == "volume" && (parts.size() == 2 || parts.size() == 4)) {
    const auto tf = render::TransferFunction::preset(parts[1]);
    // Relative default: [0, ref] (|v| for the wave presets), [−ref, ref] for the diverging map.
    render::ValueWindow w = render::ValueWindow::relative_to(parts[1] == "diverging" ? -1 : 0, 1);
    t.relative = parts.size() == 2;
    if (!t.relative) w = render::ValueWindow::absolute(number(parts[2]), number(parts[3])).resolve(0);
    t.spec = render::TaskSpec::volume(0, tf, w);
    t.entry.method = "volume";
    t.entry.parameters = {{"preset", parts[1]}, {"window", t.relative ? "relative" : "absolute"}};
    if (!t.relative) t.entry.parameters["range"] = {w.lo, w.hi};
  } else if (parts[0] == "iso" && parts.size() == 2) {
    const double v = number(parts[1]);
    t.spec = render::TaskSpec::isosurface(0, float(v));
    t.entry.method = "isosurface";
    t.entry.parameters = {{"isovalue", v}};
  } else if (parts[0] == "slice" && (parts.size() == 3 || parts.size() == 4 || parts.size() == 6)) {
    const std::string axes = "xyz";
    if (parts[1].size() != 1 || axes.find(parts[1][0]) == std::string::npos)
      throw Error("--task \"" + text + "\": slice axis \"" + parts[1] + "\"; expected x, y or z");
    const int axis = int(axes.find(parts[1][0]));
    const double f = number(parts[2]);
    if (!(f >= 0 && f <= 1)) throw Error("--task \"" + text + "\": slice position " + parts[2] + "; expected a fraction in [0, 1]");
    const std::string preset = parts.size() >= 4 ? parts[3] : "diverging";
    render::ValueWindow w = render::ValueWindow::relative_to(-1, 1);
    t.relative = parts.size() < 6;
    if (!t.relative) w = render::ValueWindow::absolute(number(parts[4]), number(parts[5])).resolve(0);
    const double pos = grid.origin[axis] + f * (grid.dims[axis] - 1) * grid.spacing[axis];
    t.spec = render::TaskSpec::slice(0, axis, pos, render::TransferFunction::preset(preset), w);
    t.entry.method = "slice";
    t.entry.parameters = {{"axis", parts[1]}, {"fraction", f}, {"position", pos}, {"preset", preset},
                          {"window", t.relative ? "relative" : "absolute"}};
  } else {
    throw Error("--task \"" + text + "\"" + usage);
  }
  return t;
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

void run(const Args& a, const std::string& command_line) {
  std::smatch m;
  static const std::regex size_re(R"((\d{1,5})x(\d{1,5}))");
  if (!std::regex_match(a.size, m, size_re))
    throw Error("--size \"" + a.size + "\": expected WIDTHxHEIGHT, e.g. 920x896");
  const int width = std::stoi(m[1]), height = std::stoi(m[2]);
  if (width < 2 || height < 2 || width > 16384 || height > 16384)
    throw Error("--size \"" + a.size + "\": expected 2..16384 pixels per side");
  const std::vector<std::string> files = expand_inputs(a.inputs);
  if (files.empty()) throw Error("no input volume given");
  const MemoryLimit available = available_memory();
  if (!a.force) {
    // Reading a volume holds its bytes and its float values at once: refuse before, not with bad_alloc.
    MemoryEstimate read;
    read.add("volume file", double(regular_file_size(files[0], UINT64_MAX, "volume file")) * 2);
    check_memory(read, available, 1, "reading " + files[0], "pass --force");
  }

  // The first volume fixes the grid of the whole series.
  app::Volume first = app::read_volume(files[0]);
  render::GridGeometry grid{first.dims, first.origin, first.spacing};
  if (!a.spacing.empty()) {
    const auto s = parse_numbers(a.spacing, 3, "--spacing");
    grid.spacing = {s[0], s[1], s[2]};
  }
  if (!a.origin.empty()) {
    const auto o = parse_numbers(a.origin, 3, "--origin");
    grid.origin = {o[0], o[1], o[2]};
  }
  grid.validate();
  const auto bg = parse_numbers(a.background, 3, "--background");
  for (double c : bg)
    if (!(c >= 0 && c <= 1)) throw Error("--background \"" + a.background + "\": expected three values in [0, 1]");

  std::vector<CliTask> tasks;
  for (const std::string& t : (a.tasks.empty() ? std::vector<std::string>{"volume:hot"} : a.tasks))
    tasks.push_back(parse_task(t, grid));

  const camera::Domain domain{grid.domain_lo(), grid.domain_hi() - grid.domain_lo()};
  camera::RigSpec rig_spec = camera::RigSpec::parse(a.rig);
  rig_spec.up_axis = camera::parse_up_axis(a.up_axis);
  const camera::Rig rig = camera::make_rig(rig_spec, domain);
  const camera::NavigationGraph graph = camera::build_navigation_graph(rig);

  store::Manifest man;
  man.title = a.title.empty() ? "panoptes render " + files[0] : a.title;
  man.provenance.program = "panoptes render";
  man.provenance.version = panoptes::kVersion;
  man.provenance.command_line = command_line;
  man.domain.dims = {grid.dims[0], grid.dims[1], grid.dims[2]};
  man.domain.origin = grid.origin;
  man.domain.spacing = grid.spacing;
  man.domain.up_axis = a.up_axis;
  man.image.width = width;
  man.image.height = height;
  if (a.crf >= 0) man.video.crf = a.crf;
  man.rig.kind = rig.spec;
  man.rig.parameters = {{"spec", rig.spec}, {"shells", rig.shell_count}};
  // Additive (issue 14): players read the projection and the lattice shape from here; older readers ignore them.
  const camera::Projection projection = camera::parse_projection(a.projection);
  if (projection != camera::Projection::perspective) man.rig.parameters["projection"] = a.projection;
  if (rig.is_lattice()) man.rig.parameters["lattice"] = rig.lattice;
  if (rig.path) man.rig.parameters["path"] = true;
  std::vector<camera::Camera> cams;
  for (int c = 0; c < rig.size(); ++c) {
    const camera::RigCamera& rc = rig.cameras[std::size_t(c)];
    cams.push_back(rig.camera(c, width, height, projection));
    store::CameraEntry e;
    e.id = c;
    e.position = rc.position;
    e.look_at = rc.look_at;
    e.up = rc.up;
    e.fov_y_deg = cams.back().fov_y_degrees();
    e.labels.patch = rc.patch;
    e.labels.lat_deg = rc.latitude_deg;
    e.labels.lon_deg = rc.longitude_deg;
    e.labels.shell = rc.shell;
    man.cameras.push_back(e);
    const camera::Neighbours& n = graph.neighbours[std::size_t(c)];
    man.graph.neighbours.push_back({n.left, n.right, n.up, n.down, n.in, n.out});
  }
  // Several isosurfaces form an "isovalue" axis, so the player can step the isovalue.
  std::vector<double> isovalues;
  for (const CliTask& t : tasks)
    if (t.spec.kind == render::TaskKind::isosurface) isovalues.push_back(t.spec.isovalue);
  if (isovalues.size() >= 2) man.axes.push_back({"isovalue", isovalues, ""});
  int iso_index = 0;
  for (std::size_t i = 0; i < tasks.size(); ++i) {
    tasks[i].entry.id = int(i);
    if (man.find_task(tasks[i].entry.name) >= 0) throw Error("--task \"" + tasks[i].entry.name + "\" is given twice");
    if (isovalues.size() >= 2 && tasks[i].spec.kind == render::TaskKind::isosurface)
      tasks[i].entry.axes = {{"isovalue", iso_index++}};
    man.tasks.push_back(tasks[i].entry);
  }

  const long long streams = checked_product(rig.size(), (long long)tasks.size(), "cameras x tasks (movies)", INT_MAX);
  if (const long long files_limit = open_file_limit(); files_limit >= 0 && streams > files_limit - 64)
    throw Error(std::to_string(rig.size()) + " cameras x " + std::to_string(tasks.size()) + " tasks = " +
                std::to_string(streams) + " movies open at once, but the open-file limit (ulimit -n) is " +
                std::to_string(files_limit) + "; use fewer cameras or tasks, or raise the limit");
  if (!a.force) {
    const double px = double(width) * height, points = double(grid.dims[0]) * grid.dims[1] * grid.dims[2];
    MemoryEstimate e;
    e.add("volumes", points * 4 * (files.size() > 1 ? 2 : 1) + points);  // first + current, macro-cells
    e.add("images", double(tasks.size()) * px * (20 + 8 * 3) + omp_get_max_threads() * video::live_encoder_bytes(px));
    e.add("open movie writers", double(streams) * video::open_writer_bytes(px, man.video.gop));
    e.add("rig and manifest", rig.size() * 1500.0);
    check_memory(e, available, 1, "this render", "pass --force");
  }
  store::DatabaseWriter writer = store::DatabaseWriter::create(a.out, man, a.overwrite);
  const bool tty = ::isatty(STDERR_FILENO) && !a.quiet;
  const bool show_progress = !a.quiet;
  const long long total = (long long)files.size() * rig.size() * (long long)tasks.size();
  long long done = 0;
  const auto t0 = std::chrono::steady_clock::now();
  render::RenderOptions opt;
  opt.sample_distance = a.sample_distance;
  opt.adaptive = a.adaptive;
  render::OutlineStyle outline;
  outline.enabled = !a.no_outline && projection == camera::Projection::perspective;  // box edges curve in 360° frames
  const render::Rgb background{float(bg[0]), float(bg[1]), float(bg[2])};
  render::RunningMax reference;
  std::vector<render::PartialImage> partials(tasks.size());
  std::vector<render::TaskSpec> specs(tasks.size());
  std::vector<Image> frames(std::size_t(8) * tasks.size());

  for (std::size_t f = 0; f < files.size(); ++f) {
    app::Volume vol = f == 0 ? std::move(first) : app::read_volume(files[f]);
    warn_if_not_finite(files[f], vol.values);
    if (vol.dims != grid.dims)
      throw FileError(files[f], "volume of " + std::to_string(vol.dims[0]) + "x" + std::to_string(vol.dims[1]) + "x" +
                                    std::to_string(vol.dims[2]) + " points; expected " + std::to_string(grid.dims[0]) + "x" +
                                    std::to_string(grid.dims[1]) + "x" + std::to_string(grid.dims[2]) + " like " + files[0]);
    const render::FieldView view = render::FieldView::whole(grid, vol.values.data());
    const std::vector<render::PreparedField> fields{render::PreparedField(view)};
    // Relative windows follow a running maximum of a high percentile of |v| over the series: the
    // window only widens, so colours stay comparable along each movie.
    const double ref = reference.update(render::abs_percentile(view, a.percentile));
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      specs[i] = tasks[i].spec;
      if (tasks[i].relative) specs[i].reference = std::max(ref, 1e-30);
    }
    // Cameras in batches: render each camera (multi-threaded inside), then encode the batch's
    // frames in parallel — each goes to its own stream, and one x264 encoder uses one thread.
    const int batch = 8;
    int c0 = 0;
    for (; c0 < rig.size() && !stop_requested(); c0 += batch) {
      const int c1 = std::min(rig.size(), c0 + batch);
      for (int c = c0; c < c1; ++c) {
        render::render_brick(cams[std::size_t(c)], fields, specs, partials, opt);
        for (std::size_t i = 0; i < tasks.size(); ++i)
          frames[std::size_t(c - c0) * tasks.size() + i] =
              render::finish_image(partials[i], cams[std::size_t(c)], grid, background, outline);
      }
      const int n = (c1 - c0) * int(tasks.size());
      std::exception_ptr error;
#pragma omp parallel for schedule(dynamic, 1)
      for (int j = 0; j < n; ++j) {
        try {
          writer.append(c0 + j / int(tasks.size()), j % int(tasks.size()), frames[std::size_t(j)]);
        } catch (...) {
#pragma omp critical(render_append_error)
          if (!error) error = std::current_exception();
        }
      }
      if (error) std::rethrow_exception(error);
      done += n;
      if (show_progress) progress(tty, done, total, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    if (c0 >= rig.size()) {  // a snapshot cut short by a signal is abandoned: the manifest keeps the last one
      writer.set_time(int(f), double(f));
      writer.checkpoint();
    }
    if (const int sig = stop_requested()) {
      if (tty) std::fprintf(stderr, "\n");
      throw Interrupted(sig, a.out + ": stopped by " + signal_name(sig) + "; " + std::to_string(writer.complete_frames()) +
                                 " complete snapshot(s) kept, the database is marked interrupted");
    }
  }
  writer.finalize();
  if (tty) std::fprintf(stderr, "\n");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("wrote %s: %d cameras x %zu tasks = %lld streams, %zu frames of %dx%d, in %.1f s\n", a.out.c_str(), rig.size(),
              tasks.size(), (long long)rig.size() * (long long)tasks.size(), files.size(), width, height, seconds);
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto args = std::make_shared<Args>();
  auto* sub = root.add_subcommand(
      "render",
      "Render a volume (or a time series of volumes) from every camera of a rig for every task into a movie "
      "database. Inputs: NumPy .npy (3-D float32/float64; C order = shape (nz, ny, nx)) or VTK legacy "
      "STRUCTURED_POINTS .vtk (ASCII or BINARY); several files or a quoted glob make a time series.");
  sub->add_option("VOLUME", args->inputs, "Volume file(s) or glob pattern(s), one frame each, in order")->required();
  sub->add_option("--rig", args->rig,
                  "Camera rig: yinyang[:NTxNP], latlon[:NLATxNLON[+poles]], fibonacci[:N], file:PATH; "
                  "optional @R1,R2,... shell radii in bounding-sphere radii; or cameras inside the volume: "
                  "lattice:NXxNYxNZ[@MARGIN] (lattice nodes, walk along world axes) or path:FILE (x y z per line)")
      ->capture_default_str();
  sub->add_option("--task", args->tasks,
                  "Visualization task (repeatable): volume:PRESET[:LO:HI], iso:VALUE, slice:x|y|z:FRACTION[:PRESET[:LO:HI]]. "
                  "Presets: p-wave, s-wave, diverging, grayscale, hot, rainbow. Without LO:HI the window follows the "
                  "running maximum of the --percentile of |v| (default task: volume:hot)")
      ->allow_extra_args(false);
  sub->add_option("--size", args->size, "Image size WIDTHxHEIGHT")->capture_default_str();
  sub->add_option("--out", args->out, "Output database directory")->required();
  sub->add_flag("--overwrite", args->overwrite, "Replace an existing database in --out");
  sub->add_option("--sample-distance", args->sample_distance, "Ray sample distance in voxels")
      ->check(CLI::Range(0.01, 16.0))->capture_default_str();
  sub->add_flag("--adaptive,!--no-adaptive", args->adaptive,
                "Adaptive image-space sampling: march every 4th pixel and interpolate where the image is smooth "
                "(default: on; --no-adaptive marches every pixel)");
  sub->add_option("--percentile", args->percentile, "Reference for relative windows: this quantile of |v|")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  sub->add_option("--spacing", args->spacing, "Grid spacing sx,sy,sz (default: from the file, or 1,1,1)");
  sub->add_option("--origin", args->origin, "Grid origin x,y,z (default: from the file, or 0,0,0)");
  sub->add_option("--background", args->background, "Background colour r,g,b in [0, 1]")->capture_default_str();
  sub->add_flag("--no-outline", args->no_outline, "Do not draw the domain's outline box");
  sub->add_option("--title", args->title, "Title stored in the manifest");
  sub->add_option("--crf", args->crf, "x264 quality 0..51 (default: the video default)");
  sub->add_flag("--force", args->force, "Start even when the estimated memory exceeds what is available");
  sub->add_option("--up-axis", args->up_axis,
                  "Which way is up in the volume: z_up, or z_down (z is depth, as in seismology); the rig's poles, "
                  "latitudes, the images' up and the player's Up key follow it")
      ->check(CLI::IsMember({"z_up", "z_down"}))
      ->capture_default_str();
  sub->add_option("--projection", args->projection,
                  "perspective, or equirectangular: 360x180-degree frames (use a 2:1 --size, e.g. 1920x960) that the "
                  "player looks around in; no outline box is drawn then")
      ->check(CLI::IsMember({"perspective", "equirectangular"}))
      ->capture_default_str();
  sub->add_flag("-q,--quiet", args->quiet, "No progress output");
  sub->callback([args] {
    install_stop_handlers();
    run(*args, recorded_command_line(*args));
  });
});

}  // namespace
