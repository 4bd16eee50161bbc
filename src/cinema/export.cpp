#include "cinema/export.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <set>
#include <tuple>
#include <fstream>
#include <mutex>
#include <thread>

#include "cinema/csv.hpp"
#include "cinema/stream_workers.hpp"
#include "core/error.hpp"
#include "core/png.hpp"
#include "store/database.hpp"
#include "store/manifest.hpp"

#include <nlohmann/json.hpp>

namespace panoptes::cinema {
namespace fs = std::filesystem;

std::vector<int> parse_frame_list(const std::string& text, int frame_count) {
  std::vector<int> frames;
  std::size_t start = 0;
  auto number = [&](const std::string& s, const std::string& item) {
    std::size_t used = 0;
    int v = 0;
    try {
      v = std::stoi(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != s.size() || s.empty())
      throw Error("--frames: \"" + item + "\" is not a frame, start:stop or start:stop:step");
    return v;
  };
  while (start <= text.size()) {
    const std::size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    std::vector<std::string> parts;
    for (std::size_t p = 0;;) {
      const std::size_t colon = item.find(':', p);
      parts.push_back(item.substr(p, colon == std::string::npos ? std::string::npos : colon - p));
      if (colon == std::string::npos) break;
      p = colon + 1;
    }
    if (parts.size() == 1) {
      const int f = number(parts[0], item);
      if (f < 0 || f >= frame_count)
        throw Error("--frames: frame " + std::to_string(f) + " out of range; the database has " +
                    std::to_string(frame_count) + " complete frames (0.." + std::to_string(frame_count - 1) + ")");
      frames.push_back(f);
    } else if (parts.size() <= 3) {
      const int a = parts[0].empty() ? 0 : number(parts[0], item);
      const int b = parts[1].empty() ? frame_count : number(parts[1], item);
      const int step = parts.size() == 3 ? number(parts[2], item) : 1;
      if (step < 1) throw Error("--frames: \"" + item + "\": step must be at least 1");
      if (a < 0 || b > frame_count || a >= b)
        throw Error("--frames: \"" + item + "\" is not a non-empty range inside 0.." + std::to_string(frame_count));
      for (int f = a; f < b; f += step) frames.push_back(f);
    } else {
      throw Error("--frames: \"" + item + "\" is not a frame, start:stop or start:stop:step");
    }
    start = comma + 1;
  }
  return frames;
}

namespace {

// The columns that identify an image in data.csv.
struct Layout {
  bool camera_grid = false;  // phi, theta (, shell) instead of camera
  bool shells = false;
  bool task_column = false;  // task id (tasks that are not their axes' full grid)
  bool axis_columns = false; // the axes identify the tasks
  bool task_names = false;   // a task_name text column
};

Layout plan_layout(const store::Manifest& m) {
  Layout l;
  std::set<std::string> phis, thetas;
  std::set<int> shells;
  std::set<std::tuple<std::string, std::string, int>> triples;
  for (const auto& c : m.cameras) {
    phis.insert(format_value(c.labels.lon_deg));
    thetas.insert(format_value(c.labels.lat_deg));
    shells.insert(c.labels.shell);
    triples.insert({format_value(c.labels.lon_deg), format_value(c.labels.lat_deg), c.labels.shell});
  }
  const double grid = double(phis.size()) * double(thetas.size()) * double(shells.size());
  l.camera_grid = triples.size() == m.cameras.size() && grid == double(m.cameras.size());
  l.shells = l.camera_grid && shells.size() > 1;
  if (m.tasks.size() > 1) {
    bool full = !m.axes.empty();
    std::set<std::vector<int>> combos;
    double product = 1;
    for (const auto& a : m.axes) product *= double(a.values.size());
    for (const auto& t : m.tasks) {
      if (t.axes.size() != m.axes.size()) full = false;
      std::vector<int> key(m.axes.size(), -1);
      for (const auto& p : t.axes)
        for (std::size_t a = 0; a < m.axes.size(); ++a)
          if (m.axes[a].name == p.axis) key[a] = p.index;
      combos.insert(key);
    }
    full = full && combos.size() == m.tasks.size() && product == double(m.tasks.size());
    l.axis_columns = full;
    l.task_column = !full;
    l.task_names = true;
    for (const auto& t : m.tasks) {
      double x;
      if (parse_number(t.name, x) || t.name.empty()) l.task_names = false;  // would become a slider
    }
  }
  return l;
}

// A directory beside `out` that this run alone creates (mkdir fails if it exists).
fs::path make_staging(const fs::path& out) {
  const fs::path abs = fs::absolute(out).lexically_normal();
  const fs::path parent = abs.has_filename() ? abs.parent_path() : abs.parent_path().parent_path();
  const std::string base = abs.has_filename() ? abs.filename().string() : abs.parent_path().filename().string();
  for (int i = 0; i < 1000; ++i) {
    const fs::path p = parent / ("." + base + ".partial-" + std::to_string(::getpid()) + "-" + std::to_string(i));
    if (::mkdir(p.c_str(), 0755) == 0) return p;
    if (errno != EEXIST) throw FileError(p.string(), std::string("cannot create the temporary export directory: ") + std::strerror(errno));
  }
  throw FileError(out.string(), "cannot create a temporary export directory beside it");
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream file(path, std::ios::binary);
  file << text;
  if (!file.flush()) throw FileError(path.string(), "cannot be written (disk full?)");
}

void move(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (ec) throw FileError(to.string(), "cannot move the export into place: " + ec.message());
}

}  // namespace

ExportReport export_cinema(const fs::path& db_dir, const fs::path& out, const ExportOptions& o,
                           const std::function<void(std::int64_t, std::int64_t)>& progress) {
  const store::Database db = store::Database::open(db_dir);
  const store::Manifest& m = db.manifest();
  if (o.format != "png" && o.format != "jpg")
    throw Error("export-cinema: format \"" + o.format + "\"; expected png or jpg");
  if (db.frame_count() < 1) throw FileError(db_dir.string(), "no complete frame to export");
  std::vector<int> frames = o.frames;
  if (frames.empty())
    for (int f = 0; f < db.frame_count(); ++f) frames.push_back(f);
  for (int f : frames)
    if (f < 0 || f >= db.frame_count())
      throw Error("export-cinema: frame " + std::to_string(f) + " out of range; the database has " +
                  std::to_string(db.frame_count()) + " complete frames");
  const int cams = db.camera_count(), tasks = db.task_count();

  // Every movie exists before anything is created (a manifest listing 10^4 tasks without movies must
  // not leave 40,000 directories behind); stream() checks each one fully when it is decoded.
  // (A packed database has no per-stream file: its index is checked when each stream opens.)
  for (int c = 0; c < cams && !db.packed(); ++c)
    for (int t = 0; t < tasks; ++t) {
      const fs::path movie = db.stream_path(c, t);
      std::error_code ec;
      if (!fs::is_regular_file(movie, ec))
        throw FileError(movie.string(), "movie of camera " + std::to_string(c) + ", task " + std::to_string(t) +
                                            " is missing or not a file; nothing exported");
    }
  if (fs::exists(out)) {
    if (!fs::is_directory(out)) throw FileError(out.string(), "exists and is not a directory");
    const bool cinema = fs::exists(out / "data.csv");
    if (!fs::is_empty(out) && !cinema) throw FileError(out.string(), "exists and is not a Cinema database; refusing to write into it");
    if (cinema && !o.overwrite) throw FileError(out.string(), "already holds a Cinema database (data.csv); use --overwrite");
  }

  const Layout layout = plan_layout(m);
  auto rel_file = [&](int c, int t, int f) {
    return "image/c" + std::to_string(c) + "/t" + std::to_string(t) + "_f" + std::to_string(f) + "." + o.format;
  };
  const fs::path stage = make_staging(out);
  try {
    for (int c = 0; c < cams; ++c) fs::create_directories(stage / ("image/c" + std::to_string(c)));

    // Streams are independent: decode them on a few threads, each stream's frames in order.
    const std::int64_t streams = std::int64_t(cams) * tasks, total = streams * std::int64_t(frames.size());
    std::atomic<std::int64_t> done{0}, bytes{0};
    std::mutex progress_mutex;
    for_each_stream(streams, o.threads, [&](std::int64_t s) {
      const int c = int(s / tasks), t = int(s % tasks);
      const auto reader = db.stream(c, t);
      for (int f : frames) {
        Image img = reader->read_rgba(f);
        if (o.decorate) o.decorate(img, c, t, f);
        const fs::path path = stage / rel_file(c, t, f);
        if (o.format == "png")
          write_png(path.string(), img);
        else
          write_jpg(path.string(), img, o.jpeg_quality);
        bytes += std::int64_t(fs::file_size(path));
        const std::int64_t d = ++done;
        if (progress && (d % 64 == 0 || d == total)) {
          std::lock_guard lock(progress_mutex);
          progress(d, total);
        }
      }
    });

    // data.csv: one row per image; the identifying numeric columns, then FILE (Spec D).
    std::string csv = "time";
    if (layout.camera_grid)
      csv += layout.shells ? ",phi,theta,shell" : ",phi,theta";
    else
      csv += ",camera";
    if (layout.task_column) csv += ",task";
    if (layout.task_names) csv += ",task_name";
    if (layout.axis_columns)
      for (const auto& a : m.axes) (csv += ',') += csv_field(a.name);
    csv += ",FILE\r\n";
    for (int f : frames)
      for (int c = 0; c < cams; ++c) {
        const store::CameraLabels& l = m.cameras[std::size_t(c)].labels;
        for (int t = 0; t < tasks; ++t) {
          const store::TaskEntry& task = m.tasks[std::size_t(t)];
          csv += format_value(m.frame_time(f));
          if (layout.camera_grid) {
            csv += "," + format_value(l.lon_deg) + "," + format_value(l.lat_deg);
            if (layout.shells) csv += "," + std::to_string(l.shell);
          } else {
            csv += "," + std::to_string(c);
          }
          if (layout.task_column) csv += "," + std::to_string(t);
          if (layout.task_names) csv += "," + csv_field(task.name);
          if (layout.axis_columns)
            for (const auto& a : m.axes) {
              csv += ",";
              for (const auto& p : task.axes)
                if (p.axis == a.name) csv += format_value(a.values[std::size_t(p.index)]);
            }
          ((csv += ',') += csv_field(rel_file(c, t, f))) += "\r\n";
        }
      }
    write_text(stage / "data.csv", csv);
    nlohmann::json side = {{"format", "panoptes-cinema"}, {"version", 1}, {"manifest", store::to_json(m)}};
    const std::string side_text = side.dump(1);
    write_text(stage / "panoptes-cinema.json", side_text);

    // Into place: a new OUT is the staging directory renamed; an existing one (empty, or a Cinema
    // database being overwritten) loses its old export's files and receives the new ones, data.csv last.
    if (!fs::exists(out)) {
      move(stage, out);
    } else {
      for (const char* old : {"data.csv", "panoptes-cinema.json"}) fs::remove(out / old);
      fs::remove_all(out / "image");
      move(stage / "image", out / "image");
      move(stage / "panoptes-cinema.json", out / "panoptes-cinema.json");
      move(stage / "data.csv", out / "data.csv");
      fs::remove(stage);
    }
    return {total, bytes.load() + std::int64_t(csv.size() + side_text.size())};
  } catch (...) {
    std::error_code ec;
    fs::remove_all(stage, ec);
    throw;
  }
}

}  // namespace panoptes::cinema
