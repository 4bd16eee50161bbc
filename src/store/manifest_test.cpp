#include "store/manifest.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "core/error.hpp"
#include "store/test_support.hpp"

using namespace panoptes;
using namespace panoptes::store;
using panoptes::store::testing::sample_manifest;
using panoptes::store::testing::TempDir;
using nlohmann::json;

namespace {

// Runs f, expects an Error whose message contains every one of `parts`.
template <class F>
void expect_error(F f, std::initializer_list<std::string> parts) {
  try {
    f();
    ADD_FAILURE() << "no error thrown";
  } catch (const Error& e) {
    for (const auto& p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << "message: " << e.what() << "\nexpected: " << p;
  }
}

void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

}  // namespace

TEST(Manifest, SchemaRoundTripKeepsEveryField) {
  Manifest m = sample_manifest(7, 4, 63, 37);
  m.times = {0.0, 0.5, 1.25};
  m.status = Status::interrupted;
  m.frames_written = 3;
  m.image.padded_width = 64;
  m.image.padded_height = 38;
  m.video.preset = "medium";
  m.video.fps = 24;
  m.video.threads = 2;
  m.cameras[2].labels.extra = {{"note", "pole"}, {"shell_radius", "2.5"}};
  m.cameras[3].labels.shell = 1;
  m.graph.neighbours[1].in = 3;
  m.graph.neighbours[3].out = 1;
  m.axes.push_back({"window", {0.0, 0.25}, "normalized"});
  m.tasks[0].axes.push_back({"window", 1});
  m.tasks[0].parameters["nested"] = {{"a", json::array({1, 2, 3})}, {"b", "text"}};
  m.rig.parameters["yang_rotation"] = json::array({-1, 0, 0});
  m.movie_pattern = "m/{camera}-{task}.mp4";
  m.domain.up_axis = "z_down";
  m.playback_fps = 12.5;

  const json j = to_json(m);
  EXPECT_EQ(j.at("schema_version"), kSchemaVersion);
  const Manifest back = manifest_from_json(json::parse(j.dump()), "mem");
  EXPECT_EQ(to_json(back), j);
  EXPECT_EQ(back.cameras, m.cameras);
  EXPECT_EQ(back.tasks, m.tasks);
  EXPECT_EQ(back.graph, m.graph);
  EXPECT_EQ(back.axes, m.axes);
  EXPECT_EQ(back.provenance, m.provenance);
  EXPECT_EQ(back.domain, m.domain);
  EXPECT_EQ(back.image, m.image);
  EXPECT_EQ(back.times, m.times);
  EXPECT_EQ(back.status, Status::interrupted);
  EXPECT_EQ(back.video.preset, "medium");
  EXPECT_EQ(back.video.fps, 24);

  TempDir dir;
  write_manifest_atomic(dir / "panoptes.json", m);
  const Manifest from_file = read_manifest(dir / "panoptes.json");
  EXPECT_EQ(to_json(from_file), j);
  // No temp file is left behind: the manifest and its camera table only.
  int files = 0;
  for (auto& e : std::filesystem::directory_iterator(dir.path)) files += bool(e.is_regular_file());
  EXPECT_EQ(files, 2);
}

TEST(Manifest, OrientationAndPlaybackRateAreOptionalAndChecked) {
  // Older databases carry neither: they read as "" (z up) and 0 (the video's rate), and are written
  // back without the fields.
  Manifest m = sample_manifest(3, 2, 16, 16);
  json j = to_json(m);
  EXPECT_FALSE(j["domain"].contains("up_axis"));
  EXPECT_FALSE(j.contains("playback_fps"));
  Manifest back = manifest_from_json(j, "mem");
  EXPECT_EQ(back.domain.up_axis, "");
  EXPECT_EQ(back.domain.sky(), (Vec3{0, 0, 1}));
  EXPECT_EQ(back.playback_fps, 0);
  j["domain"]["up_axis"] = "z_down";
  j["playback_fps"] = 10;
  back = manifest_from_json(j, "mem");
  EXPECT_EQ(back.domain.sky(), (Vec3{0, 0, -1}));
  EXPECT_EQ(back.playback_fps, 10);
  j["domain"]["up_axis"] = "sideways";
  EXPECT_THROW(manifest_from_json(j, "mem"), Error);
  j["domain"]["up_axis"] = "z_up";
  j["playback_fps"] = -1;
  EXPECT_THROW(manifest_from_json(j, "mem"), Error);
}

TEST(Manifest, FieldUnitsReferencesAndTimeUnitsAreOptionalAndChecked) {
  // Issue 34 (colour legends): older manifests have neither and stay readable; written back without them.
  Manifest m = sample_manifest(3, 2, 16, 16);
  json j = to_json(m);
  EXPECT_FALSE(j.contains("fields"));
  EXPECT_FALSE(j.contains("time_units"));
  EXPECT_TRUE(manifest_from_json(j, "mem").fields.empty());
  m.time_units = "s";
  m.fields = {{"phi_p", "1/s", {0.5, 0.25}, "running"}, {"phi_s", "", {}, ""}};
  j = to_json(m);
  const Manifest back = manifest_from_json(j, "mem");
  EXPECT_EQ(back.time_units, "s");
  EXPECT_EQ(back.fields, m.fields);
  EXPECT_EQ(back.find_field("phi_s"), 1);
  EXPECT_EQ(back.find_field("phi"), -1);
  // Through the file form too.
  TempDir dir("manifest-fields");
  write_manifest_atomic(dir.path / kManifestFileName, m);
  EXPECT_EQ(read_manifest(dir.path / kManifestFileName).fields, m.fields);
  json bad = j;
  bad["fields"][0]["references"][1] = 0;
  expect_error([&] { manifest_from_json(bad, "mem"); }, {"fields[0].references[1]", "expected a finite value > 0"});
  bad = j;
  bad["fields"][1]["name"] = "phi_p";
  expect_error([&] { manifest_from_json(bad, "mem"); }, {"fields[1]", "used twice"});
  bad = j;  // issue 41: the scale mode is one of three words
  bad["fields"][0]["reference_mode"] = "sometimes";
  expect_error([&] { manifest_from_json(bad, "mem"); }, {"fields[0].reference_mode", "\"sometimes\""});
  bad = j;
  bad["fields"][0]["references"] = "many";
  expect_error([&] { manifest_from_json(bad, "mem"); }, {"fields[0].references"});
  bad = j;
  bad["time_units"] = 3;
  expect_error([&] { manifest_from_json(bad, "mem"); }, {"time_units"});
}

TEST(Manifest, EmptyGraphAndMinimalFieldsAreValid) {
  Manifest m = sample_manifest(3, 2);
  m.graph.neighbours.clear();
  m.axes.clear();
  for (auto& t : m.tasks) t.axes.clear();
  EXPECT_NO_THROW(m.validate());
  // Optional sections may be absent.
  json j = to_json(m);
  for (const char* key : {"title", "provenance", "domain", "times", "video", "rig", "navigation", "axes"}) j.erase(key);
  const Manifest back = manifest_from_json(j, "mem");
  EXPECT_TRUE(back.graph.empty());
  EXPECT_EQ(back.camera_count(), 3);
  EXPECT_EQ(back.task_count(), 2);
}

TEST(Manifest, SizeGrowsWithCamerasPlusTasksNotTheirProduct) {
  const auto bytes = [](int c, int t) { return to_json(sample_manifest(c, t)).dump().size(); };
  const double both = double(bytes(300, 300)), separate = double(bytes(300, 1) + bytes(1, 300));
  EXPECT_LT(both, 1.05 * separate) << both << " vs " << separate;
}

TEST(Manifest, StreamPathsAndLookups) {
  Manifest m = sample_manifest(12, 3);
  EXPECT_EQ(m.stream_relative_path(11, 2), "movies/c11/t2.mp4");
  expect_error([&] { m.stream_relative_path(12, 0); }, {"camera 12 out of range", "12 cameras"});
  expect_error([&] { m.stream_relative_path(0, -1); }, {"task -1 out of range"});
  EXPECT_EQ(m.find_task("iso 2"), 2);
  EXPECT_EQ(m.find_task("nope"), -1);
  EXPECT_EQ(m.find_axis("isovalue"), 0);
  EXPECT_EQ(m.step_task_on_axis(0, "isovalue", 1), 1);
  EXPECT_EQ(m.step_task_on_axis(2, "isovalue", 1), -1);
  EXPECT_EQ(m.step_task_on_axis(1, "isovalue", -1), 0);
  EXPECT_EQ(m.step_task_on_axis(1, "window", 1), -1);
  EXPECT_EQ(m.frame_time(4), 4.0);
  m.times = {0, 0.1};
  EXPECT_EQ(m.frame_time(1), 0.1);
}

TEST(Manifest, StepsOnOneAxisOfATwoAxisGrid) {
  Manifest m = sample_manifest(2, 0);
  m.axes = {{"isovalue", {1, 2, 3}, ""}, {"field", {0, 1}, ""}};
  for (int f = 0; f < 2; ++f)
    for (int i = 0; i < 3; ++i) {
      TaskEntry t;
      t.id = int(m.tasks.size());
      t.name = "f" + std::to_string(f) + "i" + std::to_string(i);
      t.axes = {{"field", f}, {"isovalue", i}};
      if (f == 1) std::swap(t.axes[0], t.axes[1]);  // order of positions must not matter
      m.tasks.push_back(t);
    }
  m.validate();
  EXPECT_EQ(m.step_task_on_axis(m.find_task("f0i1"), "isovalue", 1), m.find_task("f0i2"));
  EXPECT_EQ(m.step_task_on_axis(m.find_task("f0i1"), "field", 1), m.find_task("f1i1"));
  EXPECT_EQ(m.step_task_on_axis(m.find_task("f1i0"), "isovalue", -1), -1);
}

TEST(Manifest, UnknownSchemaVersionIsRefused) {
  json j = to_json(sample_manifest(2, 2));
  j["schema_version"] = 3;
  expect_error([&] { manifest_from_json(j, "db/panoptes.json"); },
               {"db/panoptes.json", "schema_version 3 is not supported", "reads versions 1 to 2", "newer"});
  j["schema_version"] = 0;
  expect_error([&] { manifest_from_json(j, "x"); }, {"schema_version 0 is not supported", "unknown version"});
  j["schema_version"] = "1";
  expect_error([&] { manifest_from_json(j, "x"); }, {"schema_version", "expected an integer"});
  j.erase("schema_version");
  expect_error([&] { manifest_from_json(j, "x"); }, {"schema_version", "missing"});
}

TEST(Manifest, MissingOrMalformedFilesGiveClearMessages) {
  TempDir dir;
  expect_error([&] { read_manifest(dir / "panoptes.json"); }, {"panoptes.json", "no manifest here"});
  write_text(dir / "panoptes.json", "{\"schema_version\": 1, \"cameras\": [");
  expect_error([&] { read_manifest(dir / "panoptes.json"); }, {"panoptes.json", "malformed manifest", "parse error"});
  write_text(dir / "panoptes.json", "[1, 2]");
  expect_error([&] { read_manifest(dir / "panoptes.json"); }, {"expected a JSON object"});
  try {
    read_manifest(dir / "panoptes.json");
  } catch (const FileError& e) {
    EXPECT_EQ(e.path(), (dir / "panoptes.json").string());
  }
}

TEST(Manifest, MissingAndMistypedFieldsAreNamed) {
  const json good = to_json(sample_manifest(3, 2));
  json j = good;
  j.erase("cameras");
  expect_error([&] { manifest_from_json(j, "f"); }, {"f: cameras: missing"});
  j = good;
  j["cameras"][1]["position"] = json::array({1, 2});
  expect_error([&] { manifest_from_json(j, "f"); }, {"cameras[1].position", "array of 3 numbers"});
  j = good;
  j["image"]["width"] = "wide";
  expect_error([&] { manifest_from_json(j, "f"); }, {"image.width", "expected an integer", "string"});
  j = good;
  j["status"] = "paused";
  expect_error([&] { manifest_from_json(j, "f"); }, {"status", "\"paused\"", "running, complete, interrupted"});
  j = good;
  j["tasks"][0]["parameters"] = json::array();
  expect_error([&] { manifest_from_json(j, "f"); }, {"tasks[0].parameters", "JSON object"});
  j = good;
  j["video"]["codec"] = "vp9";
  expect_error([&] { manifest_from_json(j, "f"); }, {"video.codec", "vp9", "h264"});
}

TEST(Manifest, ValidateNamesTheBadField) {
  const Manifest good = sample_manifest(4, 3);
  Manifest m = good;
  m.cameras[2].id = 7;
  expect_error([&] { m.validate(); }, {"cameras[2].id is 7", "expected its index 2"});
  m = good;
  m.graph.neighbours.pop_back();
  expect_error([&] { m.validate(); }, {"navigation graph has 3 entries", "4"});
  m = good;
  m.graph.neighbours[1].up = 4;
  expect_error([&] { m.validate(); }, {"navigation graph entry 1 names camera 4"});
  m = good;
  m.tasks[1].axes[0].axis = "threshold";
  expect_error([&] { m.validate(); }, {"tasks[1] sits on unknown axis \"threshold\""});
  m = good;
  m.tasks[1].axes[0].index = 3;
  expect_error([&] { m.validate(); }, {"tasks[1] has index 3 on axis \"isovalue\" of 3 values"});
  m = good;
  m.tasks[2].name = m.tasks[0].name;
  expect_error([&] { m.validate(); }, {"task name \"iso 0\" is used twice"});
  m = good;
  m.image.width = 0;
  expect_error([&] { m.validate(); }, {"image size 0x64 must be positive"});
  m = good;
  m.cameras[0].fov_y_deg = 180;
  expect_error([&] { m.validate(); }, {"cameras[0].fov_y_deg"});
  m = good;
  m.frames_written = -1;
  expect_error([&] { m.validate(); }, {"frames_written -1"});
}

TEST(Manifest, PatternsEscapingTheDirectoryAreRefused) {
  EXPECT_NO_THROW(validate_movie_pattern("movies/c{camera}/t{task}.mp4"));
  EXPECT_NO_THROW(validate_movie_pattern("c{camera}_t{task}.mp4"));
  EXPECT_NO_THROW(validate_movie_pattern("a..b/{camera}{task}.mp4"));
  expect_error([] { validate_movie_pattern("../movies/c{camera}/t{task}.mp4"); }, {"reaches outside", ".."});
  expect_error([] { validate_movie_pattern("movies/../../c{camera}/t{task}.mp4"); }, {"reaches outside"});
  expect_error([] { validate_movie_pattern("/tmp/c{camera}/t{task}.mp4"); }, {"is absolute"});
  expect_error([] { validate_movie_pattern("movies//c{camera}t{task}.mp4"); }, {"empty path component"});
  expect_error([] { validate_movie_pattern("./c{camera}t{task}.mp4"); }, {"\".\" path component"});
  expect_error([] { validate_movie_pattern("movies\\..\\c{camera}t{task}.mp4"); }, {"backslash"});
  expect_error([] { validate_movie_pattern("movies/c{camera}.mp4"); }, {"lacks {task}"});
  expect_error([] { validate_movie_pattern("movies/t{task}.mp4"); }, {"lacks {camera}"});
  expect_error([] { validate_movie_pattern("{camera}/{frame}/{task}.mp4"); }, {"placeholder other than"});
  expect_error([] { validate_movie_pattern(""); }, {"is empty"});
  // Through a manifest file: the whole database is refused at open time.
  json j = to_json(sample_manifest(2, 2));
  j["movie_pattern"] = "../../etc/c{camera}t{task}";
  expect_error([&] { manifest_from_json(j, "db/panoptes.json"); }, {"db/panoptes.json", "reaches outside"});
}

TEST(Manifest, AtomicWriteFailureLeavesNoTempFile) {
  TempDir dir;
  expect_error([&] { write_manifest_atomic(dir / "no-such-dir" / "panoptes.json", sample_manifest(1, 1)); },
               {"no-such-dir", "cannot create the camera table"});
  Manifest bad = sample_manifest(1, 1);
  bad.image.width = -3;
  write_manifest_atomic(dir / "panoptes.json", sample_manifest(1, 1));
  EXPECT_THROW(write_manifest_atomic(dir / "panoptes.json", bad), Error);
  EXPECT_EQ(read_manifest(dir / "panoptes.json").image.width, 64);
}
