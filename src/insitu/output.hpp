#pragma once
// The session's database, opened as `[output] mode` says: create (refuse an existing database),
// overwrite, or resume (continue it after a checkpoint restart). Collective: rank 0 opens the manifest
// first, then every rank that owns cameras opens its movies; when any rank fails, every rank throws
// (one message, from the rank that failed), instead of the others waiting for it forever.
#include <optional>
#include <string>
#include <vector>

#include "insitu/config.hpp"
#include "store/database.hpp"

#ifdef PANOPTES_HAVE_MPI
#include <mpi.h>
#endif

namespace panoptes::insitu {

/// Provenance note in which the session keeps the running references of relative windows
/// (every field's, whatever its SessionConfig::reference mode), so that a resumed run goes on with them.
inline constexpr const char* kRunningMaxNote = "insitu.running_max";
/// Provenance note holding the schedule ("every_steps = 10" or "every_time = 0.25"): the manifest has
/// no other place for it, and a resumed run with another schedule would mix two cadences in one movie.
inline constexpr const char* kScheduleNote = "insitu.schedule";
/// The kScheduleNote text of a schedule (every_time exactly, %.17g).
std::string schedule_text(const ScheduleConfig& schedule);

/// A database opened for a session.
struct SessionOutput {
  std::optional<store::DatabaseWriter> writer;  ///< rank 0 always; other ranks when they own cameras
  int frames = 0;                 ///< snapshots already in the database (resume), the same on every rank
  double last_time = 0;           ///< resume with frames > 0: time of the last of them
  std::vector<double> references; ///< resume: the running references kept in the manifest (may be empty)
};

/// Where and with whom the database is opened.
struct OutputGroup {
  int rank = 0, size = 1;
#ifdef PANOPTES_HAVE_MPI
  MPI_Comm comm = MPI_COMM_NULL;
#endif
};

/// Opens cfg.output_dir per cfg.mode for the cameras `owned` by this rank (collective over the group).
/// Errors name `[output] mode` (the key every language's user has), never a command-line option.
SessionOutput open_session_output(const SessionConfig& cfg, const store::Manifest& manifest,
                                  const std::vector<int>& owned, const OutputGroup& group);

/// "v1 v2 ..." of the running references, exactly (for kRunningMaxNote), and back.
std::string format_references(const std::vector<double>& refs);
std::vector<double> parse_references(const std::string& text);

}  // namespace panoptes::insitu
