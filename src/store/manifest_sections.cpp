#include "store/manifest_sections.hpp"
// Sections, in the manifest's order (each a write/read pair):
//   header        schema_version, format, title, status, frames_written, movie_pattern
//   provenance    provenance
//   domain        domain
//   playback      playback_fps
//   frame_checks  frame_checks
//   times         times, time_units
//   fields        fields
//   image         image
//   video         video
//   rig           rig
//   cameras       camera_table or cameras, navigation
//   axes          axes
//   tasks         tasks

#include <cmath>

namespace panoptes::store::manifest_sections {

namespace {

json vec3_json(const Vec3& v) { return json::array({v.x, v.y, v.z}); }

json labels_json(const std::map<std::string, std::string>& m) {
  json j = json::object();
  for (const auto& [k, v] : m) j[k] = v;
  return j;
}

}  // namespace

// --- header ---

void write_header(json& j, const Manifest& m) {
  // Always the current version: both forms (inline cameras or a table) are valid in it, and a manifest
  // read from a version-1 file is written back as version 2.
  j["schema_version"] = kSchemaVersion;
  j["format"] = "panoptes movie database";
  j["title"] = m.title;
  j["status"] = std::string(to_string(m.status));
  j["frames_written"] = m.frames_written;
  j["movie_pattern"] = m.movie_pattern;
}

void read_header(const Reader& r, const json& j, Manifest& m) {
  const std::string& source = r.source;
  {
    const auto it = j.find("schema_version");
    if (it == j.end()) r.fail("schema_version", "missing (not a Panoptes manifest?)");
    const std::int64_t v = r.integer(*it, "schema_version");
    if (v < kOldestSchemaVersion || v > kSchemaVersion)
      throw Error(source + ": schema_version " + std::to_string(v) + " is not supported (this build reads versions " +
                  std::to_string(kOldestSchemaVersion) + " to " + std::to_string(kSchemaVersion) + "; " +
                  (v > kSchemaVersion ? "written by a newer Panoptes" : "unknown version") + ")");
    m.schema_version = int(v);
  }
  m.title = r.opt_str(j, "title", "");
  m.status = [&] {
    const std::string s = r.str(r.field(j, "status", ""), "status");
    try {
      return parse_status(s);
    } catch (const Error& e) {
      r.fail("status", e.what());
    }
  }();
  m.frames_written = r.int32(r.field(j, "frames_written", ""), "frames_written");
  m.movie_pattern = r.str(r.field(j, "movie_pattern", ""), "movie_pattern");
}

// --- provenance ---

void write_provenance(json& j, const Manifest& m) {
  j["provenance"] = {{"program", m.provenance.program},
                     {"version", m.provenance.version},
                     {"created", m.provenance.created},
                     {"host", m.provenance.host},
                     {"command_line", m.provenance.command_line},
                     {"extra", labels_json(m.provenance.extra)}};
}

void read_provenance(const Reader& r, const json& j, Manifest& m) {
  if (const json* p = r.optional(j, "provenance", "")) {
    m.provenance.program = r.opt_str(*p, "program", "provenance");
    m.provenance.version = r.opt_str(*p, "version", "provenance");
    m.provenance.created = r.opt_str(*p, "created", "provenance");
    m.provenance.host = r.opt_str(*p, "host", "provenance");
    m.provenance.command_line = r.opt_str(*p, "command_line", "provenance");
    if (const json* e = r.optional(*p, "extra", "provenance")) m.provenance.extra = r.string_map(*e, "provenance.extra");
  }
}

// --- domain ---

void write_domain(json& j, const Manifest& m) {
  j["domain"] = {{"dims", m.domain.dims},
                 {"origin", vec3_json(m.domain.origin)},
                 {"spacing", vec3_json(m.domain.spacing)},
                 {"units", m.domain.units}};
  if (!m.domain.up_axis.empty()) j["domain"]["up_axis"] = m.domain.up_axis;
  if (!m.domain.grid.empty()) j["domain"]["grid"] = m.domain.grid;
}

void read_domain(const Reader& r, const json& j, Manifest& m) {
  if (const json* d = r.optional(j, "domain", "")) {
    if (const json* dims = r.optional(*d, "dims", "domain")) {
      if (!dims->is_array() || dims->size() != 3) r.fail("domain.dims", "expected an array of 3 integers");
      for (int i = 0; i < 3; ++i) m.domain.dims[std::size_t(i)] = r.integer((*dims)[std::size_t(i)], "domain.dims");
    }
    if (const json* o = r.optional(*d, "origin", "domain")) m.domain.origin = r.vec3(*o, "domain.origin");
    if (const json* s = r.optional(*d, "spacing", "domain")) m.domain.spacing = r.vec3(*s, "domain.spacing");
    m.domain.units = r.opt_str(*d, "units", "domain");
    m.domain.up_axis = r.opt_str(*d, "up_axis", "domain");
    m.domain.grid = r.opt_str(*d, "grid", "domain");
  }
}

// --- playback ---

void write_playback(json& j, const Manifest& m) {
  if (m.playback_fps > 0) j["playback_fps"] = m.playback_fps;
}

void read_playback(const Reader& r, const json& j, Manifest& m) {
  if (const json* v = r.optional(j, "playback_fps", "")) m.playback_fps = r.num(*v, "playback_fps");
}

// --- frame_checks ---

void write_frame_checks(json& j, const Manifest& m) {
  if (m.frame_checks.recorded())
    j["frame_checks"] = {{"scheme", m.frame_checks.scheme}, {"database_id", m.frame_checks.database_id}};
}

void read_frame_checks(const Reader& r, const json& j, Manifest& m) {
  if (const json* fc = r.optional(j, "frame_checks", "")) {
    m.frame_checks.scheme = r.str(r.field(*fc, "scheme", "frame_checks"), "frame_checks.scheme");
    m.frame_checks.database_id = r.str(r.field(*fc, "database_id", "frame_checks"), "frame_checks.database_id");
  }
}

// --- layout ---

void write_layout(json& j, const Manifest& m) {
  if (m.layout != Layout::packed) return;  // absent = files, as every database before it
  j["layout"] = "packed";
  json segs = json::array();
  for (const PackSegment& s : m.packs)
    segs.push_back({{"segment", s.segment}, {"first_frame", s.first_frame}, {"ranks", s.ranks}});
  j["packs"] = segs;
}

void read_layout(const Reader& r, const json& j, Manifest& m) {
  const std::string layout = r.opt_str(j, "layout", "");
  if (layout.empty() || layout == "files") {
    m.layout = Layout::files;
  } else if (layout == "packed") {
    m.layout = Layout::packed;
  } else {
    r.fail("layout", "\"" + layout.substr(0, 64) + "\" is not a layout this build reads (files, packed)");
  }
  if (const json* p = r.optional(j, "packs", "")) {
    if (!p->is_array()) r.fail("packs", "expected an array of segments");
    if (p->size() > 100000) r.fail("packs", "lists " + std::to_string(p->size()) + " segments (at most 100000)");
    for (std::size_t i = 0; i < p->size(); ++i) {
      const std::string path = "packs[" + std::to_string(i) + "]";
      const json& e = (*p)[i];
      if (!e.is_object()) r.fail(path, "expected an object");
      PackSegment s;
      const std::int64_t seg = r.integer(r.field(e, "segment", path), path + ".segment");
      const std::int64_t first = r.integer(r.field(e, "first_frame", path), path + ".first_frame");
      const std::int64_t ranks = r.integer(r.field(e, "ranks", path), path + ".ranks");
      if (seg < 0 || seg > 100000 || (!m.packs.empty() && seg <= m.packs.back().segment))
        r.fail(path + ".segment", std::to_string(seg) + "; expected ascending segment numbers in 0..100000");
      if (first < 0 || first > INT32_MAX || (!m.packs.empty() && first < m.packs.back().first_frame))
        r.fail(path + ".first_frame", std::to_string(first) + "; expected non-decreasing frame numbers >= 0");
      if (ranks < 1 || ranks > 1000000) r.fail(path + ".ranks", std::to_string(ranks) + "; expected 1..1000000");
      s.segment = int(seg);
      s.first_frame = int(first);
      s.ranks = int(ranks);
      m.packs.push_back(s);
    }
  }
  if (m.layout == Layout::packed && m.packs.empty()) r.fail("packs", "a packed database must list its segments");
}

// --- times ---

void write_times(json& j, const Manifest& m) {
  j["times"] = m.times;
  // Additive (issue 34): older readers ignore them, and manifests without them stay readable.
  if (!m.time_units.empty()) j["time_units"] = m.time_units;
}

void read_times(const Reader& r, const json& j, Manifest& m) {
  if (const json* t = r.optional(j, "times", "")) {
    r.array(*t, "times");
    m.times.reserve(t->size());
    for (std::size_t i = 0; i < t->size(); ++i) m.times.push_back(r.num((*t)[i], "times[" + std::to_string(i) + "]"));
  }
  m.time_units = r.opt_str(j, "time_units", "");
}

// --- fields ---

void write_fields(json& j, const Manifest& m) {
  if (!m.fields.empty()) {
    json fields = json::array();
    for (const auto& f : m.fields) {
      json e = {{"name", f.name}, {"units", f.units}, {"references", f.references}};
      if (!f.reference_mode.empty()) e["reference_mode"] = f.reference_mode;
      fields.push_back(std::move(e));
    }
    j["fields"] = std::move(fields);
  }
}

void read_fields(const Reader& r, const json& j, Manifest& m) {
  if (const json* fs = r.optional(j, "fields", "")) {
    r.array(*fs, "fields");
    for (std::size_t i = 0; i < fs->size(); ++i) {
      const std::string at = "fields[" + std::to_string(i) + "]";
      const json& f = (*fs)[i];
      FieldInfo info;
      info.name = r.str(r.field(f, "name", at), at + ".name");
      info.units = r.opt_str(f, "units", at);
      info.reference_mode = r.opt_str(f, "reference_mode", at);
      if (!info.reference_mode.empty() && info.reference_mode != "snapshot" && info.reference_mode != "running" &&
          info.reference_mode != "fixed")
        r.fail(at + ".reference_mode", "\"" + info.reference_mode + "\"; expected \"snapshot\", \"running\" or \"fixed\"");
      if (const json* refs = r.optional(f, "references", at)) {
        r.array(*refs, at + ".references");
        info.references.reserve(refs->size());
        for (std::size_t k = 0; k < refs->size(); ++k)
          info.references.push_back(r.num((*refs)[k], at + ".references[" + std::to_string(k) + "]"));
      }
      m.fields.push_back(std::move(info));
    }
  }
}

// --- image ---

void write_image(json& j, const Manifest& m) {
  j["image"] = {{"width", m.image.width},
                {"height", m.image.height},
                {"padded_width", m.image.padded_width},
                {"padded_height", m.image.padded_height}};
}

void read_image(const Reader& r, const json& j, Manifest& m) {
  {
    const json& im = r.field(j, "image", "");
    m.image.width = r.int32(r.field(im, "width", "image"), "image.width");
    m.image.height = r.int32(r.field(im, "height", "image"), "image.height");
    if (const json* v = r.optional(im, "padded_width", "image")) m.image.padded_width = r.int32(*v, "image.padded_width");
    if (const json* v = r.optional(im, "padded_height", "image")) m.image.padded_height = r.int32(*v, "image.padded_height");
  }
}

// --- video ---

void write_video(json& j, const Manifest& m) {
  j["video"] = {{"codec", "h264"},
                {"container", "fragmented mp4"},
                {"crf", m.video.crf},
                {"preset", m.video.preset},
                {"gop", m.video.gop},
                {"threads", m.video.threads},
                {"fps", m.video.fps}};
}

void read_video(const Reader& r, const json& j, Manifest& m) {
  if (const json* v = r.optional(j, "video", "")) {
    if (const json* x = r.optional(*v, "codec", "video"); x && r.str(*x, "video.codec") != "h264")
      r.fail("video.codec", "\"" + x->get<std::string>() + "\" is not supported (expected \"h264\")");
    if (const json* x = r.optional(*v, "crf", "video")) m.video.crf = r.int32(*x, "video.crf");
    if (const json* x = r.optional(*v, "preset", "video")) m.video.preset = r.str(*x, "video.preset");
    if (const json* x = r.optional(*v, "gop", "video")) m.video.gop = r.int32(*x, "video.gop");
    if (const json* x = r.optional(*v, "threads", "video")) m.video.threads = r.int32(*x, "video.threads");
    if (const json* x = r.optional(*v, "fps", "video")) m.video.fps = r.num(*x, "video.fps");
  }
}

// --- rig ---

void write_rig(json& j, const Manifest& m) {
  j["rig"] = {{"kind", m.rig.kind}, {"parameters", m.rig.parameters}};
}

void read_rig(const Reader& r, const json& j, Manifest& m) {
  if (const json* rig = r.optional(j, "rig", "")) {
    m.rig.kind = r.opt_str(*rig, "kind", "rig");
    if (const json* p = r.optional(*rig, "parameters", "rig")) {
      if (!p->is_object()) r.fail("rig.parameters", "expected a JSON object");
      m.rig.parameters = *p;
    }
  }
}

// --- cameras ---

void write_cameras(json& j, const Manifest& m, const CameraTableRef* table) {
  const json columns = json::array({"left", "right", "up", "down", "in", "out"});
  if (table) {
    j["camera_table"] = {{"file", table->file},
                         {"format", "panoptes camera table " + std::to_string(kCameraTableVersion)},
                         {"bytes", table->bytes},
                         {"crc32", table->crc32},
                         {"cameras", table->cameras},
                         {"navigation", table->navigation}};
    j["navigation"] = {{"columns", columns}};
  } else {
  json cams = json::array();
  for (const auto& c : m.cameras) {
    json labels = {{"patch", c.labels.patch}, {"lat_deg", c.labels.lat_deg}, {"lon_deg", c.labels.lon_deg},
                   {"shell", c.labels.shell}};
    if (!c.labels.extra.empty()) labels["extra"] = labels_json(c.labels.extra);
    cams.push_back({{"id", c.id},
                    {"position", vec3_json(c.position)},
                    {"look_at", vec3_json(c.look_at)},
                    {"up", vec3_json(c.up)},
                    {"fov_y_deg", c.fov_y_deg},
                    {"labels", std::move(labels)}});
  }
  j["cameras"] = std::move(cams);
  // One compact row per camera keeps the graph small for 10^5 cameras.
  json rows = json::array();
  for (const auto& g : m.graph.neighbours) rows.push_back(json::array({g.left, g.right, g.up, g.down, g.in, g.out}));
  j["navigation"] = {{"columns", columns}, {"neighbours", std::move(rows)}};
  }
}

std::optional<CameraTableRef> read_cameras(const Reader& r, const json& j, Manifest& m, const std::filesystem::path& dir) {
  // Schema 2: the cameras and the graph are in the binary camera table (read after the JSON checks);
  // inline cameras as in schema 1 are still accepted (hand-written and old manifests).
  std::optional<CameraTableRef> table;
  if (const json* t = r.optional(j, "camera_table", "")) {
    if (m.schema_version < 2) r.fail("camera_table", "is not part of schema_version 1");
    if (j.contains("cameras")) r.fail("cameras", "present although the cameras are in camera_table (one or the other)");
    CameraTableRef ref;
    ref.file = r.str(r.field(*t, "file", "camera_table"), "camera_table.file");
    try {
      validate_camera_table_name(ref.file);
    } catch (const Error& e) {
      r.fail("camera_table.file", e.what());
    }
    const std::int64_t bytes = r.integer(r.field(*t, "bytes", "camera_table"), "camera_table.bytes");
    const std::int64_t crc = r.integer(r.field(*t, "crc32", "camera_table"), "camera_table.crc32");
    ref.cameras = r.integer(r.field(*t, "cameras", "camera_table"), "camera_table.cameras");
    if (bytes < 0) r.fail("camera_table.bytes", std::to_string(bytes) + " is negative");
    if (crc < 0 || crc > INT64_C(0xFFFFFFFF)) r.fail("camera_table.crc32", std::to_string(crc) + " is not a 32-bit value");
    if (ref.cameras < 0 || ref.cameras > kMaxCameras)
      r.fail("camera_table.cameras", std::to_string(ref.cameras) + " is out of range (0.." + std::to_string(kMaxCameras) +
                                         " cameras; readers keep each camera in memory)");
    ref.bytes = std::uint64_t(bytes);
    ref.crc32 = std::uint32_t(crc);
    if (const json* nav = r.optional(*t, "navigation", "camera_table")) {
      if (!nav->is_boolean()) r.fail("camera_table.navigation", "expected true or false");
      ref.navigation = nav->get<bool>();
    }
    if (dir.empty()) r.fail("camera_table", "refers to the file " + ref.file + ", but no database directory was given");
    table = ref;
  } else {
    const json& cams = r.array(r.field(j, "cameras", ""), "cameras");
    if (std::int64_t(cams.size()) > kMaxCameras)
      r.fail("cameras", std::to_string(cams.size()) + " cameras, more than the limit of " + std::to_string(kMaxCameras));
    m.cameras.resize(cams.size());
    for (std::size_t i = 0; i < cams.size(); ++i) {
      const json& c = cams[i];
      const std::string at = "cameras[" + std::to_string(i) + "]";
      auto& e = m.cameras[i];
      e.id = r.int32(r.field(c, "id", at), at + ".id");
      e.position = r.vec3(r.field(c, "position", at), at + ".position");
      e.look_at = r.vec3(r.field(c, "look_at", at), at + ".look_at");
      e.up = r.vec3(r.field(c, "up", at), at + ".up");
      e.fov_y_deg = r.num(r.field(c, "fov_y_deg", at), at + ".fov_y_deg");
      if (const json* l = r.optional(c, "labels", at)) {
        const std::string lat = at + ".labels";
        e.labels.patch = r.opt_str(*l, "patch", lat);
        if (const json* x = r.optional(*l, "lat_deg", lat)) e.labels.lat_deg = r.num(*x, lat + ".lat_deg");
        if (const json* x = r.optional(*l, "lon_deg", lat)) e.labels.lon_deg = r.num(*x, lat + ".lon_deg");
        if (const json* x = r.optional(*l, "shell", lat)) e.labels.shell = r.int32(*x, lat + ".shell");
        if (const json* x = r.optional(*l, "extra", lat)) e.labels.extra = r.string_map(*x, lat + ".extra");
      }
    }
  }
  if (const json* nav = r.optional(j, "navigation", "")) {
    static const char* kColumns[] = {"left", "right", "up", "down", "in", "out"};
    if (const json* cols = r.optional(*nav, "columns", "navigation")) {
      if (!cols->is_array() || cols->size() != 6) r.fail("navigation.columns", "expected [left,right,up,down,in,out]");
      for (std::size_t k = 0; k < 6; ++k)
        if ((*cols)[k] != kColumns[k]) r.fail("navigation.columns", "expected [left,right,up,down,in,out]");
    }
    if (const json* rows = r.optional(*nav, "neighbours", "navigation")) {
      if (table) r.fail("navigation.neighbours", "present although the graph is in camera_table (one or the other)");
      r.array(*rows, "navigation.neighbours");
      m.graph.neighbours.resize(rows->size());
      for (std::size_t i = 0; i < rows->size(); ++i) {
        const json& row = (*rows)[i];
        const std::string at = "navigation.neighbours[" + std::to_string(i) + "]";
        if (!row.is_array() || row.size() != 6) r.fail(at, "expected an array of 6 camera ids");
        auto& g = m.graph.neighbours[i];
        int* slots[] = {&g.left, &g.right, &g.up, &g.down, &g.in, &g.out};
        for (std::size_t k = 0; k < 6; ++k) *slots[k] = r.int32(row[k], at);
      }
    }
  }
  return table;
}

// --- axes ---

void write_axes(json& j, const Manifest& m) {
  json axes = json::array();
  for (const auto& a : m.axes) axes.push_back({{"name", a.name}, {"values", a.values}, {"units", a.units}});
  j["axes"] = std::move(axes);
}

void read_axes(const Reader& r, const json& j, Manifest& m) {
  if (const json* axes = r.optional(j, "axes", "")) {
    r.array(*axes, "axes");
    for (std::size_t i = 0; i < axes->size(); ++i) {
      const std::string at = "axes[" + std::to_string(i) + "]";
      const json& a = (*axes)[i];
      ParameterAxis axis;
      axis.name = r.str(r.field(a, "name", at), at + ".name");
      const json& values = r.array(r.field(a, "values", at), at + ".values");
      for (std::size_t k = 0; k < values.size(); ++k) axis.values.push_back(r.num(values[k], at + ".values"));
      axis.units = r.opt_str(a, "units", at);
      m.axes.push_back(std::move(axis));
    }
  }
}

// --- tasks ---

void write_tasks(json& j, const Manifest& m) {
  json tasks = json::array();
  for (const auto& t : m.tasks) {
    json pos = json::array();
    for (const auto& p : t.axes) pos.push_back({{"axis", p.axis}, {"index", p.index}});
    tasks.push_back({{"id", t.id},
                     {"name", t.name},
                     {"method", t.method},
                     {"fields", t.fields},
                     {"parameters", t.parameters},
                     {"axes", std::move(pos)}});
  }
  j["tasks"] = std::move(tasks);
}

void read_tasks(const Reader& r, const json& j, Manifest& m) {
  {
    const json& tasks = r.array(r.field(j, "tasks", ""), "tasks");
    m.tasks.resize(tasks.size());
    for (std::size_t i = 0; i < tasks.size(); ++i) {
      const json& t = tasks[i];
      const std::string at = "tasks[" + std::to_string(i) + "]";
      auto& e = m.tasks[i];
      e.id = r.int32(r.field(t, "id", at), at + ".id");
      e.name = r.str(r.field(t, "name", at), at + ".name");
      e.method = r.opt_str(t, "method", at);
      if (const json* f = r.optional(t, "fields", at)) {
        r.array(*f, at + ".fields");
        for (const auto& x : *f) e.fields.push_back(r.str(x, at + ".fields"));
      }
      if (const json* p = r.optional(t, "parameters", at)) {
        if (!p->is_object()) r.fail(at + ".parameters", "expected a JSON object");
        e.parameters = *p;
      }
      if (const json* pos = r.optional(t, "axes", at)) {
        r.array(*pos, at + ".axes");
        for (const auto& p : *pos)
          e.axes.push_back({r.str(r.field(p, "axis", at + ".axes"), at + ".axes.axis"),
                            r.int32(r.field(p, "index", at + ".axes"), at + ".axes.index")});
      }
    }
  }
}

}  // namespace panoptes::store::manifest_sections
