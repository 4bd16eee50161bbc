#include "cinema/import.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "camera/navigation.hpp"
#include "camera/rig.hpp"
#include "cinema/cinema_database.hpp"
#include "cinema/csv.hpp"
#include "cinema/stream_workers.hpp"
#include "core/error.hpp"
#include "core/png.hpp"
#include "store/database.hpp"

namespace panoptes::cinema {
namespace fs = std::filesystem;

namespace {

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

int find_column(const CinemaTable& t, const std::string& name) {
  for (std::size_t i = 0; i < t.columns.size(); ++i)
    if (lower(t.columns[i]) == name) return int(i);
  return -1;
}

double number_at(const CinemaTable& t, std::size_t row, int col, const char* what) {
  double v = 0;
  if (!parse_number(t.values[row][std::size_t(col)], v))
    throw FileError(t.where[row], std::string(what) + " \"" + t.values[row][std::size_t(col)] + "\" (column " +
                                      t.columns[std::size_t(col)] + ") is not a number");
  return v;
}

constexpr double kDeg = 3.14159265358979323846 / 180.0;

}  // namespace

ImportPlan plan_import(const fs::path& cdb, const ImportOptions& o) {
  const CinemaTable t = read_cinema_database(cdb);
  const std::size_t rows = t.files.size();
  const int c_time = find_column(t, "time"), c_phi = find_column(t, "phi"), c_theta = find_column(t, "theta"),
            c_camera = find_column(t, "camera");

  // ---- frames: the distinct times, ascending --------------------------------------------------
  std::vector<double> row_time(rows, 0.0);
  if (c_time >= 0)
    for (std::size_t r = 0; r < rows; ++r) row_time[r] = number_at(t, r, c_time, "time");
  std::vector<double> times(row_time);
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  std::vector<int> row_frame(rows);
  for (std::size_t r = 0; r < rows; ++r)
    row_frame[r] = int(std::lower_bound(times.begin(), times.end(), row_time[r]) - times.begin());

  // ---- cameras: by the camera column, else by distinct (phi, theta) --------------------------------
  struct Cam {
    double phi = 0, theta = 0;
    std::size_t first_row = 0;
  };
  std::vector<Cam> cams;
  std::vector<int> row_camera(rows);
  {
    std::map<std::pair<double, double>, int> by_angles;  // (phi, theta) -> provisional id
    std::map<long long, int> by_id;
    std::vector<std::pair<double, double>> angles(rows);
    for (std::size_t r = 0; r < rows; ++r) {
      const double phi = c_phi >= 0 ? number_at(t, r, c_phi, "phi") : 0.0;
      const double theta = c_theta >= 0 ? number_at(t, r, c_theta, "theta") : 0.0;
      if (theta < -90 || theta > 90)
        throw FileError(t.where[r], "theta " + format_float(theta) + " is not an elevation in -90..90 degrees");
      angles[r] = {phi, theta};
    }
    if (c_camera >= 0) {
      std::set<long long> ids;
      for (std::size_t r = 0; r < rows; ++r) {
        const double v = number_at(t, r, c_camera, "camera");
        if (v != std::floor(v) || v < 0) throw FileError(t.where[r], "camera \"" + t.values[r][std::size_t(c_camera)] + "\" is not a camera id (integer >= 0)");
        ids.insert((long long)v);
      }
      for (long long id : ids) {
        by_id[id] = int(cams.size());
        cams.push_back({});
      }
      std::vector<bool> seen(cams.size(), false);
      for (std::size_t r = 0; r < rows; ++r) {
        const int c = by_id[(long long)number_at(t, r, c_camera, "camera")];
        row_camera[r] = c;
        if (!seen[std::size_t(c)]) {
          cams[std::size_t(c)] = {angles[r].first, angles[r].second, r};
          seen[std::size_t(c)] = true;
        } else if (std::abs(cams[std::size_t(c)].phi - angles[r].first) > 1e-9 ||
                   std::abs(cams[std::size_t(c)].theta - angles[r].second) > 1e-9) {
          throw FileError(t.where[r], "camera " + t.values[r][std::size_t(c_camera)] + " has phi/theta " +
                                          format_float(angles[r].first) + "/" + format_float(angles[r].second) + " but " +
                                          t.where[cams[std::size_t(c)].first_row] + " gave it " +
                                          format_float(cams[std::size_t(c)].phi) + "/" +
                                          format_float(cams[std::size_t(c)].theta));
        }
      }
    } else {
      // Numbered like Panoptes' lat-lon rigs: from the north (theta = +90) southwards, each ring by phi.
      for (std::size_t r = 0; r < rows; ++r) by_angles.emplace(std::pair{-angles[r].second, angles[r].first}, 0);
      for (auto& [key, id] : by_angles) {
        id = int(cams.size());
        cams.push_back({key.second, -key.first, 0});
      }
      for (std::size_t r = 0; r < rows; ++r) row_camera[r] = by_angles[{-angles[r].second, angles[r].first}];
    }
  }

  // ---- tasks: distinct combinations of the group-by columns ----------------------------------------
  std::vector<int> group;
  if (o.group_by.empty()) {
    for (std::size_t c = 0; c < t.columns.size(); ++c)
      if (int(c) != c_time && int(c) != c_phi && int(c) != c_theta && int(c) != c_camera) group.push_back(int(c));
  } else {
    for (const auto& name : o.group_by) {
      const auto it = std::find(t.columns.begin(), t.columns.end(), name);
      if (it == t.columns.end()) {
        std::string list;
        for (const auto& c : t.columns) list += (list.empty() ? "" : ", ") + c;
        throw FileError(t.source, "--group-by column \"" + name + "\" does not exist; columns: " + list);
      }
      const int c = int(it - t.columns.begin());
      if (c == c_time || c == c_phi || c == c_theta || c == c_camera)
        throw Error("--group-by: column \"" + name + "\" already maps to time or cameras; it cannot group tasks");
      group.push_back(c);
    }
  }
  std::vector<bool> numeric(group.size(), true);
  for (std::size_t g = 0; g < group.size(); ++g) {
    bool any = false;
    for (std::size_t r = 0; r < rows && numeric[g]; ++r) {
      const std::string& v = t.values[r][std::size_t(group[g])];
      double x;
      if (v.empty()) continue;
      any = true;
      numeric[g] = parse_number(v, x);
    }
    numeric[g] = numeric[g] && any;
  }
  std::map<std::vector<std::string>, int> task_of;
  std::vector<std::vector<std::string>> task_keys;
  std::vector<int> row_task(rows);
  for (std::size_t r = 0; r < rows; ++r) {
    std::vector<std::string> key;
    for (std::size_t g = 0; g < group.size(); ++g) {
      std::string v = t.values[r][std::size_t(group[g])];
      double x;
      if (numeric[g] && parse_number(v, x)) v = format_float(x);  // "0.5" and "0.50" are one value
      key.push_back(v);
    }
    const auto [it, inserted] = task_of.emplace(key, int(task_keys.size()));
    if (inserted) task_keys.push_back(key);
    row_task[r] = it->second;
  }

  ImportPlan plan;
  plan.spec = t.spec;
  store::Manifest& m = plan.manifest;
  m.title = o.title.empty() ? "Cinema database " + fs::absolute(cdb).lexically_normal().filename().string() : o.title;
  if (m.title == "Cinema database ") m.title = "Cinema database";
  m.provenance.program = "panoptes import-cinema";
  m.provenance.version = "0.1.0";
  m.provenance.command_line = o.command_line;
  m.provenance.extra["cinema_spec"] = t.spec;
  m.provenance.extra["cinema_source"] = fs::absolute(cdb).lexically_normal().string();
  m.times = times;
  m.video = o.video;

  // Axes: every numeric group column, its distinct values ascending.
  for (std::size_t g = 0; g < group.size(); ++g) {
    if (!numeric[g]) continue;
    store::ParameterAxis a;
    a.name = t.columns[std::size_t(group[g])];
    for (const auto& key : task_keys) {
      double x;
      if (parse_number(key[g], x)) a.values.push_back(x);
    }
    std::sort(a.values.begin(), a.values.end());
    a.values.erase(std::unique(a.values.begin(), a.values.end()), a.values.end());
    m.axes.push_back(a);
  }
  const int name_col = [&] {
    for (std::size_t g = 0; g < group.size(); ++g)
      if (!numeric[g] && lower(t.columns[std::size_t(group[g])]) == "task") return int(g);
    return -1;
  }();
  std::set<std::string> names;
  for (std::size_t k = 0; k < task_keys.size(); ++k) {
    const auto& key = task_keys[k];
    store::TaskEntry e;
    e.id = int(k);
    e.method = "cinema";
    std::string generic;
    for (std::size_t g = 0; g < group.size(); ++g) {
      const std::string& col = t.columns[std::size_t(group[g])];
      if (key[g].empty()) continue;
      if (int(g) != name_col) generic += (generic.empty() ? "" : " ") + col + "=" + key[g];
      double x;
      if (numeric[g] && parse_number(key[g], x)) {
        e.parameters[col] = x;
        const auto& axis = *std::find_if(m.axes.begin(), m.axes.end(), [&](const auto& a) { return a.name == col; });
        e.axes.push_back({col, int(std::lower_bound(axis.values.begin(), axis.values.end(), x) - axis.values.begin())});
      } else {
        e.parameters[col] = key[g];
      }
    }
    e.name = name_col >= 0 && !key[std::size_t(name_col)].empty() ? key[std::size_t(name_col)] : generic;
    if (e.name.empty()) e.name = "image";
    if (!names.insert(e.name).second) {  // a "task" column that does not tell all tasks apart
      e.name += " (" + generic + ")";
      if (!names.insert(e.name).second) e.name = "task " + std::to_string(k);
      names.insert(e.name);
    }
    m.tasks.push_back(std::move(e));
  }

  // ---- every (camera, task, frame) exactly once --------------------------------------------------
  const std::size_t nc = cams.size(), nt = task_keys.size(), nf = times.size();
  std::vector<std::int64_t> row_of(nc * nt * nf, -1);
  for (std::size_t r = 0; r < rows; ++r) {
    const std::size_t i = (std::size_t(row_camera[r]) * nt + std::size_t(row_task[r])) * nf + std::size_t(row_frame[r]);
    if (row_of[i] >= 0) {
      std::string differ;
      for (std::size_t c = 0; c < t.columns.size(); ++c)
        if (t.values[r][c] != t.values[std::size_t(row_of[i])][c]) differ += (differ.empty() ? "" : ", ") + t.columns[c];
      throw FileError(t.where[r], "same camera, task and time as " + t.where[std::size_t(row_of[i])] +
                                      (differ.empty() ? std::string(": two images for one view")
                                                      : "; they differ in " + differ + ": add it to --group-by"));
    }
    row_of[i] = std::int64_t(r);
  }
  auto describe = [&](std::size_t c, std::size_t k, std::size_t f) {
    return "camera phi=" + format_float(cams[c].phi) + " theta=" + format_float(cams[c].theta) + ", task \"" +
           m.tasks[k].name + "\", time " + format_float(times[f]);
  };
  plan.files.resize(row_of.size());
  int width = 0, height = 0;
  std::size_t size_row = 0;
  for (std::size_t c = 0; c < nc; ++c)
    for (std::size_t k = 0; k < nt; ++k)
      for (std::size_t f = 0; f < nf; ++f) {
        const std::int64_t r = row_of[(c * nt + k) * nf + f];
        if (r < 0) throw FileError(t.source, "no image for " + describe(c, k, f) + "; every camera needs every task at every time");
        const fs::path path = resolve_inside(t.dir, t.files[std::size_t(r)], t.where[std::size_t(r)]);
        if (!fs::is_regular_file(path))
          throw FileError(t.where[std::size_t(r)], "image \"" + t.files[std::size_t(r)] + "\" does not exist (" + path.string() + ")");
        int w = 0, h = 0;
        image_file_size(path.string(), w, h);
        if (width == 0) {
          width = w, height = h, size_row = std::size_t(r);
        } else if (w != width || h != height) {
          throw FileError(path.string(), "image is " + std::to_string(w) + "x" + std::to_string(h) + ", but " +
                                             t.files[size_row] + " is " + std::to_string(width) + "x" +
                                             std::to_string(height) + "; a Panoptes database has one image size");
        }
        plan.files[(c * nt + k) * nf + f] = path;
      }
  m.image.width = width;
  m.image.height = height;

  // ---- camera geometry: directions on a sphere around a unit box, graph computed -------------------
  std::vector<camera::PatternPoint> pattern;
  for (const Cam& c : cams) {
    const double lat = c.theta * kDeg, lon = c.phi * kDeg;
    pattern.push_back({{std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat)}, "cinema"});
  }
  camera::Rig rig = camera::place_on_shells(pattern, camera::Domain{{-0.5, -0.5, -0.5}, {1, 1, 1}}, {camera::kDefaultRadius});
  rig.spec = "cinema";
  const camera::NavigationGraph graph = camera::build_navigation_graph(rig);
  for (std::size_t i = 0; i < nc; ++i) {
    const camera::RigCamera& rc = rig.cameras[i];
    store::CameraEntry e;
    e.id = int(i);
    e.position = rc.position;
    e.look_at = rc.look_at;
    e.up = rc.up;
    e.fov_y_deg = rc.fov_y_degrees;
    e.labels.patch = "cinema";
    e.labels.lat_deg = cams[i].theta;  // exactly the database's angles, not recomputed
    e.labels.lon_deg = cams[i].phi;
    e.labels.shell = 0;
    m.cameras.push_back(e);
    const camera::Neighbours& n = graph.neighbours[i];
    m.graph.neighbours.push_back({n.left, n.right, n.up, n.down, n.in, n.out});
  }
  m.rig.kind = "cinema";
  m.rig.parameters = {{"spec", t.spec}, {"cameras", nc}, {"radius", camera::kDefaultRadius},
                      {"note", "directions from phi (azimuth) and theta (elevation); distance not in the Cinema database"}};
  m.validate();
  return plan;
}

ImportReport import_cinema(const fs::path& cdb, const fs::path& out, const ImportOptions& o,
                           const std::function<void(std::int64_t, std::int64_t)>& progress) {
  ImportPlan plan = plan_import(cdb, o);
  const store::Manifest& m = plan.manifest;
  const int nc = m.camera_count(), nt = m.task_count(), nf = int(m.times.size());
  store::DatabaseWriter writer = store::DatabaseWriter::create(out, m, o.overwrite);
  for (int f = 0; f < nf; ++f) writer.set_time(f, m.times[std::size_t(f)]);

  const std::int64_t streams = std::int64_t(nc) * nt, total = streams * nf;
  std::atomic<std::int64_t> done{0};
  std::mutex progress_mutex;
  for_each_stream(streams, o.threads, [&](std::int64_t s) {
    for (int f = 0; f < nf; ++f) {
      const fs::path& path = plan.files[std::size_t(s) * std::size_t(nf) + std::size_t(f)];
      const Image img = read_image(path.string());
      if (img.width != m.image.width || img.height != m.image.height)
        throw FileError(path.string(), "image is " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                                           "; expected " + std::to_string(m.image.width) + "x" +
                                           std::to_string(m.image.height));
      writer.append(int(s / nt), int(s % nt), img);
      const std::int64_t d = ++done;
      if (progress && (d % 64 == 0 || d == total)) {
        std::lock_guard lock(progress_mutex);
        progress(d, total);
      }
    }
    writer.close_stream(int(s / nt), int(s % nt));
  });
  writer.finalize();
  return {nc, nt, nf, plan.spec};
}

}  // namespace panoptes::cinema
