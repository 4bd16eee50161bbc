#include "store/synthetic.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <ctime>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "core/error.hpp"
#include "core/stop_request.hpp"
#include "core/version.hpp"
#include "core/frame_stamp.hpp"
#include "core/parallel_for.hpp"
#include "store/database.hpp"

namespace panoptes::store {

namespace {
// Names of the parameter axes of SyntheticOptions::axes, in order.
constexpr std::array<std::string_view, 4> kAxisNames{"isovalue", "opacity", "window", "blend"};

// The lattice variant (see SyntheticOptions::lattice). Written out here rather than through camera/,
// which store does not depend on; camera/volume_rigs_test checks the same layout and slots.
void lattice_cameras(Manifest& m, const std::array<int, 3>& n) {
  m.rig.kind = "lattice:" + std::to_string(n[0]) + "x" + std::to_string(n[1]) + "x" + std::to_string(n[2]) + "@0";
  m.rig.parameters = {{"spec", m.rig.kind}, {"shells", 1}, {"lattice", n}, {"note", "synthetic"}};
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) {
        CameraEntry e;
        e.id = i + n[0] * (j + n[1] * k);
        e.position = {-1 + 2 * (i + 0.5) / n[0], -1 + 2 * (j + 0.5) / n[1], -1 + 2 * (k + 0.5) / n[2]};
        e.look_at = e.position + Vec3{0, 2.0 / n[1], 0};
        e.up = {0, 0, 1};
        e.fov_y_deg = 90;
        e.labels.patch = "lattice";
        m.cameras.push_back(e);
        auto id = [&](int a, int b, int c) {
          return a < 0 || b < 0 || c < 0 || a >= n[0] || b >= n[1] || c >= n[2] ? -1 : a + n[0] * (b + n[1] * c);
        };
        Neighbours nb;
        nb.right = id(i + 1, j, k), nb.left = id(i - 1, j, k);
        nb.in = id(i, j + 1, k), nb.out = id(i, j - 1, k);
        nb.up = id(i, j, k + 1), nb.down = id(i, j, k - 1);
        m.graph.neighbours.push_back(nb);
      }
}
}  // namespace

Manifest synthetic_manifest(const SyntheticOptions& options) {
  SyntheticOptions o = options;
  const bool lattice = o.lattice[0] > 0 && o.lattice[1] > 0 && o.lattice[2] > 0;
  if (lattice) {
    if (std::int64_t(o.lattice[0]) * o.lattice[1] * o.lattice[2] > kStampMaxCamera + 1)
      throw Error("synthetic database: lattice of more than 2^24 cameras");
    o.cameras = o.lattice[0] * o.lattice[1] * o.lattice[2];
  }
  if (o.shells < 1 || (lattice && o.shells != 1)) throw Error("synthetic database: shells must be 1 or more, and 1 with a lattice");
  if (o.axes.size() > kAxisNames.size())
    throw Error("synthetic database: at most " + std::to_string(kAxisNames.size()) + " parameter axes");
  if (!o.axes.empty()) {
    std::int64_t tasks = 1;
    for (int n : o.axes) {
      if (n < 1) throw Error("synthetic database: every parameter axis needs at least one value");
      tasks = std::min<std::int64_t>(tasks * n, std::int64_t(kStampMaxTask) + 2);  // stops growing past the limit
    }
    o.tasks = int(tasks);
  }
  if (!lattice && std::int64_t(o.cameras) * o.shells > std::int64_t(kStampMaxCamera) + 1)
    throw Error("synthetic database: more than 2^24 cameras");
  if (!lattice) o.cameras *= o.shells;
  if (o.cameras <= 0 || o.tasks <= 0 || o.frames <= 0)
    throw Error("synthetic database: cameras (" + std::to_string(o.cameras) + "), tasks (" + std::to_string(o.tasks) +
                ") and frames (" + std::to_string(o.frames) + ") must be positive");
  if (std::uint32_t(o.cameras - 1) > kStampMaxCamera || std::uint32_t(o.tasks - 1) > kStampMaxTask ||
      std::uint32_t(o.frames - 1) > kStampMaxFrame)
    throw Error("synthetic database: at most 2^24 cameras, 2^16 tasks and 2^20 frames fit in the frame stamp");
  stamp_geometry(o.width, o.height);  // throws with the minimum size if the frame cannot hold a stamp
  Manifest m;
  m.title = o.title;
  m.provenance.program = "panoptes synth-db";
  m.provenance.version = panoptes::kVersion;
  m.provenance.command_line = o.command_line;
  m.domain.dims = {64, 64, 64};
  m.domain.origin = {-1, -1, -1};
  m.domain.spacing = {2.0 / 63, 2.0 / 63, 2.0 / 63};
  m.image.width = o.width;
  m.image.height = o.height;
  m.video = o.video;
  for (int f = 0; f < o.frames; ++f) m.times.push_back(0.1 * f);
  if (lattice) lattice_cameras(m, o.lattice);
  if (!lattice) m.rig.kind = "fibonacci";
  const int per_shell = o.cameras / o.shells;
  if (!lattice) m.rig.parameters = {{"count", per_shell}, {"radius", 3.0}, {"note", "synthetic; graph is a ring by index"}};
  if (!lattice && o.shells > 1) m.rig.parameters["shells"] = o.shells;
  if (o.projection != "perspective") m.rig.parameters["projection"] = o.projection;
  const double golden = M_PI * (3 - std::sqrt(5.0));
  for (int id = 0; id < (lattice ? 0 : o.cameras); ++id) {
    const int shell = id / per_shell, c = id % per_shell;
    const double radius = 3 / (1 + 0.5 * shell);
    const double z = 1 - (2.0 * c + 1) / per_shell, r = std::sqrt(std::max(0.0, 1 - z * z));
    const double phi = golden * c;
    CameraEntry e;
    e.id = id;
    e.position = {radius * r * std::cos(phi), radius * r * std::sin(phi), radius * z};
    e.look_at = {0, 0, 0};
    e.up = {0, 0, 1};
    e.fov_y_deg = 30;
    e.labels.patch = "fibonacci";
    e.labels.lat_deg = std::asin(z) * 180 / M_PI;
    e.labels.lon_deg = std::remainder(phi * 180 / M_PI, 360.0);
    e.labels.shell = shell;
    m.cameras.push_back(e);
    Neighbours n;
    if (per_shell > 1) {
      n.left = shell * per_shell + (c + per_shell - 1) % per_shell;
      n.right = shell * per_shell + (c + 1) % per_shell;
    }
    if (shell + 1 < o.shells) n.in = id + per_shell;
    if (shell > 0) n.out = id - per_shell;
    m.graph.neighbours.push_back(n);
  }
  const std::vector<int> counts = o.axes.empty() ? std::vector<int>{o.tasks} : o.axes;
  for (std::size_t a = 0; a < counts.size(); ++a) {
    ParameterAxis axis{std::string(kAxisNames[a]), {}, ""};
    for (int i = 0; i < counts[a]; ++i) axis.values.push_back(double(i + 1) / (counts[a] + 1));
    m.axes.push_back(axis);
  }
  for (int t = 0; t < o.tasks; ++t) {
    TaskEntry e;
    e.id = t;
    e.method = "synthetic";
    e.fields = {"synthetic"};
    e.parameters = nlohmann::json::object();
    // The first axis varies fastest: task t sits at index (t / stride) % count on each axis.
    for (std::size_t a = 0, stride = 1; a < counts.size(); stride *= std::size_t(counts[a]), ++a) {
      const int i = int((std::size_t(t) / stride) % std::size_t(counts[a]));
      e.name += (a ? " " : "") + m.axes[a].name + " " + std::to_string(i);
      e.parameters[m.axes[a].name] = m.axes[a].values[std::size_t(i)];
      e.axes.push_back({m.axes[a].name, i});
    }
    m.tasks.push_back(e);
  }
  return m;
}

void draw_synthetic_frame(Image& img, int camera, int task, int frame) {
  const int w = img.width, h = img.height, ch = img.channels;
  // Background: hue by task, brightness ramp by camera, so neighbouring streams look different.
  const double hue = std::fmod(task * 0.13, 1.0) * 6.0;
  const double rgb[3] = {0.5 + 0.5 * std::cos(hue), 0.5 + 0.5 * std::cos(hue - 2.094), 0.5 + 0.5 * std::cos(hue + 2.094)};
  const double shade = 0.35 + 0.3 * std::fmod(camera * 0.618034, 1.0);
  // A disc circling the centre: its angle advances with the frame and starts at the camera's phase.
  const double angle = frame * 0.35 + camera * 0.7;
  const double cx = w * (0.5 + 0.28 * std::cos(angle)), cy = h * (0.55 + 0.28 * std::sin(angle));
  const double radius = std::max(3.0, std::min(w, h) * 0.12), r2 = radius * radius;
  for (int y = 0; y < h; ++y) {
    std::uint8_t* p = img.row(y);
    const double ramp = shade * (0.6 + 0.4 * y / double(h));
    for (int x = 0; x < w; ++x, p += ch) {
      const double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
      if (dx * dx + dy * dy < r2) {
        p[0] = 250, p[1] = 240, p[2] = 90;
      } else {
        p[0] = std::uint8_t(255 * rgb[0] * ramp);
        p[1] = std::uint8_t(255 * rgb[1] * ramp);
        p[2] = std::uint8_t(255 * rgb[2] * ramp);
      }
      if (ch == 4) p[3] = 255;
    }
  }
  draw_frame_stamp(img, {std::uint32_t(camera), std::uint32_t(task), std::uint32_t(frame)});
}

Image synthetic_frame(int camera, int task, int frame, int width, int height) {
  Image img(width, height, 4);
  draw_synthetic_frame(img, camera, task, frame);
  return img;
}

void write_synthetic_database(const std::filesystem::path& dir, const SyntheticOptions& o,
                              const std::function<void(std::int64_t, std::int64_t)>& progress) {
  Manifest m = synthetic_manifest(o);
  WriterOptions w;
  w.overwrite = o.overwrite;
  w.overwrite_option = o.overwrite_option;
  w.layout = parse_layout_choice(o.layout);
  DatabaseWriter writer = DatabaseWriter::create(dir, m, w);
  const std::int64_t total = m.stream_count();
  std::atomic<std::int64_t> done{0};
  // Stream after stream per thread: each movie is written whole and closed, so at most `threads`
  // encoders are alive at once whatever the number of streams. A stop request (SIGINT/SIGTERM)
  // abandons the remaining streams (see core/stop_request.hpp).
  auto work = [&](std::int64_t s) {
    if (stop_requested()) return;
    Image img(o.width, o.height, 4);
    const int tasks = int(m.tasks.size());
    const int camera = int(s / tasks), task = int(s % tasks);
    for (int f = 0; f < o.frames; ++f) {
      draw_synthetic_frame(img, camera, task, f);
      writer.append(camera, task, img);
    }
    writer.close_stream(camera, task);
    ++done;
  };
  std::function<bool()> report;
  if (progress)
    report = [&] {
      if (done.load() >= total || stop_requested()) return false;
      progress(done.load(), total);
      return true;
    };
  parallel_for(total, o.threads, work, report);  // rethrows; the writer's destructor marks the database interrupted
  if (const int sig = stop_requested())
    throw Interrupted(sig, dir.string() + ": stopped by " + signal_name(sig) + " after " + std::to_string(done.load()) +
                               " of " + std::to_string(total) + " streams; the database is marked interrupted");
  if (progress) progress(total, total);
  writer.finalize();
}

}  // namespace panoptes::store
