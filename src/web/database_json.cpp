#include "web/database_json.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "player/legend.hpp"
#include "player/value_readout.hpp"

namespace panoptes::web {

nlohmann::json database_json(const store::Database& db, const DatabaseJsonOptions& options) {
  const store::Manifest& m = db.manifest();
  using nlohmann::json;
  json j;
  j["title"] = m.title;
  j["status"] = std::string(store::to_string(db.status()));
  // What a frame read as good proves (issue 44): "all", "frames" (parameter sets unverified), "none"
  // (written before frame checks: the players say its frames are unverified).
  const auto& fc = db.manifest().frame_checks;
  j["frames_verified"] = fc.binds_parameter_sets() ? "all" : fc.recorded() ? "frames" : "none";
  std::int64_t frames = db.frame_count();
  if (options.frames_backed >= 0 && options.frames_backed < frames) {
    j["frames_claimed"] = frames;
    j["warning"] = "the manifest claims " + std::to_string(frames) + " frames but the movies hold at most " +
                   std::to_string(options.frames_backed);
    frames = options.frames_backed;
  }
  j["frames"] = frames;
  // Where the movies' bytes are (docs/web.md): "files" (the movie_pattern) or "packed" (per stream
  // an index naming ranges of pack files).
  j["layout"] = std::string(store::to_string(m.layout));
  j["fps"] = m.video.fps;
  // The rate the database asks its players to use (0: none; the movies' own rate then), as the desktop player does.
  j["playback_fps"] = m.playback_fps;
  j["gop"] = m.video.gop;
  j["image"] = {{"width", m.image.width}, {"height", m.image.height}};
  // Only the times the manifest holds (bounded by its size): any other frame's time is its index.
  const std::size_t listed = std::min(std::size_t(frames), m.times.size());
  const std::size_t from = std::min(options.times_from, listed);
  const std::size_t count = std::min(listed - from, options.max_times);
  j["times"] = std::vector<double>(m.times.begin() + std::ptrdiff_t(from), m.times.begin() + std::ptrdiff_t(from + count));
  j["times_from"] = from;
  j["times_listed"] = listed;
  j["movie_pattern"] = m.movie_pattern;
  j["rig"] = m.rig.kind;
  j["domain_units"] = m.domain.units;

  json axes = json::array();
  for (const auto& a : m.axes) axes.push_back({{"name", a.name}, {"values", a.values}, {"units", a.units}});
  j["axes"] = std::move(axes);
  json tasks = json::array();
  // Slice colour tables (~600 colours each) are shared by every task with the same map, e.g. a sweep of
  // slice positions: each is sent once, and tasks name theirs by index.
  json readout_tables = json::array();
  std::map<std::string, std::size_t> table_index;
  for (int ti = 0; ti < m.task_count(); ++ti) {
    const auto& t = m.tasks[std::size_t(ti)];
    json positions = json::array();
    for (const auto& p : t.axes) positions.push_back({{"axis", p.axis}, {"index", p.index}});
    // fields and parameters carry what the colour legend shows (window, transfer function; issue 34).
    json task = {{"id", t.id}, {"name", t.name}, {"method", t.method}, {"axes", std::move(positions)},
                 {"fields", t.fields}, {"parameters", t.parameters}};
    // The legend's colours as the task draws them (player::drawn_colours: a slice opaque, a volume as a
    // thin layer over black), so the browser shows the desktop's colours without a second rule (issue 41).
    // Four decimals are finer than the 8-bit colours they become.
    json drawn = json::object();
    for (const char* key : {"transfer_function", "transfer_function2"}) {
      json colours = json::array();
      for (const auto& c : player::drawn_colours(t, key, player::kLegendSamples))
        colours.push_back({std::round(c[0] * 1e4) / 1e4, std::round(c[1] * 1e4) / 1e4, std::round(c[2] * 1e4) / 1e4});
      if (!colours.empty()) drawn[key] = std::move(colours);
    }
    if (!drawn.empty()) task["drawn_colours"] = std::move(drawn);
    // A slice's colour table and plane for the value under the cursor (player/value_readout.hpp).
    if (json readout = player::slice_readout_json(m, ti); !readout.is_null()) {
      json table = {{"colours", std::move(readout["colours"])}, {"u", std::move(readout["u"])}};
      readout.erase("colours");
      readout.erase("u");
      const auto [it, added] = table_index.emplace(table.dump(), readout_tables.size());
      if (added) readout_tables.push_back(std::move(table));
      readout["table"] = it->second;
      task["readout"] = std::move(readout);
    }
    tasks.push_back(std::move(task));
  }
  j["tasks"] = std::move(tasks);
  if (!readout_tables.empty()) j["readout_tables"] = std::move(readout_tables);
  j["time_units"] = m.time_units;
  json fields = json::array();
  for (const auto& f : m.fields) {
    json e = {{"name", f.name}, {"units", f.units}, {"references", f.references}};
    // What the references follow (issue 41), resolved for older manifests as player::task_legend does:
    // their session kept running maxima only in the running mode.
    if (!f.references.empty())
      e["reference_mode"] = !f.reference_mode.empty()                     ? f.reference_mode
                            : m.provenance.extra.count("insitu.running_max") ? "running"
                                                                             : "snapshot";
    fields.push_back(std::move(e));
  }
  j["fields"] = std::move(fields);

  const int n = m.camera_count();
  // A schema 2 database keeps its cameras in a binary table (docs/formats.md): the player fetches that
  // file as it is (GET /db/NAME) and reads its columns as typed arrays, instead of parsing ~150 bytes
  // of JSON per camera (150 MB at 10^6 cameras). Only inline (schema 1) cameras go into this JSON.
  const std::string table = store::referenced_camera_table(db.dir() / store::kManifestFileName);
  if (!table.empty() && !options.inline_cameras) {
    std::error_code ec;
    const auto bytes = std::filesystem::file_size(db.dir() / table, ec);
    j["cameras"] = {{"count", n}, {"table", table}, {"bytes", ec ? 0 : bytes}};
    return j;
  }
  std::vector<double> lat(n), lon(n), pos(3 * std::size_t(n)), look(3 * std::size_t(n)), up(3 * std::size_t(n));
  std::vector<int> shell(n);
  for (int i = 0; i < n; ++i) {
    const auto& c = m.cameras[i];
    lat[i] = c.labels.lat_deg;
    lon[i] = c.labels.lon_deg;
    shell[i] = c.labels.shell;
    const Vec3* v[3] = {&c.position, &c.look_at, &c.up};
    std::vector<double>* out[3] = {&pos, &look, &up};
    for (int k = 0; k < 3; ++k) {
      (*out[k])[3 * i] = v[k]->x;
      (*out[k])[3 * i + 1] = v[k]->y;
      (*out[k])[3 * i + 2] = v[k]->z;
    }
  }
  j["cameras"] = {{"count", n}, {"lat_deg", lat}, {"lon_deg", lon}, {"shell", shell},
                  {"position", pos}, {"look_at", look}, {"up", up}};
  json graph = json::array();
  for (const auto& g : m.graph.neighbours) graph.push_back({g.left, g.right, g.up, g.down, g.in, g.out});
  j["graph"] = std::move(graph);
  return j;
}

nlohmann::json fragment_index_json(const FragmentIndex& index) {
  nlohmann::json fragments = nlohmann::json::array();
  for (const auto& f : index.fragments) fragments.push_back({f.offset, f.size, f.first_frame, f.frames});
  return {{"file_size", index.file_size}, {"init_size", index.init_size}, {"fragments", std::move(fragments)}};
}

std::string database_file_url(const std::filesystem::path& db_dir, const std::filesystem::path& file) {
  const std::filesystem::path relative = file.lexically_normal().lexically_relative(db_dir.lexically_normal());
  if (relative.empty() || relative.begin()->string() == "..")
    throw Error(file.string() + ": not inside the database directory " + db_dir.string());
  return "db/" + relative.generic_string();
}

nlohmann::json packed_index_json(const store::PackedStream& stream, const std::filesystem::path& db_dir) {
  using nlohmann::json;
  json files = json::array(), fragments = json::array();
  // Usually one pack (the camera's in its only segment); a resumed database adds one per segment.
  std::map<std::filesystem::path, int> number;
  const auto file_number = [&](const std::filesystem::path& p) {
    const auto [it, added] = number.emplace(p, int(number.size()));
    if (added) files.push_back(database_file_url(db_dir, p));
    return it->second;
  };
  json init = json::array();
  for (std::size_t k = 0; k < stream.pieces.size(); ++k) {
    const auto& p = stream.pieces[k];
    const int file = file_number(p.file);
    if (k == 0) {
      init = {file, p.offset, p.size};
    } else {
      fragments.push_back({p.offset, p.size, p.first_frame, p.frames, file});
    }
  }
  json j = {{"files", std::move(files)}, {"init", std::move(init)}, {"fragments", std::move(fragments)}};
  if (!stream.pieces.empty()) j["init_size"] = stream.pieces.front().size;
  return j;
}

}  // namespace panoptes::web
