#include "insitu/session_impl.hpp"

#include "insitu/partial_message.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <tuple>

namespace panoptes::insitu {

// Copies (and converts) every field to float32 over this rank's required point range: the points
// its arrays hold valid values for are read there, the others come from their owners (halo.hpp).
// This rank's fields, checked before the snapshot's first collective (the caller agrees on the
// outcome with the other ranks, so a refusal on one rank cannot leave the others waiting): every field
// a task reads is given, and its strides address the ghosted block without overflowing 64-bit offsets
// (FieldInput carries no size; a wrapped offset would read plane 0 for every z, or far outside).
// This rank's snapshot time: finite, and after the previous snapshot's (a resumed run's repeats were
// skipped before). Checked with the fields, before the snapshot's first collective.
std::exception_ptr Session::Impl::time_refusal(double time) const {
  if (!std::isfinite(time))
    return std::make_exception_ptr(UsageError("snapshot: time " + number_text(time) + "; expected a finite simulation time"));
  if (std::isfinite(last_time) && !(time > last_time))
    return std::make_exception_ptr(UsageError(
        "snapshot: time " + number_text(time) + " is not after the previous snapshot's time " + number_text(last_time) +
        "; snapshot times must increase" +
        (resumed && written > 0 ? " (a resumed run skips only the times it repeats before its first new snapshot)" : "")));
  return nullptr;
}

std::exception_ptr Session::Impl::field_refusal(const std::vector<FieldInput>& fields) const {
  for (const std::string& name : field_names) {
    const FieldInput* in = nullptr;
    for (const FieldInput& x : fields)
      if (x.name == name) in = &x;
    if (!in || !in->data)
      return std::make_exception_ptr(Error("snapshot: field \"" + name + "\" (read by a task) was not given or has no data"));
    const LocalBlock& lb = block;
    const std::array<std::int64_t, 3> st = halo::field_strides(lb, in->stride);
    const std::array<std::int64_t, 3> n{std::int64_t(lb.extent[0]) + lb.ghost_lo[0] + lb.ghost_hi[0],
                                        std::int64_t(lb.extent[1]) + lb.ghost_lo[1] + lb.ghost_hi[1],
                                        std::int64_t(lb.extent[2]) + lb.ghost_lo[2] + lb.ghost_hi[2]};
    const std::int64_t elem = in->type == ScalarType::f64 ? 8 : 4;
    if (!strided_reach(n, st, elem, {lb.ghost_lo[0], lb.ghost_lo[1], lb.ghost_lo[2]}))
      return std::make_exception_ptr(UsageError(
          "snapshot: field \"" + name + "\": strides (" + std::to_string(st[0]) + ", " + std::to_string(st[1]) + ", " +
          std::to_string(st[2]) + ") over the ghosted block (" + std::to_string(n[0]) + ", " + std::to_string(n[1]) + ", " +
          std::to_string(n[2]) + ") reach further than 64-bit offsets can address; expected the strides of an array in memory"));
  }
  return nullptr;
}

void Session::Impl::load_fields(const std::vector<FieldInput>& fields) {
  const BlockInfo& b = me();
  const Box& req = b.has_brick ? b.required : b.owned;
  buffers.resize(field_names.size());
  std::vector<const FieldInput*> inputs(field_names.size());
  for (std::size_t f = 0; f < field_names.size(); ++f) {
    for (const FieldInput& in : fields)
      if (in.name == field_names[f]) inputs[f] = &in;
    if (!inputs[f] || !inputs[f]->data)  // refused by field_refusal() before the snapshot's collectives
      throw Error("snapshot: field \"" + field_names[f] + "\" (read by a task) was not given or has no data");
    buffers[f].resize(std::size_t(req.size()));
  }
  exchange.load(inputs, req, buffers);
  prepared.clear();
}

void Session::Impl::prepare_fields() {
  prepared.clear();
  const BlockInfo& b = me();
  if (!b.has_brick) return;
  const Box& req = b.required;
  render::PointRange pr{req.lo, req.hi};
  std::vector<render::FieldView> views;
  for (std::size_t f = 0; f < field_names.size(); ++f)
    views.push_back(render::FieldView::of_brick(grid, b.brick, pr, buffers[f].data()));
  // Every camera renders every task in one march: the fields the volume tasks read together get one
  // interleaved corner copy, clamped to what this snapshot's windows tell apart (render::prepare_fields()),
  // so the tasks' references must be resolved first.
  prepared = render::prepare_fields(views, specs);
}

// The q-quantile of |v| over a fixed lattice of global points (the same set whatever the
// decomposition, so the reference — and every image — does not depend on the number of ranks).
double Session::Impl::global_percentile(int f) {
  const std::int64_t total = std::int64_t(grid.dims[0]) * grid.dims[1] * grid.dims[2];
  const int s = std::max(1, int(std::ceil(std::cbrt(double(total) / 65536.0))));
  const BlockInfo& b = me();
  const Box& req = b.has_brick ? b.required : b.owned;
  const Index3 rd{req.hi[0] - req.lo[0], req.hi[1] - req.lo[1], req.hi[2] - req.lo[2]};
  std::vector<float> mine;
  const std::vector<float>& buf = buffers[std::size_t(f)];
  auto first = [&](int lo) { return (lo + s - 1) / s * s; };
  for (int k = first(b.owned.lo[2]); k < b.owned.hi[2]; k += s)
    for (int j = first(b.owned.lo[1]); j < b.owned.hi[1]; j += s)
      for (int i = first(b.owned.lo[0]); i < b.owned.hi[0]; i += s)
      {
        // NaN and infinite values (rendered as empty) are no reference: an all-NaN volume gave a NaN window.
        const float v = std::fabs(buf[std::size_t((std::int64_t(k - req.lo[2]) * rd[1] + (j - req.lo[1])) * rd[0] +
                                                  (i - req.lo[0]))]);
        if (std::isfinite(v)) mine.push_back(v);
      }
  std::vector<float> all;
#ifdef PANOPTES_HAVE_MPI
  if (size > 1) {
    int n = int(mine.size());
    std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size));
    MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
    int sum = 0;
    for (int r = 0; r < size; ++r) displs[std::size_t(r)] = sum, sum += counts[std::size_t(r)];
    all.resize(std::size_t(sum));
    MPI_Allgatherv(mine.data(), n, MPI_FLOAT, all.data(), counts.data(), displs.data(), MPI_FLOAT, comm);
  } else
#endif
    all = std::move(mine);
  if (all.empty()) return 0;
  const std::size_t idx = std::size_t(std::llround(cfg.percentile * double(all.size() - 1)));
  std::nth_element(all.begin(), all.begin() + std::ptrdiff_t(idx), all.end());
  return all[idx];
}

// The reference relative windows are multiples of: this snapshot's percentile of |v|, but at least
// kReferenceFloor x its maximum |v| (over every owned cell). While the waves fill fewer than 1 - percentile
// of the samples (the demo's first snapshot, t = 0.32 s: the source region is ~0.1 % of the grid), the
// percentile lands in the numerical precursor ahead of them, ~1e-4 x the maximum, and a window relative
// to it lit the whole box (24 % of the pixels against 0.4 % at the next snapshot). The floor was 0.001
// while windows reached up to 1 x the reference; on the running scale (issue 41) the demo's windows end at
// 0.05-0.15 x it, so the precursor at the first snapshot must sit below 0.1 x 0.05 x the floor: at 0.001
// the first p+s frame was lit on 242,564 of 936,000 pixels against 8,493 at the next (cli.demo_first_frame),
// at 0.02 it is clean. The cost: near the source the floor, not the percentile, sets phi_p's running
// maximum (4.6e-4 against 1.5e-4 1/s in the demo; phi_s's, 6.4e-4, and so the shared p+s scale, are
// unchanged), which the demo's p-wave window [0, 0.05] allows for.
double Session::Impl::window_reference(int f) {
  constexpr double kReferenceFloor = 0.02;
  const BlockInfo& b = me();
  const Box& req = b.has_brick ? b.required : b.owned;
  const Index3 rd{req.hi[0] - req.lo[0], req.hi[1] - req.lo[1], req.hi[2] - req.lo[2]};
  const std::vector<float>& buf = buffers[std::size_t(f)];
  float peak = 0;
  for (int k = b.owned.lo[2]; k < b.owned.hi[2]; ++k)
    for (int j = b.owned.lo[1]; j < b.owned.hi[1]; ++j) {
      const std::size_t row = std::size_t((std::int64_t(k - req.lo[2]) * rd[1] + (j - req.lo[1])) * rd[0]);
      for (int i = b.owned.lo[0]; i < b.owned.hi[0]; ++i)
        if (const float v = std::fabs(buf[row + std::size_t(i - req.lo[0])]); std::isfinite(v)) peak = std::max(peak, v);
    }
#ifdef PANOPTES_HAVE_MPI
  if (size > 1) MPI_Allreduce(MPI_IN_PLACE, &peak, 1, MPI_FLOAT, MPI_MAX, comm);
#endif
  return std::max(global_percentile(f), kReferenceFloor * double(peak));
}


render::OutlineStyle outline_style(const SessionConfig& cfg) {
  render::OutlineStyle outline;
  // In a 360° frame the box edges are arcs, and the horizon and compass show where to turn (issue 32).
  outline.enabled = cfg.outline || (cfg.compass && cfg.projection == "equirectangular");
  outline.box = cfg.outline;
  outline.compass = cfg.compass;
  outline.sky = camera::SkyFrame::of(cfg.up_axis.empty() ? camera::UpAxis::z_up : camera::parse_up_axis(cfg.up_axis));
  return outline;
}

// One rank rendering one sweep: per camera render_sweep() into 8-bit frames, then each task's frame
// finished and encoded from them, tasks in parallel (appends to different streams may run
// concurrently). The session holds one camera's sweep frames (4 bytes per pixel and task) and per
// thread one partial image and one frame, whatever the number of tasks.
void Session::Impl::render_sweep_snapshot(int frame) {
  const int C = rig.size();
  const int K = int(plan.size());
  const render::Rgb bg{cfg.background[0], cfg.background[1], cfg.background[2]};
  const render::OutlineStyle outline = outline_style(cfg);
  store::DatabaseWriter& w = *writer;
  for (int c = 0; c < C; ++c) {
    auto t0 = Clock::now();
    const camera::Camera& cam = cameras[std::size_t(c)];
    render::render_sweep(cam, prepared, specs, sweep_frames, cfg.render);
    time.render += since(t0);
    if (!deferred_failure.empty()) continue;  // a failed append: this rank encodes no more
    t0 = Clock::now();
    std::exception_ptr error;
#pragma omp parallel
    {
      render::PartialImage part;
      Image image;
#pragma omp for schedule(dynamic)
      for (int t = 0; t < K; ++t) {
        try {
          sweep_frames.to_partial(t, part);  // (not note_shown(): a sweep's values may show nothing, on purpose)
          render::finish_image_into(part, cam, grid, image, bg, outline);
          if (observer) {
#pragma omp critical(panoptes_sweep_observer)
            observer(c, t, frame, image);
          }
          w.append(c, t, image);
        } catch (...) {
#pragma omp critical(panoptes_encode_error)
          if (!error) error = std::current_exception();
        }
      }
    }
    if (error) {
      deferred_failure = "encoding on rank " + std::to_string(rank) + " failed: " + exception_message(error);
      continue;
    }
    frames_encoded += K;
    time.encode += since(t0);
  }
}


void Session::Impl::finish_camera(int camera, int frame) {
  const int K = int(plan.size());
  const render::Rgb bg{cfg.background[0], cfg.background[1], cfg.background[2]};
  const render::OutlineStyle outline = outline_style(cfg);
  const camera::Camera& cam = cameras[std::size_t(camera)];
  // One task at a time: composite() and finish_image() are parallel over pixels, which keeps
  // both cores busy for any K (a loop over K = 3 tasks on 2 threads left one idle a third of the time).
  std::vector<Image>& images = batch[std::size_t(batch_n)];
  for (int t = 0; t < K; ++t) {
    const std::vector<const render::PartialImage*>& p = parts[std::size_t(t)];
    Image& out = images[std::size_t(t)];
    if (p.empty()) {
      empty_partial.reset(cfg.width, cfg.height, {0, 0, 0, 0});
      render::finish_image_into(empty_partial, cam, grid, out, bg, outline);
    } else if (p.size() == 1) {
      note_shown(t, frame, *p[0]);
      render::finish_image_into(*p[0], cam, grid, out, bg, outline);
    } else {
      render::composite_into(specs[std::size_t(t)].kind, p, composited[std::size_t(t)]);  // the kind's blend
      note_shown(t, frame, composited[std::size_t(t)]);
      render::finish_image_into(composited[std::size_t(t)], cam, grid, out, bg, outline);
    }
  }
  if (observer)
    for (int t = 0; t < K; ++t) observer(camera, t, frame, images[std::size_t(t)]);
  batch_camera[std::size_t(batch_n)] = camera;
  ++batch_n;
}

// RenderSplit::cameras: this rank holds the whole grid and renders its own cameras through it; the
// frames are those one rank rendering everything makes, and no rank waits for another's partials.
void Session::Impl::render_own_cameras(int frame) {
  const int K = int(plan.size());
  const bool brick = me().has_brick;
  for (int c : owned) {
    for (auto& p : parts) p.clear();
    if (brick) {
      const auto t0 = Clock::now();
      render::render_brick(cameras[std::size_t(c)], prepared, specs, partials[0], cfg.render);
      time.render += since(t0);
      for (int t = 0; t < K; ++t) parts[std::size_t(t)].push_back(&partials[0][std::size_t(t)]);
    }
    const auto t0 = Clock::now();
    finish_camera(c, frame);
    time.composite += since(t0);
    if (batch_n == int(batch.size())) encode_batch();
  }
  encode_batch();
}

void Session::Impl::note_shown(int task, int frame, const render::PartialImage& p) {
  std::vector<char>& f = shown[std::size_t(task)];
  if (f[std::size_t(frame)] == 2) return;  // one camera is enough: most frames cost one short scan
  constexpr float kVisible = 2.0f / 255.0f;
  const std::size_t n = p.rgba.size();
  for (std::size_t i = 3; i < n; i += 4)
    if (p.rgba[i] > kVisible) {
      f[std::size_t(frame)] = 2;
      return;
    }
}

void Session::Impl::render_snapshot(int frame) {
  shown.resize(plan.size());
  for (auto& f : shown) {
    f.resize(std::max(f.size(), std::size_t(frame) + 1), 0);
    f[std::size_t(frame)] = 1;  // rendered here; 2 once something showed
  }
  if (sweep && render::is_sweep(specs)) return render_sweep_snapshot(frame);
  if (split == RenderSplit::cameras) return render_own_cameras(frame);
  const int C = rig.size();
  const int K = int(plan.size());
#ifdef PANOPTES_HAVE_MPI
  if (size > C) return render_snapshot_banded(frame);
#endif
  const bool brick = me().has_brick;
  for (int r0 = 0; r0 < C; r0 += size) {
    // Render every camera of this round, sending each partial set to its owner at once.
#ifdef PANOPTES_HAVE_MPI
    std::vector<MPI_Request> sends;
#endif
    for (int c = r0; c < std::min(C, r0 + size); ++c) {
      if (!brick) continue;
      const int slot = c - r0;
      auto t0 = Clock::now();
      render::render_brick(cameras[std::size_t(c)], prepared, specs, partials[std::size_t(slot)], cfg.render);
      time.render += since(t0);
      if (owner(c) != rank) {
#ifdef PANOPTES_HAVE_MPI
        t0 = Clock::now();
        std::vector<char>& buf = send_buf[std::size_t(slot)];
        buf.clear();
        for (const auto& p : partials[std::size_t(slot)]) pack(p, buf);
        sends.emplace_back();
        MPI_Isend(buf.data(), int(buf.size()), MPI_BYTE, owner(c), 11, comm, &sends.back());
        time.composite += since(t0);
#endif
      }
    }
    const int mine = r0 + rank;
    if (mine < C) {
      auto t0 = Clock::now();
      // Partials of my camera in rank order (a deterministic order: composite() sorts per pixel).
      for (auto& p : parts) p.clear();
      for (int s = 0; s < size; ++s) {
        if (!blocks[std::size_t(s)].has_brick) continue;
        if (s == rank) {
          for (int t = 0; t < K; ++t) parts[std::size_t(t)].push_back(&partials[std::size_t(rank)][std::size_t(t)]);
          continue;
        }
#ifdef PANOPTES_HAVE_MPI
        MPI_Status st;
        MPI_Probe(s, 11, comm, &st);
        int bytes = 0;
        MPI_Get_count(&st, MPI_BYTE, &bytes);
        recv_buf.resize(std::size_t(bytes));
        MPI_Recv(recv_buf.data(), bytes, MPI_BYTE, s, 11, comm, MPI_STATUS_IGNORE);
        const char* p = recv_buf.data();
        const char* end = p + bytes;
        for (int t = 0; t < K; ++t) {
          p = unpack(p, end, cfg.width, cfg.height, received[std::size_t(s)][std::size_t(t)]);
          parts[std::size_t(t)].push_back(&received[std::size_t(s)][std::size_t(t)]);
        }
#endif
      }
      finish_camera(mine, frame);
      time.composite += since(t0);
      if (batch_n == int(batch.size())) encode_batch();
    }
#ifdef PANOPTES_HAVE_MPI
    if (!sends.empty()) {
      auto t0 = Clock::now();
      MPI_Waitall(int(sends.size()), sends.data(), MPI_STATUSES_IGNORE);
      time.composite += since(t0);
    }
#endif
  }
  encode_batch();
}

void Session::Impl::encode_batch() {
  // After a failed append this rank encodes no more (its movies are incomplete), but it goes on with
  // the snapshot's exchanges: the other ranks wait for its partial images, and the snapshot's last
  // agreement tells them all of the failure (issue 42: a full disk on one rank hung the others).
  if (!deferred_failure.empty()) batch_n = 0;
  if (batch_n == 0) return;
  const auto t0 = Clock::now();
  const int K = int(plan.size());
  store::DatabaseWriter& w = *writer;
  // Frames of several cameras in one parallel loop: appends to different streams may run
  // concurrently, and batch_n × K frames share the threads evenly where K alone would not.
  // An exception must not leave an OpenMP region (the process would terminate): the first one is
  // kept and rethrown after the loop, e.g. a full disk as the FileError naming the movie.
  std::exception_ptr error;
#pragma omp parallel for schedule(dynamic)
  for (int f = 0; f < batch_n * K; ++f) {
    try {
      w.append(batch_camera[std::size_t(f / K)], f % K, batch[std::size_t(f / K)][std::size_t(f % K)]);
    } catch (...) {
#pragma omp critical(panoptes_encode_error)
      if (!error) error = std::current_exception();
    }
  }
  if (error) {
    deferred_failure = "encoding on rank " + std::to_string(rank) + " failed: " + exception_message(error);
    batch_n = 0;
    return;
  }
  frames_encoded += std::int64_t(batch_n) * K;
  batch_n = 0;
  time.encode += since(t0);
}

void Session::Impl::checkpoint(double t) {
  auto t0 = Clock::now();
  int frames = INT_MAX;
  std::exception_ptr local;
  try {
    if (writer) {
      writer->flush();
      if (!owned.empty()) frames = writer->complete_frames();
    }
  } catch (...) {
    local = std::current_exception();
  }
  // Every rank's encoding and flushing went well, or every rank learns which failed (this rank's
  // failed appends are in deferred_failure, which agree() reports).
  agree(Call::frames, CallRecord::at(-1, t), local, Failure::failed);
#ifdef PANOPTES_HAVE_MPI
  if (size > 1) MPI_Allreduce(MPI_IN_PLACE, &frames, 1, MPI_INT, MPI_MIN, comm);
#endif
  if (rank == 0) {
    try {
      writer->set_time(snapshots - 1, t);
      {  // every field's running maximum, so a resumed run continues the scale whatever its mode
        std::vector<double> refs;
        for (const render::RunningMax& ref : references) refs.push_back(ref.value());
        writer->set_note(kRunningMaxNote, format_references(refs));
      }
      for (std::size_t f = 0; f < last_references.size(); ++f)
        writer->set_field_reference(snapshots - 1, int(f), last_references[f]);
      writer->checkpoint(frames == INT_MAX ? snapshots : frames);
    } catch (const std::exception& e) {
      // The other ranks have returned: they learn of it at their next call.
      deferred_failure = std::string("rank 0 could not write the manifest: ") + e.what();
      throw;
    }
  }
  time.checkpoint += since(t0);
}

void Session::Impl::warn_invisible_tasks() {
  const int K = int(plan.size());
  const int F = snapshots;
  if (K == 0 || F == 0) return;
  std::vector<unsigned char> all(std::size_t(K) * std::size_t(F), 0);
  for (int t = 0; t < K && std::size_t(t) < shown.size(); ++t)
    for (int f = 0; f < F && std::size_t(f) < shown[std::size_t(t)].size(); ++f)
      all[std::size_t(t) * F + f] = static_cast<unsigned char>(shown[std::size_t(t)][std::size_t(f)]);
#ifdef PANOPTES_HAVE_MPI
  if (size > 1) MPI_Allreduce(MPI_IN_PLACE, all.data(), int(all.size()), MPI_UNSIGNED_CHAR, MPI_MAX, comm);
#endif
  if (rank != 0) return;
  for (int t = 0; t < K; ++t) {
    int rendered = 0, empty = 0;
    std::string ranges;
    int run_start = -1, listed = 0;
    auto close_run = [&](int end) {  // frames [run_start, end)
      if (run_start < 0) return;
      if (listed < 4) ranges += std::string(listed ? ", " : "") + std::to_string(run_start) +
                                (end - 1 > run_start ? "-" + std::to_string(end - 1) : "");
      else if (listed == 4) ranges += ", ...";
      ++listed;
      run_start = -1;
    };
    for (int f = 0; f < F; ++f) {
      const unsigned char v = all[std::size_t(t) * F + f];
      if (v >= 1) ++rendered;
      if (v == 1) {
        ++empty;
        if (run_start < 0) run_start = f;
      } else {
        close_run(f);
      }
    }
    close_run(F);
    // A few empty frames are physics (a wave not yet started); a quarter of the run is a scale or a
    // window that hides the field, which nobody would see until the movies are opened.
    const PlannedTask& p = plan.tasks()[std::size_t(t)];
    // A value of a parameter sweep that shows nothing is an answer (an isovalue above the field), not a
    // misconfigured scale.
    if (!p.entry.axes.empty()) continue;
    if (empty < 3 || 4 * empty < rendered) continue;
    std::string scale;
    if (p.shared && p.spec.field2 >= 0 && std::size_t(p.spec.field2) < field_names.size())
      scale = "; its windows are relative to the larger of " + field_names[std::size_t(p.spec.field)] + "'s and " +
              field_names[std::size_t(p.spec.field2)] + "'s references (a shared scale): lower them if the fields are weaker";
    else if (p.relative && p.spec.field >= 0 && std::size_t(p.spec.field) < field_names.size()) {
      const FieldScale fs = cfg.scale_of(field_names[std::size_t(p.spec.field)]);
      scale = fs.mode == ReferenceMode::fixed
                  ? "; its window is relative to " + field_names[std::size_t(p.spec.field)] + "'s fixed reference " +
                        number_text(fs.value) + ": lower it if the field is weaker"
                  : fs.mode == ReferenceMode::running
                        ? "; its window is relative to the largest reference so far of " +
                              field_names[std::size_t(p.spec.field)] +
                              ", which a source's near field can set far above the waves: a fixed reference may suit"
                        : "";
    }
    log::warn(cfg.output_dir + ": task \"" + p.entry.name + "\" showed nothing in " + std::to_string(empty) + " of " +
              std::to_string(rendered) + " frames (" + ranges + ") from any camera: every sample was transparent" + scale +
              " (docs/insitu.md, \"When running fails\")");
  }
}

}  // namespace panoptes::insitu
