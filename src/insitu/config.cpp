#include "insitu/config.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <bit>
#include <climits>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "camera/rig_spec.hpp"
#include "core/error.hpp"
#include "core/file_read.hpp"
#include "core/toml_keys.hpp"
#include "insitu/task_plan.hpp"

namespace panoptes::insitu {

namespace {

using Ctx = toml_keys::Source;
using toml_keys::boolean;
using toml_keys::int_in;
using toml_keys::integer;
using toml_keys::only_keys;
using toml_keys::str;

const toml::table* table(const Ctx& c, const toml::table& t, const std::string& key) {
  const auto* n = t.get(key);
  if (!n) return nullptr;
  if (!n->is_table()) c.fail(key, "expected a table [" + key + "]");
  return n->as_table();
}

using toml_keys::colour;
using toml_keys::num;
using toml_keys::numbers;

}  // namespace

const char* to_string(OutputMode mode) {
  switch (mode) {
    case OutputMode::create: return "create";
    case OutputMode::overwrite: return "overwrite";
    case OutputMode::resume: return "resume";
  }
  return "create";
}

OutputMode parse_output_mode(const std::string& text) {
  for (OutputMode m : {OutputMode::create, OutputMode::overwrite, OutputMode::resume})
    if (text == to_string(m)) return m;
  throw Error("[output] mode = \"" + text + "\": expected \"create\", \"overwrite\" or \"resume\"");
}

const char* to_string(RenderSplit split) {
  switch (split) {
    case RenderSplit::automatic: return "auto";
    case RenderSplit::cameras: return "cameras";
    case RenderSplit::bricks: return "bricks";
  }
  return "auto";
}

RenderSplit parse_render_split(const std::string& text) {
  for (RenderSplit m : {RenderSplit::automatic, RenderSplit::cameras, RenderSplit::bricks})
    if (text == to_string(m)) return m;
  throw Error("[resources] parallel = \"" + text + "\": expected \"auto\", \"cameras\" or \"bricks\"");
}

const char* to_string(ReferenceMode mode) {
  switch (mode) {
    case ReferenceMode::snapshot: return "snapshot";
    case ReferenceMode::running: return "running";
    case ReferenceMode::fixed: return "fixed";
  }
  return "running";
}

ReferenceMode parse_reference_mode(const std::string& text, const std::string& key) {
  for (ReferenceMode m : {ReferenceMode::snapshot, ReferenceMode::running, ReferenceMode::fixed})
    if (text == to_string(m)) return m;
  if (text == "running-max") return ReferenceMode::running;  // the word before issue 41
  throw Error(key + " = \"" + text + "\": expected \"snapshot\", \"running\" or \"fixed\"");
}

FieldScale SessionConfig::scale_of(const std::string& field) const {
  const auto it = field_scales.find(field);
  return it != field_scales.end() ? it->second : FieldScale{reference, 0};
}

void SessionConfig::validate() const {
  if (output_dir.empty()) throw Error("output.dir: must not be empty");
  if (width < 2 || height < 2 || width > kMaxImageSide || height > kMaxImageSide)
    throw Error("image.width/height: " + std::to_string(width) + "x" + std::to_string(height) +
                "; expected 2.." + std::to_string(kMaxImageSide) + " pixels each");
  (void)camera::RigSpec::parse(rig);  // throws naming the text
  (void)camera::parse_projection(projection);
  if (tasks.empty()) throw Error("task: no [[task]] given; at least one visualization task is required");
  std::set<std::string> names;
  for (const TaskConfig& t : tasks) {
    if (!names.insert(t.name).second) throw Error("task \"" + t.name + "\": the name is used twice");
    // Configurations built in code (C API, Python) skip parse_task_table's checks: an empty sweep
    // would render nothing.
    if (planned_task_count(t) == 0) throw Error("task \"" + t.name + "\": no isovalue, window or slice position");
  }
  if ((schedule.every_steps > 0) == (schedule.every_time > 0))
    throw Error("schedule: give exactly one of every_steps (> 0) or every_time (> 0)");
  if (schedule.every_time < 0 || !std::isfinite(schedule.every_time))
    throw Error("schedule.every_time: expected a finite number > 0");
  if (!(mpi_timeout >= 0.1 && mpi_timeout <= 86400))
    throw Error("resources.mpi_timeout: " + std::to_string(mpi_timeout) + "; expected 0.1 .. 86400 seconds");
  if (schedule.max_snapshots < 0) throw Error("schedule.max_snapshots: expected 0 (unlimited) or more");
  if (!(percentile > 0 && percentile <= 1)) throw Error("render.percentile: expected a value in (0, 1]");
  if (reference == ReferenceMode::fixed)
    throw Error("render.reference = \"fixed\" needs a physical value per field: give it as [render.field.NAME] "
                "reference = \"fixed\", value = V (the other fields keep \"running\" or \"snapshot\")");
  for (const auto& [name, fs] : field_scales)
    if (fs.mode == ReferenceMode::fixed && !(std::isfinite(fs.value) && fs.value > 0))
      throw Error("render.field." + name + ".value: " + std::to_string(fs.value) +
                  "; a fixed reference needs a finite value > 0 in the field's units");
  if (!(render.sample_distance >= 0.01 && render.sample_distance <= 16))
    throw Error("render.sample_distance: " + std::to_string(render.sample_distance) + "; expected 0.01..16 voxels");
  video.validate();
}

SessionConfig parse_session_config(const toml::table& root, const std::string& source,
                                   const std::vector<std::string>& foreign_sections) {
  const Ctx c{source};
  std::set<std::string> allowed{"output", "image", "rig", "schedule", "video", "render", "task", "resources"};
  for (const auto& f : foreign_sections) allowed.insert(f);
  only_keys(c, root, "", allowed);
  SessionConfig s;
  if (const auto* o = table(c, root, "output")) {
    only_keys(c, *o, "output", {"dir", "mode", "overwrite", "resume_complete", "keep_interrupted", "layout", "title", "units", "time_units", "field_units"});
    s.output_dir = str(c, *o, "dir", "output.", s.output_dir);
    // `overwrite = true/false` is the key's old spelling: it still means mode "overwrite"/"create".
    if (o->get("mode") && o->get("overwrite"))
      c.fail("output.overwrite", "give only [output] mode (\"create\", \"overwrite\" or \"resume\"); overwrite is its "
                                 "old spelling");
    if (o->get("overwrite"))
      s.mode = boolean(c, *o, "overwrite", "output.", false) ? OutputMode::overwrite : OutputMode::create;
    if (o->get("mode")) {
      const std::string m = str(c, *o, "mode", "output.", "create");
      try {
        s.mode = parse_output_mode(m);
      } catch (const Error&) {
        c.fail("output.mode", "\"" + m + "\"; expected \"create\", \"overwrite\" or \"resume\"");
      }
    }
    s.resume_complete = boolean(c, *o, "resume_complete", "output.", false);
    s.keep_interrupted = boolean(c, *o, "keep_interrupted", "output.", true);
    s.layout = str(c, *o, "layout", "output.", "auto");
    if (s.layout != "auto" && s.layout != "files" && s.layout != "packed")
      c.fail("output.layout", "\"" + s.layout + "\"; expected \"auto\", \"files\" or \"packed\"");
    s.title = str(c, *o, "title", "output.", s.title);
    s.units = str(c, *o, "units", "output.", "");
    s.time_units = str(c, *o, "time_units", "output.", "");
    if (const auto* fu = table(c, *o, "field_units"))
      for (const auto& [name, value] : *fu) {
        const auto* text = value.as_string();
        if (!text) c.fail("output.field_units." + std::string(name.str()), "expected a string (the unit, e.g. \"1/s\")");
        s.field_units[std::string(name.str())] = text->get();
      }
  }
  if (const auto* im = table(c, root, "image")) {
    only_keys(c, *im, "image", {"width", "height", "background", "outline", "compass"});
    s.width = int_in(c, *im, "width", "image.", s.width, INT_MIN, INT_MAX);
    s.height = int_in(c, *im, "height", "image.", s.height, INT_MIN, INT_MAX);
    if (s.width < 2 || s.height < 2 || s.width > kMaxImageSide || s.height > kMaxImageSide)
      c.fail("image.width/height", std::to_string(s.width) + "x" + std::to_string(s.height) +
                                       " pixels; expected 2.." + std::to_string(kMaxImageSide) + " each");
    if (const auto* bg = im->get("background")) s.background = colour(c, *bg, "image.background");
    s.outline = boolean(c, *im, "outline", "image.", true);
    s.compass = boolean(c, *im, "compass", "image.", true);
  }
  if (const auto* r = table(c, root, "rig")) {
    only_keys(c, *r, "rig", {"spec", "up", "up_axis", "projection"});
    s.projection = str(c, *r, "projection", "rig.", s.projection);
    try {
      (void)camera::parse_projection(s.projection);
    } catch (const std::exception& e) {
      c.fail("rig.projection", e.what());
    }
    s.up_axis = str(c, *r, "up_axis", "rig.", s.up_axis);
    try {
      if (!s.up_axis.empty()) (void)camera::parse_up_axis(s.up_axis);
    } catch (const std::exception& e) {
      c.fail("rig.up_axis", e.what());
    }
    s.rig = str(c, *r, "spec", "rig.", s.rig);
    if (const auto* up = r->get("up")) {
      const auto v = numbers(c, *up, "rig.up");
      if (v.size() != 3 || v[0] * v[0] + v[1] * v[1] + v[2] * v[2] == 0) c.fail("rig.up", "expected a non-zero [x, y, z]");
      s.up = {v[0], v[1], v[2]};
    }
    try {
      (void)camera::RigSpec::parse(s.rig);
    } catch (const std::exception& e) {
      c.fail("rig.spec", e.what());
    }
  }
  if (const auto* sc = table(c, root, "schedule")) {
    only_keys(c, *sc, "schedule", {"every_steps", "every_time", "max_snapshots"});
    const bool has_time = sc->get("every_time") != nullptr;
    s.schedule.every_steps = integer(c, *sc, "every_steps", "schedule.", has_time ? 0 : s.schedule.every_steps);
    s.schedule.every_time = num(c, *sc, "every_time", "schedule.", 0);
    s.schedule.max_snapshots = int_in(c, *sc, "max_snapshots", "schedule.", 0, 0, INT_MAX);
    if (s.schedule.every_steps < 0) c.fail("schedule.every_steps", "expected an integer > 0");
    if (s.schedule.every_time < 0) c.fail("schedule.every_time", "expected a time > 0");
    if ((s.schedule.every_steps > 0) == (s.schedule.every_time > 0))
      c.fail("schedule", "give exactly one of every_steps (> 0) or every_time (> 0)");
    if (s.schedule.max_snapshots < 0) c.fail("schedule.max_snapshots", "expected 0 (unlimited) or more");
  }
  if (const auto* v = table(c, root, "video")) {
    only_keys(c, *v, "video", {"crf", "preset", "gop", "threads", "fps", "playback_fps"});
    s.playback_fps = num(c, *v, "playback_fps", "video.", 0);
    if (!(s.playback_fps == 0 || (s.playback_fps > 0 && s.playback_fps <= 1000)))
      c.fail("video.playback_fps", "expected 0 (none) or a rate in (0, 1000] frames per second");
    s.video.crf = int_in(c, *v, "crf", "video.", s.video.crf, 0, 51);
    s.video.preset = str(c, *v, "preset", "video.", s.video.preset);
    s.video.gop = int_in(c, *v, "gop", "video.", s.video.gop, 1, INT_MAX);
    s.video.threads = int_in(c, *v, "threads", "video.", s.video.threads, 0, 1024);
    s.video.fps = num(c, *v, "fps", "video.", s.video.fps);
    try {
      s.video.validate();
    } catch (const std::exception& e) {
      c.fail("video", e.what());
    }
  }
  if (const auto* r = table(c, root, "render")) {
    only_keys(c, *r, "render", {"sample_distance", "percentile", "reference", "skip_empty", "termination_alpha", "adaptive",
                                      "adaptive_stride", "adaptive_tolerance", "adaptive_linear_tolerance", "equirect_adaptive", "equirect_tolerance",
                                      "iso_antialias", "field", "share_scale"});
    const std::string ref = str(c, *r, "reference", "render.", "running");
    if (ref == "fixed") c.fail("render.reference", "\"fixed\" needs a value per field: [render.field.NAME] reference = \"fixed\", value = V");
    try {
      s.reference = parse_reference_mode(ref, "render.reference");
    } catch (const Error&) {
      c.fail("render.reference", "\"" + ref + "\"; expected \"snapshot\", \"running\" or \"fixed\" (per field)");
    }
    const std::string share = str(c, *r, "share_scale", "render.", "units");
    if (share != "units" && share != "none")
      c.fail("render.share_scale", "\"" + share + "\"; expected \"units\" (two-field pictures share one reference when their units agree) or \"none\"");
    s.share_scale = share == "none" ? ScaleSharing::none : ScaleSharing::units;
    if (const auto* fields = table(c, *r, "field"))
      for (const auto& [key, node] : *fields) {
        const std::string name(key.str()), where = "render.field." + name;
        const auto* ft = node.as_table();
        if (!ft) c.fail(where, "expected a table [render.field." + name + "] with reference and value");
        only_keys(c, *ft, where, {"reference", "value"});
        FieldScale fs;
        const std::string mode = str(c, *ft, "reference", where + ".", to_string(s.reference));
        try {
          fs.mode = parse_reference_mode(mode, where + ".reference");
        } catch (const Error&) {
          c.fail(where + ".reference", "\"" + mode + "\"; expected \"snapshot\", \"running\" or \"fixed\"");
        }
        fs.value = num(c, *ft, "value", where + ".", 0);
        if (fs.mode == ReferenceMode::fixed && !(std::isfinite(fs.value) && fs.value > 0))
          c.fail(where + ".value", "a fixed reference needs a finite value > 0 in the field's units");
        if (fs.mode != ReferenceMode::fixed && ft->get("value"))
          c.fail(where + ".value", "only a fixed reference takes a value (reference = \"" + mode + "\")");
        s.field_scales[name] = fs;
      }
    s.render.sample_distance = num(c, *r, "sample_distance", "render.", s.render.sample_distance);
    if (!(s.render.sample_distance >= 0.01 && s.render.sample_distance <= 16))
      c.fail("render.sample_distance", "expected 0.01..16 voxels");
    s.percentile = num(c, *r, "percentile", "render.", s.percentile);
    if (!(s.percentile > 0 && s.percentile <= 1)) c.fail("render.percentile", "expected a value in (0, 1]");
    s.render.skip_empty = boolean(c, *r, "skip_empty", "render.", true);
    s.render.termination_alpha = float(num(c, *r, "termination_alpha", "render.", s.render.termination_alpha));
    if (!(s.render.termination_alpha > 0.5f && s.render.termination_alpha <= 1.0f))
      c.fail("render.termination_alpha", "expected a value in (0.5, 1]");
    s.render.adaptive = boolean(c, *r, "adaptive", "render.", s.render.adaptive);
    s.render.equirect_adaptive = boolean(c, *r, "equirect_adaptive", "render.", true);
    // The coarse lattice's spacing: where a voxel covers several pixels (the demo: 3.5-4 px per voxel at
    // 528x512) a wider lattice still samples every voxel's change; refinement halves it where corners differ.
    s.render.adaptive_stride = int_in(c, *r, "adaptive_stride", "render.", s.render.adaptive_stride, 2, 32);
    if (!std::has_single_bit(unsigned(s.render.adaptive_stride)))
      c.fail("render.adaptive_stride", std::to_string(s.render.adaptive_stride) + "; expected 2, 4, 8, 16 or 32 pixels (cells are split at their midpoints)");
    // In the final image's units (1/255) in the file: what users see.
    const double tol = num(c, *r, "adaptive_tolerance", "render.", double(s.render.adaptive_tolerance) * 255);
    if (!(tol >= 0 && tol <= 255)) c.fail("render.adaptive_tolerance", "expected 0..255 (units of 1/255)");
    s.render.adaptive_tolerance = float(tol / 255);
    const double lin = num(c, *r, "adaptive_linear_tolerance", "render.", double(s.render.adaptive_linear_tolerance) * 255);
    if (!(lin >= 0 && lin <= 255)) c.fail("render.adaptive_linear_tolerance", "expected 0..255 (units of 1/255)");
    s.render.adaptive_linear_tolerance = float(lin / 255);
    // 360° frames have their own: from inside a dense field 4/255 refined a third of the pixels to single
    // ones for 59 dB, 10/255 marches 15 % at 50 dB (docs/rendering.md, Round 12).
    const double eq_tol = num(c, *r, "equirect_tolerance", "render.", double(s.render.equirect_tolerance) * 255);
    if (!(eq_tol >= 0 && eq_tol <= 255)) c.fail("render.equirect_tolerance", "expected 0..255 (units of 1/255)");
    s.render.equirect_tolerance = float(eq_tol / 255);
    s.render.iso_antialias = boolean(c, *r, "iso_antialias", "render.", true);
  }
  if (const auto* r = table(c, root, "resources")) {
    only_keys(c, *r, "resources", {"check_memory", "mpi_timeout", "parallel"});
    s.check_memory = boolean(c, *r, "check_memory", "resources.", true);
    s.mpi_timeout = num(c, *r, "mpi_timeout", "resources.", s.mpi_timeout);
    const std::string split = str(c, *r, "parallel", "resources.", to_string(s.parallel));
    try {
      s.parallel = parse_render_split(split);
    } catch (const Error&) {
      c.fail("resources.parallel", "\"" + split + "\"; expected \"auto\", \"cameras\" or \"bricks\"");
    }
  }
  if (const auto* t = root.get("task")) {
    const auto* a = t->as_array();
    if (!a) c.fail("task", "expected an array of tables [[task]]");
    for (std::size_t i = 0; i < a->size(); ++i) {
      const auto* tt = a->get(i)->as_table();
      if (!tt) c.fail("task[" + std::to_string(i) + "]", "expected a table [[task]]");
      s.tasks.push_back(parse_task_table(c, *tt, i));
    }
  }
  if (s.tasks.empty()) c.fail("task", "no [[task]] given; at least one visualization task is required");
  std::set<std::string> names;
  for (const auto& t : s.tasks)
    if (!names.insert(t.name).second) c.fail("task", "the name \"" + t.name + "\" is used twice");
  return s;
}

SessionConfig parse_session_config_text(const std::string& text, const std::string& source,
                                        const std::vector<std::string>& foreign_sections) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream s;
    s << source << ": TOML syntax error at line " << e.source().begin.line << ": " << e.description();
    throw Error(s.str());
  }
  return parse_session_config(root, source, foreign_sections);
}

SessionConfig parse_combined_config(const std::string& text, const std::string& source,
                                    const std::vector<std::string>& foreign_sections, std::string& foreign_text) {
  toml::table root;
  try {
    root = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream s;
    s << source << ": TOML syntax error at line " << e.source().begin.line << ": " << e.description();
    throw Error(s.str());
  }
  toml::table foreign;
  for (const auto& [k, v] : root)
    if (std::find(foreign_sections.begin(), foreign_sections.end(), std::string(k.str())) != foreign_sections.end())
      foreign.insert(k, v);
  std::ostringstream out;
  out << foreign;
  foreign_text = out.str();
  return parse_session_config(root, source, foreign_sections);
}

SessionConfig load_session_config(const std::string& path, const std::vector<std::string>& foreign_sections) {
  return parse_session_config_text(read_regular_file(path, kMaxConfigBytes, "configuration file"), path, foreign_sections);
}

const char* config_keys_help() {
  // The [[task]] part comes from the task plan, which holds each kind's keys (one list of kinds).
  static const std::string text = std::string(R"(IN-SITU CONFIGURATION (TOML). Unknown keys, wrong types and impossible values are errors.
[output]    dir = "panoptes_out" (database directory); title = "in-situ visualization";
            units = "" (length unit of the grid); time_units = "" (unit of the snapshot times, e.g. "s");
            field_units = {} (unit of each field's values, e.g. { phi_p = "1/s" }: the players' colour legends);
            mode = "create" (refuse a directory that holds a database) | "overwrite" (replace it; an
            interrupted one is kept beside as DIR.interrupted-N unless keep_interrupted = false) |
            "resume" (continue it after a checkpoint restart: its snapshots stay, snapshots repeated by
            the restarted run (time <= the last written time) are skipped, the movies go on; rig, tasks,
            grid, image, video settings and schedule must be the ones it was written with; a complete
            database is refused unless resume_complete = true, which appends to the finished run);
            overwrite = true | false is the old spelling of mode = "overwrite" | "create";
            layout = "auto" (packed from 1024 streams at gop 1, else files) | "files" (one movie file per
            stream) | "packed" (per rank and run segment one pack file + index: bounded file count)
[image]     width = 920, height = 896 (pixels); background = [0, 0, 0]; outline = true (domain box);
            compass = true (360-degree frames: horizon, a tick every 45 degrees, N/E/S/W)
[rig]       spec = "yinyang" (yinyang[:NTxNP] | latlon[:NLATxNLON[+poles]] | fibonacci[:N] | file:PATH,
            optional @R1,R2,... shell radii in bounding-sphere radii; default 130 Yin-Yang cameras at 3 R);
            up_axis = "z_up" | "z_down" (which way is the sky: poles, latitudes, the cameras' up and the
            player's Up key follow it; `panoptes run` and `panoptes demo` use "z_down", as z is depth);
            up = [x, y, z] (world direction shown upwards in the images; default: the sky);
            spec = "lattice:NXxNYxNZ[@MARGIN]" | "path:FILE" put the cameras inside the volume (lattice nodes
            at cell centres of the domain shrunk by MARGIN at each face; world-axis navigation);
            projection = "perspective" | "equirectangular" (360 x 180 degree frames, e.g. 1920 x 960, for
            looking around in the player; the domain outline is drawn as arcs)
[schedule]  every_steps = 10 | every_time = DT (exactly one); max_snapshots = 0 (unlimited)
[video]     crf = 20, preset = "superfast", gop = 1, threads = 1, fps = 30 (H.264 in fragmented MP4);
            playback_fps = 0 (the player's preferred rate; 0 = fps)
[render]    sample_distance = 0.5 (voxels); percentile = 0.999 (quantile of |field| over the whole grid:
            the reference "ref" of relative windows); reference = "running" (the largest reference so
            far: colours mean the same in every frame, a decaying wave darkens) | "snapshot" (each
            snapshot's own quantile: every frame fills the colour map, brightness is not comparable);
            [render.field.NAME] reference = "fixed", value = V (a physical reference in the field's
            units); share_scale = "units" (two-field pictures of fields with the same unit on one scale)
            | "none"; skip_empty = true; termination_alpha = 0.998;
            adaptive = true (image-space adaptive sampling: march every 4th pixel, interpolate where the
            corners agree within adaptive_tolerance = 4 (units of 1/255), refine elsewhere, and stop
            refining where the first split's new points lie within adaptive_linear_tolerance = 2 of
            the bilinear image of its corners, or a 4x4 cell's sub-cell centres within it of the
            biquadratic through its 3x3 points, 0 = never; false = march every pixel);
            equirect_adaptive = true (360° frames: that sampling on the sphere, a lattice about 1.5°
            apart whose columns widen toward the poles, whatever adaptive says; false = every pixel);
            equirect_tolerance = 11 (360° frames: the largest corner range interpolated, units of 1/255)
            iso_antialias = true (isosurface silhouettes get partial coverage from rays that graze or
            nearly miss them: no stair steps; false = every pixel hit or missed, as before)
[resources] check_memory = true (refuse to start when a rank's estimated memory exceeds what it has
            available: MemAvailable or the cgroup limit; false = panoptes run --force);
            mpi_timeout = 120 (seconds a rank waits in a Panoptes call for the other ranks before every
            waiting rank reports them missing: no job hangs inside Panoptes);
            parallel = "auto" (how ranks share the rendering: "cameras" = every rank gathers the whole
            grid's fields and renders its own cameras alone, no compositing; "bricks" = every rank
            renders its brick for every camera, composited sort-last; "auto" = cameras when the whole
            grid's fields take at most 256 MiB per rank and there are as many cameras as ranks)
)") + task_tables_help();
  return text.c_str();
}

}  // namespace panoptes::insitu
