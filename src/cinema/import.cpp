// Importing a Cinema database: plan_import (the table -> a manifest and image files), import_cinema.
// Sections (each marked "// --- name ---" below):
//   helpers     columns, numbers, sky angles, the sidecar Panoptes' own export writes
//   planner     ImportPlanner: what plan_import's steps share
//   frames      the distinct times
//   convention  the producer's phi/theta convention
//   cameras     cameras by id column or by distinct angles
//   tasks       tasks from the group-by columns
//   manifest    the manifest's header, axes and task entries, or the sidecar's
//   images      every view's image, once, all of one size
//   geometry    camera positions, the navigation graph, the rig
//   import      plan_import runs the steps; import_cinema encodes the images
#include "cinema/import.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cmath>
#include <map>
#include <mutex>
#include <set>
#include <unordered_map>

#include "camera/navigation.hpp"
#include "camera/rig.hpp"
#include "cinema/cinema_database.hpp"
#include "cinema/conventions.hpp"
#include "cinema/csv.hpp"
#include "cinema/image_file.hpp"
#include "cinema/stream_workers.hpp"
#include "core/error.hpp"
#include "store/database.hpp"
#include "core/version.hpp"

namespace panoptes::cinema {
namespace fs = std::filesystem;

// --- helpers ---
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

constexpr double kRad = 180.0 / 3.14159265358979323846;

// Latitude and longitude of a direction in the producer's sky frame (its pole as "north"), a proper
// rotation of the world axes, so the mini-map keeps the handedness of a native database.
void sky_angles(const Vec3& d, const Vec3& pole, double& lat, double& lon) {
  Vec3 e{1, 0, 0}, n{0, 1, 0};
  if (pole.y != 0) e = {0, 0, 1}, n = {1, 0, 0};
  if (pole.x != 0) e = {0, 1, 0}, n = {0, 0, 1};
  lat = std::asin(std::clamp(dot(d, pole), -1.0, 1.0)) * kRad;
  lon = std::atan2(dot(d, n), dot(d, e)) * kRad;
  if (std::abs(lat) > 90 - 1e-9) lon = 0;
}

// How the image files carry phi and theta, when every row's path does so as one producer names them
// (ProducerEvidence::layout). A path element equals a value when it reads as the same number.
bool same_number(const std::string& text, double v) {
  double x;
  return parse_number(text, x) && std::abs(x - v) <= 1e-6 * std::max(1.0, std::abs(v));
}

bool paraview_name(const fs::path& file, double phi, double theta) {  // "...p=PHIt=THETA.png"
  const std::string stem = file.stem().string();
  const auto p = stem.rfind("p="), q = stem.rfind("t=");
  return p != std::string::npos && q != std::string::npos && q > p &&
         same_number(stem.substr(p + 2, q - p - 2), phi) && same_number(stem.substr(q + 2), theta);
}

bool ascent_name(const fs::path& file, double phi, double theta) {  // "PHI_THETA_NAME.png"
  const std::string stem = file.stem().string();
  const auto a = stem.find('_'), b = a == std::string::npos ? a : stem.find('_', a + 1);
  return b != std::string::npos && same_number(stem.substr(0, a), phi) && same_number(stem.substr(a + 1, b - a - 1), theta);
}

bool cinema_python_path(const fs::path& file, double phi, double theta) {  // ".../PHI/THETA[/...].png"
  std::vector<std::string> parts;
  for (const auto& e : file) parts.push_back(e.string());
  if (parts.empty()) return false;
  parts.back() = file.stem().string();
  for (std::size_t i = 0; i + 1 < parts.size(); ++i)
    if (same_number(parts[i], phi) && same_number(parts[i + 1], theta)) return true;
  return false;
}

void file_layout(const CinemaTable& t, const std::vector<std::pair<double, double>>& angles, ProducerEvidence& ev) {
  struct Layout {
    Angles angles;
    bool (*match)(const fs::path&, double, double);
    const char* text;
  };
  const Layout layouts[] = {{Angles::paraview, paraview_name, "files named ...p={phi}t={theta}.png"},
                            {Angles::ascent, ascent_name, "files named {phi}_{theta}_NAME.png"},
                            {Angles::cinema_python, cinema_python_path, "files laid out .../{phi}/{theta}.png"}};
  if (t.files.empty()) return;
  for (const Layout& l : layouts) {
    bool all = true;
    for (std::size_t r = 0; r < t.files.size() && all; ++r) all = l.match(fs::path(t.files[r]), angles[r].first, angles[r].second);
    if (all) {
      ev.layout = l.angles;
      ev.layout_text = std::string(l.text) + " (" + t.files[0] + ")";
      return;
    }
  }
}

// The cameras, tasks and graph Panoptes' own export wrote beside data.csv; rows are matched to them
// by the camera column or by phi/theta/shell, and by the task column or the axis columns.
struct Sidecar {
  store::Manifest m;
  bool present = false;
};

Sidecar read_sidecar(const CinemaTable& t) {
  Sidecar s;
  if (!t.panoptes) return s;
  const std::string source = (t.dir / "panoptes-cinema.json").string();
  const nlohmann::json& j = *t.panoptes;
  if (!j.is_object() || !j.contains("manifest")) throw FileError(source, "no \"manifest\" object; not written by panoptes export-cinema");
  try {
    s.m = store::manifest_from_json(j["manifest"], source);
  } catch (const FileError&) {
    throw;
  } catch (const Error& e) {
    throw FileError(source, e.what());
  }
  s.present = true;
  return s;
}

// The table, without rows whose FILE is not an image (cinema_python's and ParaView's .npz depth or
// value layers, .vti, ...): those are skipped with a warning; a table of no image at all is refused.
bool is_image_name(const std::string& file) {
  const std::string ext = lower(fs::path(file).extension().string());
  return ext.empty() || ext == ".png" || ext == ".jpg" || ext == ".jpeg";
}

CinemaTable read_table(const fs::path& cdb, const ImportOptions& o) {
  CinemaTable t = read_cinema_database(cdb, o.image_column);
  std::size_t kept = 0;
  std::string example;  // the first row skipped
  std::map<std::string, int> skipped_ext;
  for (std::size_t r = 0; r < t.files.size(); ++r) {
    if (!is_image_name(t.files[r])) {
      if (example.empty()) example = t.where[r] + ": " + t.files[r];
      ++skipped_ext[lower(fs::path(t.files[r]).extension().string())];
      continue;
    }
    if (kept != r) {
      t.values[kept] = std::move(t.values[r]);
      t.files[kept] = std::move(t.files[r]);
      t.where[kept] = std::move(t.where[r]);
    }
    ++kept;
  }
  if (skipped_ext.empty()) return t;
  std::string exts;
  for (const auto& [ext, n] : skipped_ext) exts += (exts.empty() ? "" : ", ") + std::to_string(n) + " " + ext;
  if (kept == 0)
    throw FileError(t.source, "no row names a PNG or JPEG image (" + exts + "; e.g. " + example +
                                  "); Panoptes imports images" + (t.spec == "D" ? " (--image-column names the column that holds them)" : ""));
  t.warnings.push_back(t.source + ": skipped " + std::to_string(t.files.size() - kept) + " rows whose " + t.file_column +
                       " is not an image (" + exts + "; e.g. " + example + "); " + std::to_string(kept) + " image rows imported");
  t.values.resize(kept);
  t.files.resize(kept);
  t.where.resize(kept);
  return t;
}

// --- planner ---
// The steps of plan_import, in the order it takes them; each reads what the ones before it found.
struct ImportPlanner {
  struct Cam {
    double phi = 0, theta = 0;
    std::size_t first_row = 0;
  };
  ImportPlanner(const fs::path& cdb, const ImportOptions& o) : cdb(cdb), o(o), t(read_table(cdb, o)) { plan.warnings = t.warnings; }
  const fs::path& cdb;
  const ImportOptions& o;
  const CinemaTable t;
  const Sidecar side = read_sidecar(t);
  const std::size_t rows = t.files.size();
  // The frames: "time", or "timestep" as some producers name it.
  const int c_time = find_column(t, "time") >= 0 ? find_column(t, "time") : find_column(t, "timestep");
  const int c_phi = find_column(t, "phi"), c_theta = find_column(t, "theta"),
            c_camera = find_column(t, "camera"), c_shell = side.present ? find_column(t, "shell") : -1;
  // ParaView's camera mode Static: no phi, theta or camera column; one camera as the producer left it.
  const bool static_camera = !side.present && c_phi < 0 && c_theta < 0 && c_camera < 0;
  std::vector<double> times;            // frames: the distinct times, ascending
  std::vector<int> row_frame;           // per row
  std::vector<std::pair<double, double>> angles;  // per row: phi, theta
  CameraModel model;                    // the producer's convention (no sidecar)
  std::vector<Cam> cams;
  std::vector<int> row_camera;          // per row
  std::vector<int> group;               // the columns that tell tasks apart
  std::vector<bool> numeric;            // per group column
  std::vector<std::vector<std::string>> task_keys;
  std::vector<int> row_task;            // per row
  ImportPlan plan;
  store::Manifest& m = plan.manifest;

  void read_frames();
  void detect_convention();
  void find_cameras();
  void group_tasks();
  void make_tasks();
  bool views_distinct(bool complete) const;
  void drop_measures();
  void start_manifest();
  void name_tasks();
  void adopt_sidecar_tasks();
  void find_images();
  void place_cameras();
  void place_static_camera();
};

// --- frames ---
void ImportPlanner::read_frames() {
  // ---- frames: the distinct times, ascending --------------------------------------------------
  std::vector<double> row_time(rows, 0.0);
  if (c_time >= 0)
    for (std::size_t r = 0; r < rows; ++r) row_time[r] = number_at(t, r, c_time, "time");
  times = row_time;
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  row_frame.resize(rows);
  for (std::size_t r = 0; r < rows; ++r)
    row_frame[r] = int(std::lower_bound(times.begin(), times.end(), row_time[r]) - times.begin());
}

// --- convention ---
void ImportPlanner::detect_convention() {
  // ---- the phi/theta convention ---------------------------------------------------------------------
  angles.assign(rows, {0.0, 0.0});
  std::vector<double> thetas;
  for (std::size_t r = 0; r < rows; ++r) {
    angles[r].first = c_phi >= 0 ? number_at(t, r, c_phi, "phi") : 0.0;
    angles[r].second = c_theta >= 0 ? number_at(t, r, c_theta, "theta") : 0.0;
    if (c_theta >= 0) thetas.push_back(angles[r].second);
  }
  std::sort(thetas.begin(), thetas.end());
  thetas.erase(std::unique(thetas.begin(), thetas.end()), thetas.end());
  if (!side.present) {
    ProducerEvidence ev;
    ev.spec = t.spec;
    ev.columns = t.columns;
    ev.file_column = t.file_column;
    ev.info = t.info;
    ev.has_info_js = t.has_info_js;
    ev.thetas = thetas;
    ev.time_count = int(times.size());
    if (c_phi >= 0 && c_theta >= 0) file_layout(t, angles, ev);
    try {
      model = detect_producer(ev, o.angles, o.azimuth_zero);
      for (const std::string& n : model.notes) plan.warnings.push_back(t.source + ": " + n);
    } catch (const FileError&) {
      throw;
    } catch (const Error& e) {
      throw FileError(t.source, e.what());
    }
  }
}

// --- cameras ---
void ImportPlanner::find_cameras() {
  // ---- cameras: by the camera column, else by distinct (phi, theta[, shell]) ---------------------
  row_camera.resize(rows);
  if (side.present) {
    const int n = side.m.camera_count();
    // The export prints each label as format_value: match on that text.
    std::map<std::tuple<std::string, std::string, int>, int> by_angles;
    for (const auto& c : side.m.cameras)
      by_angles.emplace(std::tuple{format_value(c.labels.lon_deg), format_value(c.labels.lat_deg), c.labels.shell}, c.id);
    for (std::size_t r = 0; r < rows; ++r) {
      int id = -1;
      if (c_camera >= 0) {
        const double v = number_at(t, r, c_camera, "camera");
        if (v == std::floor(v) && v >= 0 && v < n) id = int(v);
      } else {
        const int shell = c_shell >= 0 ? int(number_at(t, r, c_shell, "shell")) : 0;
        const auto it = by_angles.find({format_value(angles[r].first), format_value(angles[r].second), shell});
        if (it != by_angles.end()) id = it->second;
      }
      if (id < 0) throw FileError(t.where[r], "no camera of panoptes-cinema.json matches this row's camera columns");
      row_camera[r] = id;
    }
    for (const auto& c : side.m.cameras) cams.push_back({c.labels.lon_deg, c.labels.lat_deg, 0});
  } else if (c_camera >= 0) {
    std::map<long long, int> by_id;
    for (std::size_t r = 0; r < rows; ++r) {
      const double v = number_at(t, r, c_camera, "camera");
      if (v != std::floor(v) || v < 0 || v > 1e15)
        throw FileError(t.where[r], "camera \"" + t.values[r][std::size_t(c_camera)] + "\" is not a camera id (integer >= 0)");
      by_id.emplace((long long)v, 0);
    }
    for (auto& [id, index] : by_id) index = int(cams.size()), cams.push_back({});
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
                                        format_float(cams[std::size_t(c)].phi) + "/" + format_float(cams[std::size_t(c)].theta));
      }
    }
  } else {
    // Numbered like Panoptes' lat-lon rigs: by descending theta, each ring by phi.
    std::map<std::pair<double, double>, int> by_angles;
    for (std::size_t r = 0; r < rows; ++r) by_angles.emplace(std::pair{-angles[r].second, angles[r].first}, 0);
    for (auto& [key, id] : by_angles) {
      id = int(cams.size());
      cams.push_back({key.second, -key.first, 0});
    }
    for (std::size_t r = 0; r < rows; ++r) row_camera[r] = by_angles[{-angles[r].second, angles[r].first}];
  }
}

// --- tasks ---
void ImportPlanner::group_tasks() {
  // ---- tasks: distinct combinations of the group-by columns ----------------------------------------
  auto is_camera_col = [&](int c) { return c == c_time || c == c_phi || c == c_theta || c == c_camera || c == c_shell; };
  if (o.group_by.empty()) {
    for (std::size_t c = 0; c < t.columns.size(); ++c)
      if (!is_camera_col(int(c))) group.push_back(int(c));
  } else {
    for (const auto& name : o.group_by) {
      const auto it = std::find(t.columns.begin(), t.columns.end(), name);
      if (it == t.columns.end()) {
        std::string list;
        for (const auto& c : t.columns) list += (list.empty() ? "" : ", ") + c;
        if (list.size() > 1000) list = list.substr(0, 1000) + "...";
        throw FileError(t.source, "--group-by column \"" + name + "\" does not exist; columns: " + list);
      }
      const int c = int(it - t.columns.begin());
      if (is_camera_col(c)) throw Error("--group-by: column \"" + name + "\" already maps to time or cameras; it cannot group tasks");
      group.push_back(c);
    }
  }
  numeric.assign(group.size(), true);
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
  make_tasks();
  if (o.group_by.empty() && !side.present && !views_distinct(true)) drop_measures();
}

void ImportPlanner::make_tasks() {
  std::map<std::vector<std::string>, int> task_of;
  task_keys.clear();
  row_task.assign(rows, 0);
  for (std::size_t r = 0; r < rows; ++r) {
    std::vector<std::string> key;
    key.reserve(group.size());
    for (std::size_t g = 0; g < group.size(); ++g) {
      std::string v = t.values[r][std::size_t(group[g])];
      double x;
      if (numeric[g] && parse_number(v, x)) v = format_float(x);  // "0.5" and "0.50" are one value
      key.push_back(std::move(v));
    }
    const auto [it, inserted] = task_of.emplace(std::move(key), int(task_keys.size()));
    if (inserted) task_keys.push_back(it->first);
    row_task[r] = it->second;
  }
}

// Every row a distinct (camera, task, frame); `complete` also asks for every combination.
bool ImportPlanner::views_distinct(bool complete) const {
  std::unordered_map<std::uint64_t, char> seen;
  seen.reserve(rows);
  const std::uint64_t nt = task_keys.size(), nf = times.size();
  for (std::size_t r = 0; r < rows; ++r)
    if (!seen.emplace((std::uint64_t(row_camera[r]) * nt + std::uint64_t(row_task[r])) * nf + std::uint64_t(row_frame[r]), 0).second)
      return false;
  return !complete || double(cams.size()) * double(nt) * double(nf) == double(rows);
}

// Numeric columns that vary between images without indexing them (a per-image measure: an area, a
// maximum, a time step number beside the time) make every image its own task, so no task has every
// camera. Such a column is one the images are told apart without: dropped greedily, the most varied
// first, while the views stay distinct; kept out of the tasks when that completes the table, with a
// warning naming them and --group-by. Otherwise the table is left as it was (and refused below).
void ImportPlanner::drop_measures() {
  constexpr std::size_t kMaxCandidates = 64;  // each try is linear in the table
  std::vector<std::pair<std::size_t, std::size_t>> candidates;  // (distinct values, group index)
  for (std::size_t g = 0; g < group.size(); ++g) {
    if (!numeric[g]) continue;
    std::set<std::string> distinct;
    for (std::size_t r = 0; r < rows; ++r) distinct.insert(t.values[r][std::size_t(group[g])]);
    if (distinct.size() > 1) candidates.push_back({distinct.size(), g});
  }
  if (candidates.empty() || candidates.size() > kMaxCandidates) return;
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) { return a.first > b.first || (a.first == b.first && a.second < b.second); });
  const std::vector<int> all_group = group;
  const std::vector<bool> all_numeric = numeric;
  std::vector<bool> dropped(group.size(), false);
  auto apply = [&] {
    group.clear();
    numeric.clear();
    for (std::size_t g = 0; g < all_group.size(); ++g)
      if (!dropped[g]) group.push_back(all_group[g]), numeric.push_back(all_numeric[g]);
    make_tasks();
  };
  for (const auto& [n, g] : candidates) {
    dropped[g] = true;
    apply();
    if (!views_distinct(false)) dropped[g] = false;
  }
  apply();
  std::string names;
  for (std::size_t g = 0; g < all_group.size(); ++g)
    if (dropped[g]) names += (names.empty() ? "" : ", ") + t.columns[std::size_t(all_group[g])];
  if (names.empty() || !views_distinct(true)) {  // not measures: the table is incomplete as it is
    std::fill(dropped.begin(), dropped.end(), false);
    apply();
    return;
  }
  std::string kept;
  for (int c : group) kept += (kept.empty() ? "" : ",") + t.columns[std::size_t(c)];
  plan.warnings.push_back(t.source + ": column" + (names.find(',') != std::string::npos ? "s " : " ") + names +
                          " vary per image but do not index the images (per-image measures); ignored, not made tasks "
                          "(--group-by chooses the task columns" + (kept.empty() ? std::string() : "; here " + kept) + ")");
}

// --- manifest ---
void ImportPlanner::start_manifest() {
  plan.spec = t.spec;
  m.title = o.title.empty() ? "Cinema database " + fs::absolute(cdb).lexically_normal().filename().string() : o.title;
  if (m.title == "Cinema database ") m.title = "Cinema database";
  m.provenance.program = "panoptes import-cinema";
  m.provenance.version = panoptes::kVersion;
  m.provenance.command_line = o.command_line;
  m.provenance.extra["cinema_spec"] = t.spec;
  m.provenance.extra["cinema_source"] = fs::absolute(cdb).lexically_normal().string();
  m.times = times;
  m.video = o.video;
}

void ImportPlanner::name_tasks() {
  // Axes: every numeric group column, its distinct values ascending.
  std::vector<int> axis_of_group(group.size(), -1);
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
    axis_of_group[g] = int(m.axes.size());
    m.axes.push_back(std::move(a));
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
      if (int(g) != name_col && generic.size() <= kMaxField) generic += (generic.empty() ? "" : " ") + col + "=" + key[g];
      double x;
      if (numeric[g] && parse_number(key[g], x)) {
        e.parameters[col] = x;
        const auto& axis = m.axes[std::size_t(axis_of_group[g])];
        e.axes.push_back({col, int(std::lower_bound(axis.values.begin(), axis.values.end(), x) - axis.values.begin())});
      } else {
        e.parameters[col] = key[g];
      }
    }
    if (generic.size() > kMaxField) generic = "task " + std::to_string(k);  // too many columns to name it by
    e.name = name_col >= 0 && !key[std::size_t(name_col)].empty() ? key[std::size_t(name_col)] : generic;
    if (e.name.empty()) e.name = "image";
    if (!names.insert(e.name).second) {  // a "task" column that does not tell all tasks apart
      e.name += " (" + generic + ")";
      if (!names.insert(e.name).second) e.name = "task " + std::to_string(k);
      names.insert(e.name);
    }
    m.tasks.push_back(std::move(e));
  }
}

void ImportPlanner::adopt_sidecar_tasks() {
  if (side.present) {
    // The export's task column holds the task id, or its axis columns the task's axis values; a
    // table whose tasks are exactly the sidecar's keeps the sidecar's names, methods and parameters.
    if (task_keys.size() != side.m.tasks.size())
      throw FileError(t.source, std::to_string(task_keys.size()) + " tasks in the table, " + std::to_string(side.m.tasks.size()) +
                                    " in panoptes-cinema.json; the files do not belong together");
    const int c_task = [&] {
      for (std::size_t g = 0; g < group.size(); ++g)
        if (t.columns[std::size_t(group[g])] == "task" && numeric[g]) return int(g);
      return -1;
    }();
    std::vector<int> remap(task_keys.size(), -1);
    for (std::size_t k = 0; k < task_keys.size(); ++k) {
      int id = -1;
      double x;
      if (c_task >= 0 && parse_number(task_keys[k][std::size_t(c_task)], x) && x == std::floor(x) && x >= 0 &&
          x < double(side.m.tasks.size())) {
        id = int(x);
      } else if (c_task < 0) {
        for (const auto& st : side.m.tasks) {
          bool all = true;
          for (std::size_t g = 0; g < group.size() && all; ++g) {
            const std::string& col = t.columns[std::size_t(group[g])];
            if (col == "task_name") continue;  // the names are the sidecar's
            const auto pos = std::find_if(st.axes.begin(), st.axes.end(), [&](const auto& p) { return p.axis == col; });
            double v;
            const auto ax = std::find_if(side.m.axes.begin(), side.m.axes.end(), [&](const auto& a) { return a.name == col; });
            all = pos != st.axes.end() && ax != side.m.axes.end() && parse_number(task_keys[k][g], v) &&
                  v == ax->values[std::size_t(pos->index)];
          }
          if (all) id = st.id;
        }
      }
      if (id < 0) throw FileError(t.source, "task " + std::to_string(k) + " of the table matches no task of panoptes-cinema.json");
      remap[k] = id;
    }
    for (std::size_t r = 0; r < rows; ++r) row_task[r] = remap[std::size_t(row_task[r])];
    m.tasks = side.m.tasks;
    m.axes = side.m.axes;
    task_keys.assign(m.tasks.size(), {});
  }
}

// --- images ---
void ImportPlanner::find_images() {
  // ---- every (camera, task, frame) exactly once; memory linear in the rows -------------------------
  const std::size_t nc = cams.size(), nt = task_keys.size(), nf = times.size();
  std::unordered_map<std::uint64_t, std::int64_t> row_of;
  row_of.reserve(rows);
  auto view_key = [&](std::size_t c, std::size_t k, std::size_t f) { return (std::uint64_t(c) * nt + k) * nf + f; };
  for (std::size_t r = 0; r < rows; ++r) {
    const auto [it, inserted] = row_of.emplace(view_key(std::size_t(row_camera[r]), std::size_t(row_task[r]), std::size_t(row_frame[r])), std::int64_t(r));
    if (!inserted) {
      const std::size_t prev = std::size_t(it->second);
      std::string differ;
      for (std::size_t c = 0; c < t.columns.size() && differ.size() < 1000; ++c)
        if (t.values[r][c] != t.values[prev][c]) differ += (differ.empty() ? "" : ", ") + t.columns[c];
      throw FileError(t.where[r], "same camera, task and time as " + t.where[prev] +
                                      (differ.empty() ? std::string(": two images for one view")
                                                      : "; they differ in " + differ + ": add it to --group-by"));
    }
  }
  auto describe = [&](std::size_t c, std::size_t k, std::size_t f) {
    return "camera phi=" + format_float(cams[c].phi) + " theta=" + format_float(cams[c].theta) + ", task \"" +
           m.tasks[k].name + "\", time " + format_float(times[f]);
  };
  // rows distinct views exist; fewer than cameras x tasks x times means one is missing: find it within
  // rows + 1 lookups (never walking the whole, possibly huge, product).
  if (double(nc) * double(nt) * double(nf) != double(rows)) {
    for (std::size_t c = 0; c < nc; ++c)
      for (std::size_t k = 0; k < nt; ++k)
        for (std::size_t f = 0; f < nf; ++f)
          if (!row_of.count(view_key(c, k, f)))
            throw FileError(t.source, "no image for " + describe(c, k, f) + "; every camera needs every task at every time");
  }
  plan.files.resize(rows);
  int width = 0, height = 0;
  std::size_t size_row = 0;
  for (std::size_t c = 0; c < nc; ++c)
    for (std::size_t k = 0; k < nt; ++k)
      for (std::size_t f = 0; f < nf; ++f) {
        const std::size_t r = std::size_t(row_of.at(view_key(c, k, f)));
        const fs::path path = resolve_inside(t.dir, t.files[r], t.where[r]);
        if (!fs::exists(fs::symlink_status(path)))
          throw FileError(t.where[r], "image \"" + t.files[r] + "\" does not exist (" + path.string() + ")");
        int w = 0, h = 0;
        image_size(path, w, h);
        if (width == 0) {
          width = w, height = h, size_row = r;
        } else if (w != width || h != height) {
          throw FileError(path.string(), "image is " + std::to_string(w) + "x" + std::to_string(h) + ", but " + t.files[size_row] +
                                             " is " + std::to_string(width) + "x" + std::to_string(height) +
                                             "; a Panoptes database has one image size");
        }
        plan.files[(c * nt + k) * nf + f] = path;
      }
  m.image.width = width;
  m.image.height = height;
}

// --- geometry ---
void ImportPlanner::place_cameras() {
  const std::size_t nc = cams.size();
  // ---- camera geometry -----------------------------------------------------------------------------
  plan.rotated.assign(nc, false);
  if (side.present) {
    m.cameras = side.m.cameras;
    m.graph = side.m.graph;
    m.rig = side.m.rig;
    m.domain = side.m.domain;
    plan.producer = "Panoptes export-cinema (cameras, graph and tasks from panoptes-cinema.json)";
  } else if (static_camera) {
    place_static_camera();
  } else {
    camera::Rig rig;
    rig.center = model.center;
    rig.spec = "cinema";
    std::size_t turned = 0;
    for (std::size_t i = 0; i < nc; ++i) {
      const ProducerCamera pc = producer_camera(model, cams[i].phi, cams[i].theta);
      camera::RigCamera rc;
      rc.position = pc.position;
      rc.look_at = pc.look_at;
      rc.up = pc.stored_up;
      rc.fov_y_degrees = model.fov_y_deg;
      rc.patch = "cinema";
      sky_angles(normalize(pc.position - pc.look_at), model.pole, rc.latitude_deg, rc.longitude_deg);
      rc.radius = model.distance;
      rig.cameras.push_back(rc);
      plan.rotated[i] = pc.rotated;
      turned += pc.rotated;
    }
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
      e.labels.lat_deg = rc.latitude_deg;
      e.labels.lon_deg = rc.longitude_deg;
      if (model.angles == Angles::elevation && !model.mirrored) {  // exactly the database's angles
        e.labels.lat_deg = cams[i].theta;
        e.labels.lon_deg = cams[i].phi;
      }
      e.labels.shell = 0;
      e.labels.extra["cinema_phi"] = format_float(cams[i].phi);
      e.labels.extra["cinema_theta"] = format_float(cams[i].theta);
      if (plan.rotated[i]) e.labels.extra["cinema_turned"] = "180";  // the producer's picture was upside down
      m.cameras.push_back(e);
      const camera::Neighbours& n = graph.neighbours[i];
      m.graph.neighbours.push_back({n.left, n.right, n.up, n.down, n.in, n.out});
    }
    m.rig.kind = "cinema";
    m.rig.parameters = {{"spec", t.spec},
                        {"cameras", nc},
                        {"producer", model.producer},
                        {"angles", to_string(model.angles)},
                        {"evidence", model.evidence},
                        {"center", {model.center.x, model.center.y, model.center.z}},
                        {"distance", model.distance},
                        {"pole", {model.pole.x, model.pole.y, model.pole.z}},
                        {"recorded_camera", model.recorded},
                        {"turned_180", turned}};
    if (model.angles == Angles::elevation) m.rig.parameters["azimuth_zero"] = model.mirrored ? "-x" : "+x";
    if (!model.recorded)
      m.rig.parameters["note"] = "the database records no scene: cameras frame a unit box at the origin as the producer frames its scene";
    plan.producer = model.producer + " (" + model.evidence + ")";
  }
}

// ParaView's camera mode Static (and any table without phi, theta or camera): one camera, where the
// producer recorded it (info.json metadata camera_eye/camera_at/camera_up, as cinema_python records
// it), else at an unknown position: the camera entry is a placeholder marked as such, never a
// direction made up from angles the database does not have.
void ImportPlanner::place_static_camera() {
  store::CameraEntry e;
  e.id = 0;
  e.labels.patch = "cinema";
  e.labels.shell = 0;
  bool recorded = false;
  const nlohmann::json* meta = t.info && t.info->is_object() && t.info->contains("metadata") && (*t.info)["metadata"].is_object()
                                   ? &(*t.info)["metadata"]
                                   : nullptr;
  auto first_vec = [&](const char* key, Vec3& v) {
    if (!meta || !meta->contains(key)) return false;
    const nlohmann::json& a = (*meta)[key];
    const nlohmann::json& x = a.is_array() && !a.empty() && a[0].is_array() ? a[0] : a;
    if (!x.is_array() || x.size() != 3) return false;
    for (int k = 0; k < 3; ++k) {
      if (!x[std::size_t(k)].is_number() || !std::isfinite(x[std::size_t(k)].get<double>())) return false;
      v[k] = x[std::size_t(k)].get<double>();
    }
    return true;
  };
  Vec3 eye, at, up;
  if (first_vec("camera_eye", eye) && first_vec("camera_at", at) && first_vec("camera_up", up) && norm(eye - at) > 0 &&
      norm(cross(eye - at, up)) > 1e-12 * norm(eye - at) * norm(up)) {
    recorded = true;
    e.position = eye;
    e.look_at = at;
    const Vec3 f = normalize(at - eye);
    e.up = normalize(up - f * dot(up, f));
    e.fov_y_deg = model.fov_y_deg;
  } else {
    e.position = Vec3{0, 0, 1} * model.distance;  // a placeholder; marked unknown below
    e.look_at = {0, 0, 0};
    e.up = {0, 1, 0};
    e.fov_y_deg = model.fov_y_deg;
    e.labels.extra["cinema_position"] = "unknown";
  }
  e.labels.extra["cinema_camera"] = "static";
  m.cameras.push_back(e);
  m.graph.neighbours.push_back({-1, -1, -1, -1, -1, -1});
  m.rig.kind = "cinema";
  m.rig.parameters = {{"spec", t.spec}, {"cameras", 1}, {"camera_mode", "static"}, {"recorded_camera", recorded}};
  if (!recorded) m.rig.parameters["camera_position"] = "unknown";
  const std::string who = model.angles == Angles::paraview && o.angles.empty() ? "ParaView image extractor (camera mode Static)"
                                                                                : "Cinema database without camera angles";
  plan.producer = who + ": one camera, " +
                  (recorded ? std::string("as recorded in info.json metadata camera_eye/camera_at/camera_up")
                            : std::string("its position not recorded"));
  if (!recorded)
    plan.warnings.push_back(t.source + ": no phi, theta or camera column (" + who +
                            "): one camera whose position the producer did not record; imported as one view of unknown direction");
}

}  // namespace

// --- import ---
ImportPlan plan_import(const fs::path& cdb, const ImportOptions& o) {
  ImportPlanner s(cdb, o);
  s.read_frames();
  s.detect_convention();
  s.find_cameras();
  s.group_tasks();
  s.start_manifest();
  s.name_tasks();
  s.adopt_sidecar_tasks();
  s.find_images();
  s.place_cameras();
  s.m.provenance.extra["cinema_producer"] = s.plan.producer;
  s.m.validate();
  return std::move(s.plan);
}

ImportReport import_cinema(const fs::path& cdb, const fs::path& out, const ImportOptions& o,
                           const std::function<void(std::int64_t, std::int64_t)>& progress) {
  ImportPlan plan = plan_import(cdb, o);
  const store::Manifest& m = plan.manifest;
  const int nc = m.camera_count(), nt = m.task_count(), nf = int(m.times.size());
  store::WriterOptions w;
  w.overwrite = o.overwrite;
  w.overwrite_option = o.overwrite_option;
  store::DatabaseWriter writer = store::DatabaseWriter::create(out, m, w);
  for (int f = 0; f < nf; ++f) writer.set_time(f, m.times[std::size_t(f)]);

  const std::int64_t streams = std::int64_t(nc) * nt, total = streams * nf;
  std::atomic<std::int64_t> done{0};
  std::mutex progress_mutex;
  for_each_stream(streams, o.threads, [&](std::int64_t s) {
    const bool turn = plan.rotated[std::size_t(s / nt)];
    for (int f = 0; f < nf; ++f) {
      const fs::path& path = plan.files[std::size_t(s) * std::size_t(nf) + std::size_t(f)];
      const Image img = decode_image(path, turn);
      if (img.width != m.image.width || img.height != m.image.height)
        throw FileError(path.string(), "image is " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                                           "; expected " + std::to_string(m.image.width) + "x" + std::to_string(m.image.height));
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
  return {nc, nt, nf, plan.spec, plan.producer, plan.warnings};
}

}  // namespace panoptes::cinema
