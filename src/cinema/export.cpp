#include "cinema/export.hpp"

#include <atomic>
#include <fstream>
#include <mutex>
#include <thread>

#include "cinema/csv.hpp"
#include "cinema/stream_workers.hpp"
#include "core/error.hpp"
#include "core/png.hpp"
#include "store/database.hpp"

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

  std::error_code ec;
  if (fs::exists(out)) {
    if (!fs::is_directory(out)) throw FileError(out.string(), "exists and is not a directory");
    const bool cinema = fs::exists(out / "data.csv");
    const bool empty = fs::is_empty(out);
    if (!empty && !cinema) throw FileError(out.string(), "exists and is not a Cinema database; refusing to write into it");
    if (cinema && !o.overwrite) throw FileError(out.string(), "already holds a Cinema database (data.csv); use --overwrite");
    fs::remove(out / "data.csv", ec);
    fs::remove_all(out / "image", ec);
  }
  fs::create_directories(out / "image", ec);
  if (ec) throw FileError(out.string(), "cannot create the directory: " + ec.message());

  const int cams = db.camera_count(), tasks = db.task_count();
  auto rel_file = [&](int c, int t, int f) {
    return "image/c" + std::to_string(c) + "/t" + std::to_string(t) + "/f" + std::to_string(f) + "." + o.format;
  };
  for (int c = 0; c < cams; ++c)
    for (int t = 0; t < tasks; ++t) {
      fs::create_directories(out / ("image/c" + std::to_string(c) + "/t" + std::to_string(t)), ec);
      if (ec) throw FileError(out.string(), "cannot create image directories: " + ec.message());
    }

  // Streams are independent: decode them on a few threads, each stream's frames in order.
  const std::int64_t streams = std::int64_t(cams) * tasks, total = streams * std::int64_t(frames.size());
  std::atomic<std::int64_t> done{0}, bytes{0};
  std::mutex progress_mutex;
  for_each_stream(streams, o.threads, [&](std::int64_t s) {
    const int c = int(s / tasks), t = int(s % tasks);
    const auto reader = db.stream(c, t);
    for (int f : frames) {
      const Image img = reader->read_rgba(f);
      const fs::path path = out / rel_file(c, t, f);
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

  // data.csv: one row per image; parameters first, FILE last (Spec D).
  std::string csv = "time,camera,phi,theta,task";
  for (const auto& a : m.axes) (csv += ',') += csv_field(a.name);
  csv += ",FILE\r\n";
  for (int f : frames)
    for (int c = 0; c < cams; ++c) {
      const store::CameraLabels& l = m.cameras[std::size_t(c)].labels;
      for (int t = 0; t < tasks; ++t) {
        csv += format_float(m.frame_time(f)) + "," + std::to_string(c) + "," + format_float(l.lon_deg) + "," +
               format_float(l.lat_deg) + "," + csv_field(m.tasks[std::size_t(t)].name);
        for (const auto& a : m.axes) {
          csv += ",";
          for (const auto& p : m.tasks[std::size_t(t)].axes)
            if (p.axis == a.name) csv += format_float(a.values[std::size_t(p.index)]);
        }
        ((csv += ',') += csv_field(rel_file(c, t, f))) += "\r\n";
      }
    }
  const fs::path tmp = out / "data.csv.tmp";
  {
    std::ofstream file(tmp, std::ios::binary);
    file << csv;
    if (!file.flush()) throw FileError(tmp.string(), "cannot be written (disk full?)");
  }
  fs::rename(tmp, out / "data.csv", ec);
  if (ec) throw FileError((out / "data.csv").string(), "cannot be written: " + ec.message());
  return {total, bytes.load() + std::int64_t(csv.size())};
}

}  // namespace panoptes::cinema
