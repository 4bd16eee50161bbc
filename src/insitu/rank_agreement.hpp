#pragma once
// Every call of a session that involves more than one rank starts with an agreement (issue 42): the
// ranks compare which call they are in (its kind and number, the step, the time, the snapshots taken,
// at the start the grid and configuration) and whether their own part failed, in one small
// non-blocking reduction that waits at most a timeout. What used to hang a job in the next collective
// becomes an error on every rank, within bounded time:
//   - one rank's failure (a refused argument, a field it could not bind, an encoder that failed):
//     every rank throws, naming that rank and its message (broadcast from it);
//   - ranks out of step (a skipped or extra call, another step, time or snapshot count, another grid):
//     every rank throws, naming the two ranks that differ and their values;
//   - a rank that does not come within the timeout (it stopped calling Panoptes, or waits elsewhere):
//     the waiting ranks throw. The pending reduction stays posted (MPI cannot cancel a collective), so
//     the late rank meets it at its next call and learns that it is out of step there.
// The reduction is one MPI_Iallreduce(MAXLOC) of (value, rank) pairs: O(log P) latency, a few hundred
// bytes whatever the number of ranks; a failure adds one broadcast of the message.
#include <array>
#include <cstdint>
#include <exception>
#include <memory>
#include <string>

#include "core/error.hpp"

#ifdef PANOPTES_HAVE_MPI
#include <mpi.h>
#endif

namespace panoptes::insitu {

/// The session calls that agree, in the words their messages use.
enum class Call : int { start = 1, due, process, snapshot, frames, finalize, report };
const char* to_string(Call call);

/// Values the ranks must share at the start: grid dims, origin and spacing, then a digest of the
/// configuration's fields that shape the database.
inline constexpr int kShapeValues = 10;

/// What this rank says at a call.
struct CallRecord {
  Call call = Call::start;
  std::int64_t step = -1;   ///< process(), due(): the step; -1 elsewhere
  double time = 0;          ///< the call's time (0 where it has none); not compared when not finite
  std::int64_t snapshots = 0;
  bool compare_time = false;
  std::array<double, kShapeValues> shape{};  ///< start only
  /// A call at a step and time of the simulation (process, due: both compared); step -1: a time only.
  static CallRecord at(std::int64_t step, double time) {
    CallRecord r;
    r.step = step;
    r.time = time;
    r.compare_time = true;
    return r;
  }
};

/// How bad a rank's own failure at a call is.
enum class Failure : int {
  none = 0,
  refused = 1,  ///< a bad argument of this call: every rank refuses the call, the session goes on
  failed = 2,   ///< the session cannot go on (a write failed, the grid differs, ...)
};

/// Thrown on every rank when the agreement fails. `stops` = the session cannot go on.
class AgreementError : public Error {
 public:
  AgreementError(const std::string& what, bool stops) : Error(what), stops_(stops) {}
  bool stops() const { return stops_; }

 private:
  bool stops_;
};

/// One session's agreements over its own duplicate of the communicator (so they never match the
/// session's data collectives or the simulation's own messages).
class RankAgreement {
 public:
  /// One process: every agreement only rethrows this rank's own failure.
  RankAgreement() = default;
#ifdef PANOPTES_HAVE_MPI
  /// Duplicates `comm` (itself collective: waits at most `timeout_s` for the other ranks).
  RankAgreement(MPI_Comm comm, double timeout_s);
#endif
  RankAgreement(RankAgreement&&) noexcept;
  RankAgreement& operator=(RankAgreement&&) noexcept;
  ~RankAgreement();

  /// Returns when every rank is in the same call with the same values and none failed; else throws on
  /// every rank: this rank's own `error` as it is (its type kept), another rank's failure as an
  /// AgreementError naming that rank and its message, a disagreement or a timeout as an
  /// AgreementError naming what differs. `stop` (a signal number, 0 = none) is agreed too: the
  /// largest of every rank's is returned.
  int agree(const CallRecord& mine, std::exception_ptr error = nullptr, Failure severity = Failure::none, int stop = 0);

  int rank() const { return rank_; }
  int size() const { return size_; }
  double timeout() const { return timeout_; }

 private:
  struct Pending;
  int rank_ = 0, size_ = 1;
  double timeout_ = 0;
  std::int64_t calls_ = 0;  ///< agreements so far: ranks out of step differ here first
#ifdef PANOPTES_HAVE_MPI
  MPI_Comm comm_ = MPI_COMM_NULL;
#endif
  // The reduction's buffers and request, on the heap: when a wait times out they must outlive this
  // object (the reduction cannot be cancelled; a late rank still completes it).
  Pending* pending_ = nullptr;
};

/// How long a rank waiting for the others polls before it sleeps: 100 us, or 20 us when this node runs
/// more ranks than it has cores (`local_ranks` as the MPI launcher says, 0 = unknown), where the rank
/// waited for may need this very core.
double wait_spin_seconds(long local_ranks, unsigned cores);

/// The message of an exception (for records and reports).
std::string exception_message(const std::exception_ptr& e);

}  // namespace panoptes::insitu
