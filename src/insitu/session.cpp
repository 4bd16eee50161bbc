// Session's public calls (session_impl.hpp says where the rest lives). Each collective call opens with
// the ranks' agreement (Impl::agree, rank_agreement.hpp).
#include "insitu/session_impl.hpp"

#include "render/corner_field.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>

namespace panoptes::insitu {

LocalBlock LocalBlock::slab(const render::GridGeometry& g, int axis, int parts, int index, int ghosts) {
  if (axis < 0 || axis > 2 || parts < 1 || index < 0 || index >= parts || parts > g.dims[axis])
    throw Error("LocalBlock::slab: axis " + std::to_string(axis) + ", part " + std::to_string(index) + " of " +
                std::to_string(parts) + " does not fit " + std::to_string(g.dims[axis]) + " points");
  LocalBlock b = whole(g);
  const int n = g.dims[axis];
  const int lo = int(std::int64_t(n) * index / parts), hi = int(std::int64_t(n) * (index + 1) / parts);
  b.offset[axis] = lo;
  b.extent[axis] = hi - lo;
  b.ghost_lo[axis] = std::min(ghosts, lo);
  b.ghost_hi[axis] = std::min(ghosts, n - hi);
  return b;
}

// Every rank's call starts here: a session that stopped throws at once (its ranks agreed on that, or
// a late rank learns it at this call's agreement); the caller's refusal and this rank's failure since
// the last call are told to every rank now.
int Session::Impl::agree(Call call, CallRecord record, std::exception_ptr error, Failure severity, int stop) {
  if (!stopped.empty()) throw Error(stopped);
  record.call = call;
  record.snapshots = snapshots;
  if (!error && !deferred_failure.empty()) {
    error = std::make_exception_ptr(Error(deferred_failure));
    severity = Failure::failed;
  } else if (!error && !caller_refusal.empty()) {
    error = std::make_exception_ptr(UsageError(caller_refusal));
    severity = Failure::refused;
  }
  caller_refusal.clear();
  try {
    return agreement.agree(record, error, severity, stop);
  } catch (const AgreementError& e) {
    if (e.stops()) stopped = std::string("the session stopped: ") + e.what();
    throw;
  } catch (const std::exception& e) {
    if (severity == Failure::failed) stopped = std::string("the session stopped: ") + e.what();
    throw;
  }
}

Session::Session(const SessionConfig& config, const render::GridGeometry& grid, const LocalBlock& block,
                 std::shared_ptr<OverheadMeter> meter)
    : impl_(std::make_unique<Impl>()) {
  impl_->meter = meter ? std::move(meter) : std::make_shared<OverheadMeter>();
  OverheadMeter::Scope counted(*impl_->meter);
  impl_->cfg = config;
  impl_->grid = grid;
  impl_->block = block;
#ifdef PANOPTES_HAVE_MPI
  int init = 0;
  MPI_Initialized(&init);
  if (init) {
    MPI_Comm_dup(MPI_COMM_SELF, &impl_->comm);
  }
#endif
  impl_->init();
}

#ifdef PANOPTES_HAVE_MPI
Session::Session(const SessionConfig& config, const render::GridGeometry& grid, const LocalBlock& block, MPI_Comm comm,
                 std::shared_ptr<OverheadMeter> meter)
    : impl_(std::make_unique<Impl>()) {
  impl_->meter = meter ? std::move(meter) : std::make_shared<OverheadMeter>();
  OverheadMeter::Scope counted(*impl_->meter);
  impl_->cfg = config;
  impl_->grid = grid;
  impl_->block = block;
  // The agreements' own communicator first: its duplication waits at most the timeout for every rank,
  // so a rank that never starts its session cannot hang the others in the duplication below.
  impl_->agreement = RankAgreement(comm, config.mpi_timeout);
  MPI_Comm_dup(comm, &impl_->comm);
  MPI_Comm_rank(impl_->comm, &impl_->rank);
  MPI_Comm_size(impl_->comm, &impl_->size);
  impl_->init();
}
#endif


Session::Session(const SessionConfig& config, const grid::GridDescription& source, const std::vector<GridBlock>& blocks,
                 const ResampleOptions& resample, std::shared_ptr<OverheadMeter> meter)
    : impl_(std::make_unique<Impl>()) {
  impl_->meter = meter ? std::move(meter) : std::make_shared<OverheadMeter>();
  OverheadMeter::Scope counted(*impl_->meter);
  impl_->cfg = config;
#ifdef PANOPTES_HAVE_MPI
  impl_->start_grid_stage(source, blocks, resample, MPI_COMM_NULL);
  int init = 0;
  MPI_Initialized(&init);
  if (init) MPI_Comm_dup(MPI_COMM_SELF, &impl_->comm);
#else
  impl_->start_grid_stage(source, blocks, resample);
#endif
  impl_->init();
}

#ifdef PANOPTES_HAVE_MPI
Session::Session(const SessionConfig& config, const grid::GridDescription& source, const std::vector<GridBlock>& blocks,
                 const ResampleOptions& resample, MPI_Comm comm, std::shared_ptr<OverheadMeter> meter)
    : impl_(std::make_unique<Impl>()) {
  impl_->meter = meter ? std::move(meter) : std::make_shared<OverheadMeter>();
  OverheadMeter::Scope counted(*impl_->meter);
  impl_->cfg = config;
  impl_->agreement = RankAgreement(comm, config.mpi_timeout);
  impl_->start_grid_stage(source, blocks, resample, comm);
  MPI_Comm_dup(comm, &impl_->comm);
  MPI_Comm_rank(impl_->comm, &impl_->rank);
  MPI_Comm_size(impl_->comm, &impl_->size);
  impl_->init();
}
#endif

Session::~Session() {
#ifdef PANOPTES_HAVE_MPI
  if (impl_ && impl_->comm != MPI_COMM_NULL) {
    int fin = 0;
    MPI_Finalized(&fin);
    if (!fin) MPI_Comm_free(&impl_->comm);
  }
#endif
  // The corner copies' blocks were kept for the next snapshot's (render/corner_field.hpp): there is none.
  impl_.reset();
  render::release_idle_huge_blocks();
}

// The schedule's answer on this rank (the agreement before it made every rank's arguments and state alike).
bool Session::Impl::due_here(std::int64_t step, double time) const {
  const ScheduleConfig& s = cfg.schedule;
  if (finalized) return false;
  if (s.max_snapshots > 0 && snapshots >= s.max_snapshots) return false;
  if (repeated(time)) return false;
  if (s.every_steps > 0) return step % s.every_steps == 0;
  return time >= next_time - 1e-9 * s.every_time;
}

namespace {
std::exception_ptr finite_refusal(const char* call, double time) {
  if (std::isfinite(time)) return nullptr;
  return std::make_exception_ptr(UsageError(std::string(call) + ": time " + number_text(time) +
                                            "; expected a finite simulation time"));
}
}  // namespace

bool Session::due(std::int64_t step, double time) const {
  Impl& m = *impl_;
  OverheadMeter::Scope counted(*m.meter);
  // Collective (issue 42): ranks that disagree here (another step or time, a skipped call) would take
  // different snapshots and wait for each other in the next one.
  m.agree(Call::due, CallRecord::at(step, time), finite_refusal("due", time), Failure::refused);
  return m.due_here(step, time);
}

void Session::snapshot(double time, const std::vector<FieldInput>& fields) {
  Impl& m = *impl_;
  OverheadMeter::Scope counted(*m.meter);  // also when it throws
  m.take_snapshot(time, fields);
}

void Session::Impl::take_snapshot(double time, const std::vector<FieldInput>& fields) {
  Impl& m = *this;
  if (m.finalized) throw Error("snapshot: the session is finalized");
  // [output] mode = "resume": a restarted run repeats the steps since its checkpoint; what the
  // database already holds is not written twice (the same time on every rank: the same decision).
  // NaN is never a repeat: it is refused below.
  const bool repeat = m.repeated(time);
  // The time and the fields are this rank's own arguments (another rank's may be fine): every rank
  // learns in the snapshot's agreement whether any refused its own, and then all refuse this snapshot
  // instead of waiting for that rank in the snapshot's collectives. SIGINT/SIGTERM (when the program
  // installed core/stop_request.hpp's handlers, as `panoptes run` does) is agreed there too: every
  // rank stops before this snapshot; the writer's destructor marks the database interrupted.
  std::exception_ptr refusal;
  if (!repeat) {
    refusal = m.time_refusal(time);
    if (!refusal) refusal = m.adapter ? m.grid_field_refusal(fields) : m.field_refusal(fields);
  }
  const int stop = m.agree(Call::snapshot, CallRecord::at(-1, time), refusal, Failure::refused, stop_requested());
  if (stop)
    throw Interrupted(stop, m.cfg.output_dir + ": stopped by " + signal_name(stop) + " before snapshot " +
                                std::to_string(m.snapshots) + "; the database is marked interrupted");
  if (repeat) {
    if (m.rank == 0)
      log::info(m.cfg.output_dir + ": snapshot at time " + number_text(time) + " skipped: the resumed database already holds "
                "snapshots up to time " + number_text(m.last_time));
    return;
  }
  if (m.cfg.schedule.max_snapshots > 0 && m.snapshots >= m.cfg.schedule.max_snapshots)
    throw Error("snapshot: schedule.max_snapshots = " + std::to_string(m.cfg.schedule.max_snapshots) + " already taken");
  auto t0 = Clock::now();
  // The grid stage (collective: it gathers the source points each slab needs) only for a snapshot.
  m.load_fields(m.adapter ? m.adapter->adapt(fields) : fields);
  std::vector<double> ref(m.field_names.size());
  for (std::size_t f = 0; f < m.field_names.size(); ++f) {
    const FieldScale scale = m.cfg.scale_of(m.field_names[f]);
    if (scale.mode == ReferenceMode::fixed) {
      ref[f] = scale.value;  // the same on every rank: no quantile, no collective
      continue;
    }
    const double q = m.window_reference(int(f));
    const double running = m.references[f].update(q);
    ref[f] = std::max(scale.mode == ReferenceMode::running ? running : q, 1e-30);
  }
  m.last_references = ref;
  m.plan.resolve(ref, m.specs);
  m.prepare_fields();
  m.time.copy += since(t0);
  m.render_snapshot(m.snapshots);
  ++m.snapshots;
  ++m.written;
  m.last_time = time;
  if (m.cfg.schedule.every_time > 0)
    m.next_time = (std::floor(time / m.cfg.schedule.every_time + 1e-9) + 1) * m.cfg.schedule.every_time;
  m.checkpoint(time);
}

bool Session::process(std::int64_t step, double time, const std::vector<FieldInput>& fields) {
  Impl& m = *impl_;
  OverheadMeter::Scope counted(*m.meter);
  // One agreement every step (a few microseconds): a rank that skips a step's call, or passes another
  // step or time, is named at once instead of leaving the others waiting in the next snapshot (issue
  // 42). A time that is not finite is refused on every rank (due() cannot answer for it).
  m.agree(Call::process, CallRecord::at(step, time), finite_refusal("process", time), Failure::refused);
  if (!m.due_here(step, time)) return false;
  m.take_snapshot(time, fields);
  return true;
}

void Session::refuse_next_call(const std::string& message) { impl_->caller_refusal = message; }

void Session::finalize() {
  Impl& m = *impl_;
  if (m.finalized) return;
  {
    OverheadMeter::Scope counted(*m.meter);
    int frames = INT_MAX;
    std::exception_ptr local;
    try {
      if (m.writer && !m.owned.empty()) {
        m.writer->flush();
        frames = m.writer->complete_frames();
      }
    } catch (...) {
      local = std::current_exception();
    }
    m.agree(Call::finalize, CallRecord{}, local, Failure::failed);
    m.finalized = true;
    m.warn_invisible_tasks();
#ifdef PANOPTES_HAVE_MPI
    if (m.size > 1) MPI_Allreduce(MPI_IN_PLACE, &frames, 1, MPI_INT, MPI_MIN, m.comm);
#endif
    if (m.rank != 0 && m.writer) m.writer->finalize();
    m.barrier();
    if (m.rank == 0) m.writer->finalize(frames == INT_MAX ? m.snapshots : frames);
    m.barrier();
  }
  m.meter->stop();  // the run's end for the report
}

void Session::set_frame_observer(FrameObserver observer) { impl_->observer = std::move(observer); }
int Session::rank() const { return impl_->rank; }
int Session::ranks() const { return impl_->size; }
int Session::camera_count() const { return impl_->rig.size(); }
int Session::task_count() const { return int(impl_->plan.size()); }
int Session::snapshots() const { return impl_->snapshots; }
const std::vector<std::string>& Session::field_names() const { return impl_->field_names; }
const std::string& Session::output_dir() const { return impl_->cfg.output_dir; }

SessionStats Session::stats() const {
  const Impl& m = *impl_;
  SessionStats s;
  s.snapshots = m.snapshots;
  s.frames_encoded = m.frames_encoded;
  s.owned_cameras = int(m.owned.size());
  for (const auto& b : m.buffers) s.field_buffer_bytes += std::int64_t(b.capacity() * sizeof(float));
  for (const auto& p : m.prepared) s.field_buffer_bytes += std::int64_t(p.corners.bytes());
  auto add = [&](const render::PartialImage& p) {
    s.partial_buffer_bytes += std::int64_t((p.rgba.capacity() + p.depth.capacity() + p.rgba_open.capacity()) * sizeof(float) +
                                           p.sliver_end.capacity());
  };
  for (const auto& v : m.partials)
    for (const auto& p : v) add(p);
  for (const auto& v : m.received)
    for (const auto& p : v) add(p);
  for (const auto& p : m.composited) add(p);
  for (const auto& b : m.send_buf) s.partial_buffer_bytes += std::int64_t(b.capacity());
  s.partial_buffer_bytes += std::int64_t(m.recv_buf.capacity());
  s.peak_rss_bytes = Impl::peak_rss();
  s.time = m.time;
  const RankOverhead o = m.meter->read();
  s.session_seconds = o.visualization_wall_s;
  s.elapsed_seconds = o.elapsed_wall_s;
  s.visualization_cpu_seconds = o.visualization_cpu_s;
  s.simulation_cpu_seconds = o.simulation_cpu_s;
  return s;
}

std::vector<RankOverhead> Session::overhead() const {
  RankOverhead mine = impl_->meter->read();
  mine.rank = impl_->rank;
  constexpr int kValues = 4;
  const double values[kValues] = {mine.visualization_cpu_s, mine.simulation_cpu_s, mine.visualization_wall_s,
                                  mine.elapsed_wall_s};
  std::vector<double> all(values, values + kValues);
#ifdef PANOPTES_HAVE_MPI
  Impl& m = *impl_;
  m.agree(Call::report, CallRecord{});
  if (m.size > 1) {
    all.resize(kValues * std::size_t(m.size));
    MPI_Allgather(values, kValues, MPI_DOUBLE, all.data(), kValues, MPI_DOUBLE, m.comm);
  }
#endif
  std::vector<RankOverhead> out;
  for (std::size_t r = 0; r + kValues <= all.size(); r += kValues)
    out.push_back({int(r / kValues), all[r], all[r + 1], all[r + 2], all[r + 3]});
  return out;
}

SessionStats Session::reduced_stats() const {
  SessionStats s = stats();
#ifdef PANOPTES_HAVE_MPI
  Impl& m = *impl_;
  m.agree(Call::report, CallRecord{});
  if (m.size > 1) {
    double t[5] = {s.time.copy, s.time.render, s.time.composite, s.time.encode, s.time.checkpoint};
    MPI_Allreduce(MPI_IN_PLACE, t, 5, MPI_DOUBLE, MPI_MAX, m.comm);
    s.time = {t[0], t[1], t[2], t[3], t[4]};
    std::int64_t c[2] = {s.frames_encoded, s.owned_cameras};
    MPI_Allreduce(MPI_IN_PLACE, c, 2, MPI_INT64_T, MPI_SUM, m.comm);
    s.frames_encoded = c[0];
    s.owned_cameras = int(c[1]);
    std::int64_t mx[3] = {s.field_buffer_bytes, s.partial_buffer_bytes, s.peak_rss_bytes};
    MPI_Allreduce(MPI_IN_PLACE, mx, 3, MPI_INT64_T, MPI_MAX, m.comm);
    s.field_buffer_bytes = mx[0];
    s.partial_buffer_bytes = mx[1];
    s.peak_rss_bytes = mx[2];
  }
#endif
  return s;
}

}  // namespace panoptes::insitu
