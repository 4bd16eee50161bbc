#include "insitu/output.hpp"
#include "insitu/rank_agreement.hpp"

#include <sys/stat.h>

#include <cstdio>
#include <exception>
#include <sstream>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/number_text.hpp"

namespace panoptes::insitu {

namespace {

// Every rank learns whether any failed, and the failing rank's message: then all throw it.
void agree(const std::string& failure, const OutputGroup& g) {
  int failed = failure.empty() ? g.size : g.rank;  // lowest failing rank wins
#ifdef PANOPTES_HAVE_MPI
  if (g.size > 1) {
    MPI_Allreduce(MPI_IN_PLACE, &failed, 1, MPI_INT, MPI_MIN, g.comm);
    if (failed == g.size) return;
    int n = failed == g.rank ? int(failure.size()) : 0;
    MPI_Bcast(&n, 1, MPI_INT, failed, g.comm);
    std::string text = failed == g.rank ? failure : std::string(std::size_t(n), ' ');
    MPI_Bcast(text.data(), n, MPI_CHAR, failed, g.comm);
    throw Error(failed == 0 ? text : "rank " + std::to_string(failed) + ": " + text);
  }
#endif
  if (failed != g.size) throw Error(failure);
}


// What resume may not continue, checked against the database's manifest before the store opens it:
// a database whose run finished (unless resume_complete), and another schedule than it was written
// with (the store compares what the manifest records of the images, not the session's schedule).
void refuse_resume(const SessionConfig& cfg, const store::Manifest& now) {
  struct stat st{};
  const std::string man = cfg.output_dir + "/panoptes.json";
  if (::lstat(man.c_str(), &st) != 0) return;  // nothing to resume: the store starts a new database
  const store::Manifest old = store::read_manifest(man);
  if (old.status == store::Status::complete && !cfg.resume_complete) {
    const int n = old.frames_written;
    const std::string last = n > 0 && std::size_t(n) <= old.times.size()
                                 ? " up to time " + number_text(old.times[std::size_t(n) - 1])
                                 : "";
    throw FileError(cfg.output_dir, "holds a complete database (its run finished: " + std::to_string(n) + " snapshots" + last +
                                        "); [output] mode = \"resume\" continues only an interrupted run, and this run's "
                                        "snapshots up to that time would be skipped, leaving the old movies. Set mode = "
                                        "\"overwrite\" to replace it, write to another [output] dir, or set [output] "
                                        "resume_complete = true to append to the finished run");
  }
  const auto was = old.provenance.extra.find(kScheduleNote);
  const auto is = now.provenance.extra.find(kScheduleNote);
  if (was != old.provenance.extra.end() && is != now.provenance.extra.end() && was->second != is->second)
    throw FileError(cfg.output_dir, "cannot resume this database: the schedule ([schedule]) differs (" + was->second +
                                        " in the database, " + is->second +
                                        " in this run); a resumed run must use the configuration it was written with");
}

}  // namespace

std::string format_references(const std::vector<double>& refs) {
  std::string out;
  char buf[40];
  for (double r : refs) {
    std::snprintf(buf, sizeof buf, "%.17g", r);
    out += (out.empty() ? "" : " ") + std::string(buf);
  }
  return out;
}

std::string schedule_text(const ScheduleConfig& schedule) {
  if (schedule.every_time > 0) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "every_time = %.17g", schedule.every_time);
    return buf;
  }
  return "every_steps = " + std::to_string(schedule.every_steps);
}

std::vector<double> parse_references(const std::string& text) {
  std::istringstream in(text);
  std::vector<double> v;
  for (double x; in >> x;) v.push_back(x);
  return v;
}

// mode = "overwrite" over an interrupted run: that run's snapshots are the only copy of its movies (a
// restart that meant "resume" would delete them), so they are kept beside, renamed (one rename, nothing
// copied), and the log says where and how to resume instead.
namespace {
void keep_interrupted(const SessionConfig& cfg) {
  struct stat st{};
  const std::string man = cfg.output_dir + "/panoptes.json";
  if (::lstat(man.c_str(), &st) != 0) return;
  store::Manifest old;
  try {
    old = store::read_manifest(man);
  } catch (const std::exception&) {
    return;  // not a readable database: overwrite replaces it as before
  }
  if (old.status != store::Status::interrupted || old.frames_written <= 0) return;
  std::string kept;
  for (int n = 1; n < 1000 && kept.empty(); ++n) {
    const std::string candidate = cfg.output_dir + ".interrupted-" + std::to_string(n);
    if (::lstat(candidate.c_str(), &st) != 0) kept = candidate;
  }
  if (kept.empty() || std::rename(cfg.output_dir.c_str(), kept.c_str()) != 0)
    throw FileError(cfg.output_dir, "holds an interrupted run (" + std::to_string(old.frames_written) +
                                        " snapshots) that mode = \"overwrite\" would delete, and it could not be kept "
                                        "beside; set [output] mode = \"resume\" to continue it, or keep_interrupted = false to "
                                        "delete it");
  log::warn(cfg.output_dir + " held an interrupted run (" + std::to_string(old.frames_written) +
            " snapshots): mode = \"overwrite\" starts a new database and keeps that run as " + kept +
            " (a restart that should continue it sets [output] mode = \"resume\"; keep_interrupted = false deletes it)");
}
}  // namespace

SessionOutput open_session_output(const SessionConfig& cfg, const store::Manifest& manifest,
                                  const std::vector<int>& owned, const OutputGroup& g) {
  SessionOutput out;
  // Rank 0: the manifest (and its movies).
  std::string failure;
  if (g.rank == 0) {
    try {
      store::WriterOptions o;
      o.owned_cameras = owned;
      o.layout = store::parse_layout_choice(cfg.layout);
      o.rank = g.rank;
      o.ranks = g.size;
      if (cfg.mode == OutputMode::resume) {
        refuse_resume(cfg, manifest);
        out.writer.emplace(store::DatabaseWriter::resume(cfg.output_dir, manifest, o));
        const store::Manifest& m = out.writer->manifest();
        out.frames = m.frames_written;
        if (out.frames > 0 && std::size_t(out.frames) <= m.times.size()) out.last_time = m.times[std::size_t(out.frames) - 1];
        const auto note = m.provenance.extra.find(kRunningMaxNote);
        if (note != m.provenance.extra.end()) out.references = parse_references(note->second);
      } else {
        struct stat st{};
        const std::string man = cfg.output_dir + "/panoptes.json";
        // The store's own refusal names its C++ option; a C, Fortran or Python user has this key.
        if (cfg.mode == OutputMode::create && ::lstat(man.c_str(), &st) == 0)
          throw FileError(cfg.output_dir, "already holds a Panoptes database (panoptes.json); " +
                                              (cfg.existing_database_advice.empty()
                                                   ? std::string("set [output] mode = \"overwrite\" to replace it, or mode = "
                                                                 "\"resume\" to continue it after a restart")
                                                   : cfg.existing_database_advice));
        o.overwrite = cfg.mode == OutputMode::overwrite;
        if (o.overwrite && cfg.keep_interrupted) keep_interrupted(cfg);
        out.writer.emplace(store::DatabaseWriter::create(cfg.output_dir, manifest, o));
      }
    } catch (...) {
      failure = exception_message(std::current_exception());
    }
  }
  agree(failure, g);
#ifdef PANOPTES_HAVE_MPI
  if (g.size > 1) {
    double v[2] = {double(out.frames), out.last_time};
    MPI_Bcast(v, 2, MPI_DOUBLE, 0, g.comm);
    out.frames = int(v[0]);
    out.last_time = v[1];
    int n = int(out.references.size());
    MPI_Bcast(&n, 1, MPI_INT, 0, g.comm);
    out.references.resize(std::size_t(n));
    MPI_Bcast(out.references.data(), n, MPI_DOUBLE, 0, g.comm);
  }
#endif
  // The other ranks: the movies of the cameras they own, in the directory rank 0 made.
  if (g.rank != 0 && !owned.empty()) {
    try {
      store::WriterOptions o;
      o.owned_cameras = owned;
      o.writes_manifest = false;
      o.rank = g.rank;
      o.ranks = g.size;
      out.writer.emplace(cfg.mode == OutputMode::resume
                             ? store::DatabaseWriter::resume(cfg.output_dir, manifest, o, out.frames)
                             : store::DatabaseWriter::create(cfg.output_dir, manifest, o));
    } catch (...) {
      failure = exception_message(std::current_exception());
    }
  }
  agree(failure, g);
  if (cfg.mode == OutputMode::resume && g.rank == 0 && out.frames > 0)
    log::info(cfg.output_dir + ": resuming after snapshot " + std::to_string(out.frames - 1) + " (time " +
              std::to_string(out.last_time) + "); snapshots at or before that time are skipped");
  return out;
}

}  // namespace panoptes::insitu
