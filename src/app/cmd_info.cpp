// `panoptes info DB [--json]`: a summary of a movie database, with a deep check of every movie.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "app/command.hpp"
#include "core/error.hpp"
#include "store/database.hpp"

namespace cmd_info {  // named, not anonymous: the unity build joins the command units

namespace fs = std::filesystem;
using namespace panoptes;

struct Args {
  std::string db;
  bool json = false;
  bool no_check = false;
  bool decode = false;
  int threads = 0;
  int max_problems = 20;
};

std::string human_bytes(double b) {
  const char* units[] = {"B", "kB", "MB", "GB", "TB", "PB"};
  int u = 0;
  while (b >= 1000 && u < 5) b /= 1000, ++u;
  char buf[32];
  std::snprintf(buf, sizeof buf, u == 0 ? "%.0f %s" : "%.1f %s", b, units[u]);
  return buf;
}

// Bytes of every regular file under dir (links are not followed: they may point anywhere).
std::int64_t size_on_disk(const fs::path& dir) {
  std::int64_t total = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, fs::directory_options::skip_permission_denied, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    std::error_code ec2;
    if (it->is_regular_file(ec2) && !it->is_symlink(ec2)) total += std::int64_t(it->file_size(ec2));
  }
  return total;
}

std::string axis_summary(const store::ParameterAxis& a) {
  std::string s = a.name + " (" + std::to_string(a.values.size()) + " values";
  if (!a.values.empty()) {
    char buf[64];
    std::snprintf(buf, sizeof buf, ": %g .. %g", a.values.front(), a.values.back());
    s += buf;
  }
  if (!a.units.empty()) s += " " + a.units;
  return s + ")";
}

void run(const Args& a) {
  const store::Database db = store::Database::open(a.db);
  const store::Manifest& m = db.manifest();
  const std::int64_t disk = size_on_disk(db.dir());
  const bool tty = ::isatty(STDERR_FILENO) && !a.json;
  store::StreamReport report;
  if (!a.no_check)
    report = db.validate_streams(a.threads, a.decode, [&](std::int64_t done, std::int64_t total) {
      if (tty) std::fprintf(stderr, "\rchecking movies: %lld / %lld", (long long)done, (long long)total), std::fflush(stderr);
    });
  if (tty && !a.no_check) std::fprintf(stderr, "\r\033[K");

  std::set<std::string> methods;
  for (const auto& t : m.tasks) methods.insert(t.method.empty() ? "?" : t.method);
  std::string method_list;
  for (const auto& s : methods) method_list += (method_list.empty() ? "" : ", ") + s;
  std::string status = std::string(store::to_string(db.status()));
  if (db.status() != db.stored_status())
    status += " (stored as " + std::string(store::to_string(db.stored_status())) + "; no live writer holds the lock)";

  if (a.json) {
    nlohmann::json j;
    j["database"] = db.dir().string();
    j["title"] = m.title;
    j["status"] = std::string(store::to_string(db.status()));
    j["stored_status"] = std::string(store::to_string(db.stored_status()));
    j["schema_version"] = m.schema_version;
    j["provenance"] = {{"program", m.provenance.program}, {"version", m.provenance.version},
                       {"created", m.provenance.created}, {"host", m.provenance.host},
                       {"command_line", m.provenance.command_line}};
    j["cameras"] = m.camera_count();
    j["rig"] = m.rig.kind;
    j["navigation_graph"] = !m.graph.empty();
    j["tasks"] = m.task_count();
    j["methods"] = methods;
    nlohmann::json axes = nlohmann::json::array();
    for (const auto& x : m.axes) axes.push_back({{"name", x.name}, {"values", x.values.size()}, {"units", x.units}});
    j["axes"] = axes;
    nlohmann::json fields = nlohmann::json::array();
    for (const auto& f : m.fields)
      fields.push_back({{"name", f.name}, {"units", f.units}, {"reference_mode", f.reference_mode},
                        {"references", f.references.size()}});
    j["fields"] = fields;
    j["streams"] = db.stream_count();
    j["frames"] = m.frames_written;
    j["image"] = {{"width", m.image.width}, {"height", m.image.height},
                  {"padded_width", m.image.padded_width}, {"padded_height", m.image.padded_height}};
    j["video"] = {{"codec", "h264"}, {"crf", m.video.crf}, {"preset", m.video.preset},
                  {"gop", m.video.gop}, {"fps", m.video.fps}};
    j["movie_pattern"] = m.movie_pattern;
    j["layout"] = std::string(store::to_string(m.layout));
    if (m.layout == store::Layout::packed) {
      std::int64_t ranks = 0;
      for (const auto& seg : m.packs) ranks += seg.ranks;
      j["pack_segments"] = m.packs.size();
      j["pack_files_max"] = 2 * ranks;
    }
    j["frame_checks"] = m.frame_checks.recorded() ? nlohmann::json(m.frame_checks.scheme) : nlohmann::json(nullptr);
    // What a frame read as good proves (issue 44): "all" (scheme 3), "frames" (scheme 2: not the
    // parameter sets), "none" (written before frame checks: unverified).
    j["frames_verified"] = m.frame_checks.binds_parameter_sets() ? "all" : m.frame_checks.recorded() ? "frames" : "none";
    j["bytes_on_disk"] = disk;
    if (!a.no_check) {
      nlohmann::json problems = nlohmann::json::array();
      for (const auto& p : report.problems)
        problems.push_back({{"camera", p.camera}, {"task", p.task},
                            {"kind", std::string(store::to_string(p.kind))}, {"message", p.message},
                            {"damaged_frames", p.damaged_frames}});
      j["check"] = {{"checked", report.checked}, {"movie_bytes", report.bytes}, {"decoded_all_frames", a.decode},
                    {"problems", problems}};
    }
    std::printf("%s\n", j.dump(2).c_str());
  } else {
    std::printf("database   %s\n", db.dir().string().c_str());
    std::printf("title      %s\n", m.title.empty() ? "(none)" : m.title.c_str());
    std::printf("status     %s\n", status.c_str());
    if (!m.provenance.program.empty() || !m.provenance.created.empty())
      std::printf("created    %s by %s %s on %s\n", m.provenance.created.c_str(), m.provenance.program.c_str(),
                  m.provenance.version.c_str(), m.provenance.host.c_str());
    std::printf("cameras    %d (rig %s; navigation graph %s)\n", m.camera_count(),
                m.rig.kind.empty() ? "unnamed" : m.rig.kind.c_str(), m.graph.empty() ? "empty" : "present");
    std::printf("tasks      %d (%s)\n", m.task_count(), method_list.empty() ? "none" : method_list.c_str());
    for (std::size_t i = 0; i < m.axes.size(); ++i)
      std::printf("%s%s\n", i == 0 ? "axes       " : "           ", axis_summary(m.axes[i]).c_str());
    if (m.axes.empty()) std::printf("axes       none\n");
    // Issue 41: what each field's colours are scaled by, so a reader knows whether brightness compares
    // across frames.
    for (std::size_t i = 0; i < m.fields.size(); ++i) {
      const store::FieldInfo& f = m.fields[i];
      std::string line = f.name + (f.units.empty() ? "" : " [" + f.units + "]");
      if (!f.references.empty()) {
        const auto [lo, hi] = std::minmax_element(f.references.begin(), f.references.end());
        const std::string mode = f.reference_mode.empty() ? "not recorded" : f.reference_mode;
        char range[96];
        std::snprintf(range, sizeof range, "%.3g .. %.3g", *lo, *hi);
        line += ": scale " + mode + ", reference " + range + (f.units.empty() ? "" : " " + f.units);
      }
      std::printf("%s%s\n", i == 0 ? "fields     " : "           ", line.c_str());
    }
    if (m.frames_written > 0)
      std::printf("frames     %d (t = %g .. %g)\n", m.frames_written, m.frame_time(0), m.frame_time(m.frames_written - 1));
    else
      std::printf("frames     0\n");
    std::printf("image      %dx%d (coded %dx%d)\n", m.image.width, m.image.height, m.image.padded_width,
                m.image.padded_height);
    std::printf("video      h264, crf %d, preset %s, gop %d, %g fps\n", m.video.crf, m.video.preset.c_str(),
                m.video.gop, m.video.fps);
    if (m.layout == store::Layout::packed) {
      std::int64_t ranks = 0;
      for (const auto& seg : m.packs) ranks += seg.ranks;
      std::printf("streams    %lld (packed: %zu segment(s), at most %lld pack and index files in packs/)\n",
                  (long long)db.stream_count(), m.packs.size(), (long long)(2 * ranks));
    } else {
      std::printf("streams    %lld (movies %s)\n", (long long)db.stream_count(), m.movie_pattern.c_str());
    }
    std::printf("checks     %s\n", m.frame_checks.binds_parameter_sets()
                                      ? "every frame: checksum, movie identity, index, timestamp and the stream's parameter "
                                        "sets (panoptes-frame-3)"
                                  : m.frame_checks.recorded()
                                      ? "every frame: checksum, movie identity, index and timestamp (panoptes-frame-2); "
                                        "the parameter sets (SPS/PPS) are unverified: written before they were bound"
                                      : "UNVERIFIED frames: checksums only where a movie carries them (written before frame "
                                        "checks were recorded): damage that decodes, re-ordered fragments and damaged "
                                        "parameter sets cannot be told from good frames");
    std::printf("on disk    %s", human_bytes(double(disk)).c_str());
    if (!a.no_check && db.stream_count() > 0)
      std::printf(" (movies %s, %s per stream)", human_bytes(double(report.bytes)).c_str(),
                  human_bytes(double(report.bytes) / double(db.stream_count())).c_str());
    std::printf("\n");
    if (a.no_check) {
      std::printf("checked    no movie (--no-check)\n");
    } else {
      std::printf("checked    %lld of %lld movies%s: %s\n", (long long)report.checked, (long long)db.stream_count(),
                  a.decode ? " (every frame decoded)" : "",
                  report.problems.empty() ? (m.frame_checks.recorded() ? "all readable"
                                                                        : "all readable, frames unverified (see checks)")
                                          : (std::to_string(report.problems.size()) + " with problems").c_str());
      const std::size_t shown = std::min(report.problems.size(), std::size_t(std::max(0, a.max_problems)));
      for (std::size_t i = 0; i < shown; ++i)
        std::printf("  %-10s %s\n", std::string(store::to_string(report.problems[i].kind)).c_str(),
                    report.problems[i].message.c_str());
      if (shown < report.problems.size())
        std::printf("  ... and %zu more (--max-problems, or --json for all)\n", report.problems.size() - shown);
    }
  }
  // Problems are findings, not a failure to run: exit 2 without an error line, so scripts can tell.
  if (!report.problems.empty()) app::exit_code() = 2;
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto args = std::make_shared<Args>();
  auto* sub = root.add_subcommand(
      "info",
      "Summarize a movie database (status, cameras, tasks, axes, frames, sizes) and check every movie. Exit "
      "status: 0 all good, 2 some movies missing/unreadable/truncated/damaged, 1 not a database");
  sub->add_option("DB", args->db, "Database directory (holding panoptes.json)")->required();
  sub->add_flag("--json", args->json, "Print the summary as JSON");
  sub->add_flag("--no-check", args->no_check, "Read the manifest only; do not open the movies");
  sub->add_flag("--decode", args->decode, "Also decode every recorded frame of every movie and list the damaged ones (slower)");
  sub->add_option("--threads", args->threads, "Threads for the movie check (0 = all cores)")->capture_default_str();
  sub->add_option("--max-problems", args->max_problems, "Problems listed in the text output")->capture_default_str();
  sub->callback([args] { run(*args); });
});

}  // namespace
