#include "insitu/rank_agreement.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <utility>
#include <vector>

#ifdef __linux__
#include <sys/prctl.h>
#endif

namespace panoptes::insitu {

const char* to_string(Call call) {
  switch (call) {
    case Call::start: return "the session's start";
    case Call::due: return "due()";
    case Call::process: return "process()";
    case Call::snapshot: return "snapshot()";
    case Call::frames: return "the end of a snapshot";
    case Call::finalize: return "finalize()";
    case Call::report: return "a report of the session's statistics";
  }
  return "an unknown call";
}

std::string exception_message(const std::exception_ptr& e) {
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& x) {
    return x.what();
  } catch (...) {
    return "unknown error";
  }
}

namespace {

// The compared values, in the order a disagreement is reported: first what says the ranks are in
// different calls, then a failure (with its message), then the call's arguments.
enum Slot : int { kCall, kCalls, kFailure, kStop, kStep, kSnapshots, kTime, kTimeCompared, kShape, kSlots = kShape + kShapeValues };
constexpr int kMessageBytes = 1024;

const char* shape_name(int i) {
  static const char* const names[kShapeValues] = {"grid dims x", "grid dims y", "grid dims z", "grid origin x",
                                                  "grid origin y", "grid origin z", "grid spacing x", "grid spacing y",
                                                  "grid spacing z", "configuration"};
  return names[i];
}

std::string exact(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

[[noreturn]] void rethrow_own(std::exception_ptr error) { std::rethrow_exception(error); }

}  // namespace

struct RankAgreement::Pending {
#ifdef PANOPTES_HAVE_MPI
  struct Pair {
    double value;
    int rank;
  };
  // [0, kSlots): the values, [kSlots, 2 kSlots): their negations (MAXLOC of -v is the minimum).
  std::array<Pair, 2 * kSlots> pairs{};
  std::array<char, kMessageBytes> message{};
  MPI_Request request = MPI_REQUEST_NULL;
#endif
  bool abandoned = false;  ///< a wait timed out: the request is still posted
};

double wait_spin_seconds(long local_ranks, unsigned cores) {
  return local_ranks > 0 && cores > 0 && local_ranks > long(cores) ? 20e-6 : 100e-6;
}

#ifdef PANOPTES_HAVE_MPI
namespace {

// While a waiting thread sleeps, its sleeps end when asked: Linux lets a sleep overrun by the thread's
// timer slack (50 us by default), so a 20 us sleep took ~70 us, and the rank that woke late was the
// late rank at the next step, where the other one waited in turn: the ranks took turns waiting at every
// step (below). Restored when the wait ends: the slack is the simulation thread's own setting.
class FineTimerSlack {
 public:
  FineTimerSlack() = default;
  FineTimerSlack(const FineTimerSlack&) = delete;
  FineTimerSlack& operator=(const FineTimerSlack&) = delete;
  void engage() {
#ifdef __linux__
    if (old_ >= 0) return;
    old_ = prctl(PR_GET_TIMERSLACK, 0, 0, 0, 0);
    if (old_ >= 0) prctl(PR_SET_TIMERSLACK, 1000UL, 0, 0, 0);  // 1 us (0 would mean "the default")
#endif
  }
  ~FineTimerSlack() {
#ifdef __linux__
    if (old_ > 0) prctl(PR_SET_TIMERSLACK, static_cast<unsigned long>(old_), 0, 0, 0);
#endif
  }

 private:
  long old_ = -1;
};

// The spin of wait_for(), chosen once per process from what the MPI launcher says about this node.
double node_spin_seconds() {
  static const double spin = [] {
    long local = 0;
    for (const char* name : {"OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS", "PMI_LOCAL_SIZE"})
      if (const char* v = std::getenv(name)) {
        local = std::atol(v);
        break;
      }
    return wait_spin_seconds(local, std::thread::hardware_concurrency());
  }();
  return spin;
}

// Waits for `request` at most `timeout_s`: true when it completed. Spins first (ranks in step arrive
// within microseconds; ranks that drift apart, within a step's jitter), then sleeps in growing steps
// so that a rank waiting long costs no core.
bool wait_for(MPI_Request& request, double timeout_s) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  int done = 0;
  auto pause = std::chrono::microseconds(0);
  FineTimerSlack slack;
  const double spin = node_spin_seconds();
  for (;;) {
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
    if (done) return true;
    const double waited = std::chrono::duration<double>(Clock::now() - start).count();
    if (waited > timeout_s) return false;
    // A non-blocking collective advances only inside MPI calls: poll without giving the core away for the
    // first 100 us (20 us where ranks outnumber cores: wait_spin_seconds()), then sleep: 20 us at a time
    // (with a fine timer slack) for the first 2 ms, then in growing steps. The agreement runs at every
    // step's process() call, and ranks that exchange nothing between snapshots drift apart by a step's
    // jitter, so the early rank waits at every step. Measured in insitu_overhead_bench's setting (2 ranks,
    // 8,000 steps, 2 shared cores; Panoptes' CPU by the OS over the code's own, three alternations;
    // docs/rendering.md, Round 18): spinning 20 us and sleeping with the default slack 0.31-0.36x; spinning
    // 100 us 0.22-0.30x; spinning 100 us and sleeping with a fine slack 0.23-0.27x (the wall time 11.8-12.0
    // s against 13.2-13.9 s; the code alone 9.5 s). Round 13 spun 0.2 ms and then yielded up to 2 ms,
    // burning a core for a descheduled rank's whole time slice (the session's own CPU a median of 14.1 s
    // against 8.7 s with sleeps): past the short spin it sleeps.
    if (waited < spin) continue;
    slack.engage();
    if (waited < 0.002) {
      std::this_thread::sleep_for(std::chrono::microseconds(20));
      continue;
    }
    pause = std::min(std::chrono::microseconds(2000), pause + std::chrono::microseconds(50));
    std::this_thread::sleep_for(pause);
  }
}

}  // namespace

RankAgreement::RankAgreement(MPI_Comm comm, double timeout_s) : timeout_(timeout_s) {
  MPI_Comm_rank(comm, &rank_);
  MPI_Comm_size(comm, &size_);
  if (size_ == 1) return;
  MPI_Request request = MPI_REQUEST_NULL;
  MPI_Comm_idup(comm, &comm_, &request);
  if (!wait_for(request, timeout_s)) {
    // The duplicate is still being made; it cannot be used or freed before it is, so it is left.
    comm_ = MPI_COMM_NULL;
    throw AgreementError("rank " + std::to_string(rank_) + ": not every rank of the communicator started a Panoptes session within " +
                             exact(timeout_s) + " s ([resources] mpi_timeout): every rank must create it",
                         true);
  }
}
#endif

RankAgreement::RankAgreement(RankAgreement&& o) noexcept { *this = std::move(o); }

RankAgreement& RankAgreement::operator=(RankAgreement&& o) noexcept {
  std::swap(rank_, o.rank_);
  std::swap(size_, o.size_);
  std::swap(timeout_, o.timeout_);
  std::swap(calls_, o.calls_);
#ifdef PANOPTES_HAVE_MPI
  std::swap(comm_, o.comm_);
#endif
  std::swap(pending_, o.pending_);
  return *this;
}

RankAgreement::~RankAgreement() {
  // An abandoned reduction keeps its buffers (a late rank still completes it) and its communicator.
  if (pending_ && pending_->abandoned) return;
  delete pending_;
#ifdef PANOPTES_HAVE_MPI
  if (comm_ != MPI_COMM_NULL) {
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (!finalized) MPI_Comm_free(&comm_);
  }
#endif
}

int RankAgreement::agree(const CallRecord& mine, std::exception_ptr error, Failure severity, int stop) {
  if (error && severity == Failure::none) severity = Failure::failed;
  if (!error) severity = Failure::none;
  ++calls_;
  if (size_ == 1) {
    if (error) rethrow_own(error);
    return stop;
  }
#ifdef PANOPTES_HAVE_MPI
  if (pending_ && pending_->abandoned)
    throw AgreementError("rank " + std::to_string(rank_) + ": an earlier call waited in vain for the other ranks; the session cannot go on", true);
  if (!pending_) pending_ = new Pending;
  Pending& p = *pending_;
  std::array<double, kSlots> v{};
  v[kCall] = double(int(mine.call));
  v[kCalls] = double(calls_);
  v[kFailure] = double(int(severity));
  v[kStop] = double(stop);
  v[kStep] = double(mine.step);
  v[kSnapshots] = double(mine.snapshots);
  const bool timed = mine.compare_time && std::isfinite(mine.time);
  v[kTime] = timed ? mine.time : 0.0;
  v[kTimeCompared] = timed ? 1 : 0;
  for (int i = 0; i < kShapeValues; ++i) v[kShape + i] = std::isfinite(mine.shape[std::size_t(i)]) ? mine.shape[std::size_t(i)] : 0.0;
  for (int i = 0; i < kSlots; ++i) {
    p.pairs[std::size_t(i)] = {v[std::size_t(i)], rank_};
    p.pairs[std::size_t(kSlots + i)] = {-v[std::size_t(i)], rank_};
  }
  MPI_Iallreduce(MPI_IN_PLACE, p.pairs.data(), 2 * kSlots, MPI_DOUBLE_INT, MPI_MAXLOC, comm_, &p.request);
  if (!wait_for(p.request, timeout_)) {
    p.abandoned = true;
    throw AgreementError("rank " + std::to_string(rank_) + ": waited " + exact(timeout_) + " s ([resources] mpi_timeout) in " +
                             to_string(mine.call) + (mine.step >= 0 ? " at step " + std::to_string(mine.step) : "") +
                             " for ranks that did not come: a rank stopped calling Panoptes, skipped this call while "
                             "waiting elsewhere, or ended; the session cannot go on",
                         true);
  }
  auto hi = [&](int s) { return p.pairs[std::size_t(s)]; };
  auto lo = [&](int s) { return Pending::Pair{-p.pairs[std::size_t(kSlots + s)].value, p.pairs[std::size_t(kSlots + s)].rank}; };
  auto differs = [&](int s) { return hi(s).value != lo(s).value; };
  auto who = [&](int s, const std::string& a, const std::string& b) {
    return "rank " + std::to_string(lo(s).rank) + " " + a + ", rank " + std::to_string(hi(s).rank) + " " + b;
  };
  auto call_name = [](double c) { return std::string(to_string(Call(int(c)))); };
  // Ranks in different calls, or at a different count of calls: one skipped or added a call.
  if (differs(kCall) || differs(kCalls))
    throw AgreementError(
        "the ranks are out of step: " +
            (differs(kCall) ? who(kCall, "is in " + call_name(lo(kCall).value), "in " + call_name(hi(kCall).value))
                            : who(kCalls, "is at its Panoptes call " + exact(lo(kCalls).value),
                                  "at its call " + exact(hi(kCalls).value))) +
            " (every rank must make the same session calls in the same order: process() or due() every step, the same "
            "snapshot() and finalize() calls); the session cannot go on",
        true);
  const int failure = int(hi(kFailure).value);
  if (failure > 0) {
    const int root = hi(kFailure).rank;
    if (root == rank_) {
      const std::string text = exception_message(error);
      std::memset(p.message.data(), 0, p.message.size());
      std::memcpy(p.message.data(), text.data(), std::min(text.size(), p.message.size() - 1));
    }
    MPI_Ibcast(p.message.data(), kMessageBytes, MPI_CHAR, root, comm_, &p.request);
    if (!wait_for(p.request, timeout_)) {
      p.abandoned = true;
      throw AgreementError("rank " + std::to_string(rank_) + ": rank " + std::to_string(root) + " failed in " + to_string(mine.call) +
                               " but its message did not arrive within " + exact(timeout_) + " s",
                           true);
    }
    // This rank's own failure keeps its type (the C API's return codes follow it); a failing rank
    // that is not the one reported (a lower rank failed too) still throws its own.
    if (error) rethrow_own(error);
    p.message.back() = 0;
    const std::string text(p.message.data());
    throw AgreementError("rank " + std::to_string(root) + (failure == int(Failure::refused) ? " refused " : " failed in ") +
                             to_string(mine.call) + ": " + text +
                             (failure == int(Failure::refused) ? "" : "; the session cannot go on"),
                         failure != int(Failure::refused));
  }
  if (differs(kStep))
    throw AgreementError(std::string("the ranks are out of step in ") + to_string(mine.call) + ": " +
                             who(kStep, "is at step " + exact(lo(kStep).value), "at step " + exact(hi(kStep).value)) +
                             " (a rank skipped a step's call); the session cannot go on",
                         true);
  if (differs(kSnapshots))
    throw AgreementError(std::string("the ranks are out of step in ") + to_string(mine.call) + ": " +
                             who(kSnapshots, "has taken " + exact(lo(kSnapshots).value) + " snapshots",
                                 "has taken " + exact(hi(kSnapshots).value)) +
                             "; the session cannot go on",
                         true);
  if (hi(kTimeCompared).value > 0) {
    const double a = lo(kTime).value, b = hi(kTime).value;
    if (!(b - a <= 1e-9 * std::max(std::fabs(a), std::fabs(b))) || lo(kTimeCompared).value == 0)
      throw AgreementError(std::string("the ranks give different times in ") + to_string(mine.call) +
                               (mine.step >= 0 ? " at step " + std::to_string(mine.step) : "") + ": " +
                               who(kTime, "gives time " + exact(a), "gives " + exact(b)) +
                               " (every rank must pass the same simulation time); the session cannot go on",
                           true);
  }
  for (int i = 0; i < kShapeValues; ++i)
    if (differs(kShape + i)) {
      const bool digest = i == kShapeValues - 1;
      throw AgreementError(
          "the ranks describe different sessions: " +
              (digest ? "rank " + std::to_string(lo(kShape + i).rank) + " and rank " + std::to_string(hi(kShape + i).rank) +
                            " read different configurations (output dir, rig, image size, tasks or fields differ: every "
                            "rank must read the same one)"
                      : who(kShape + i, "has " + std::string(shape_name(i)) + " = " + exact(lo(kShape + i).value),
                            "has " + exact(hi(kShape + i).value)) +
                            " (every rank must describe the same global grid: dims, origin and spacing)") +
              "; the session cannot start",
          true);
    }
  if (error) rethrow_own(error);  // unreachable: a failure was reported above
  return int(hi(kStop).value);
#else
  (void)mine;
  if (error) rethrow_own(error);
  return stop;
#endif
}

}  // namespace panoptes::insitu
