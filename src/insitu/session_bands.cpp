// Band compositing (docs/scaling.md, "Compositing"): the session's schedule when ranks outnumber
// cameras.
#include "insitu/session_impl.hpp"

#include <algorithm>
#include <cstring>
#include <tuple>

#include "insitu/partial_message.hpp"

namespace panoptes::insitu {

#ifdef PANOPTES_HAVE_MPI
// More ranks than cameras (docs/scaling.md, "Compositing"): direct send to one owner per camera would
// leave P − C ranks without compositing work while each owner hears from every brick (the model gives an
// owner 9,999 messages and 574 MB per snapshot at 10^4 ranks), so each camera's image is cut into
// T = ⌈P/C⌉ bands of rows. A brick sends each band its rect meets the rows inside it; band j of camera
// c is composited by rank (c·T + j) mod P, which finishes it and sends its rows (RGBA8) to the camera's
// encoder, rank c (its owner, as with direct send). Pixels are composited from the same partials in
// the same (rank) order as by direct send, so the frames are the same.
void Session::Impl::render_snapshot_banded(int frame) {
  constexpr int kBandTag = 12, kRowsTag = 13;
  const int C = rig.size(), K = int(plan.size()), W = cfg.width, H = cfg.height;
  const int T = (size + C - 1) / C;
  const auto band_y0 = [&](int j) { return int(std::int64_t(H) * j / T); };
  const auto band_owner = [&](int c, int j) { return int((std::int64_t(c) * T + j) % size); };
  const render::Rgb bg{cfg.background[0], cfg.background[1], cfg.background[2]};
  const render::OutlineStyle outline = outline_style(cfg);
  std::vector<MPI_Request> sends;
  std::vector<int> count_to(std::size_t(size), 0);
  int messages = 0;
  const auto next_buffer = [&]() -> std::vector<char>& {
    if (int(band_send.size()) <= messages) band_send.resize(std::size_t(messages) + 1);
    std::vector<char>& b = band_send[std::size_t(messages++)];
    b.clear();
    return b;
  };
  // 1. Every camera's march; each band the brick's rect meets gets its rows of the K partials.
  for (int c = 0; c < C && me().has_brick; ++c) {
    auto t0 = Clock::now();
    std::vector<render::PartialImage>& mine = partials[0];
    render::render_brick(cameras[std::size_t(c)], prepared, specs, mine, cfg.render);
    time.render += since(t0);
    t0 = Clock::now();
    const render::PixelRect r = mine[0].rect;
    if (r.width() > 0 && r.height() > 0)
      for (int j = int(std::int64_t(r.y0) * T / H); j < T && band_y0(j) < r.y1; ++j) {
        const int a = std::max(r.y0, band_y0(j)), b = std::min(r.y1, band_y0(j + 1));
        if (b <= a) continue;
        std::vector<char>& buf = next_buffer();
        const std::int32_t head[2] = {c, j};
        buf.resize(sizeof head);
        std::memcpy(buf.data(), head, sizeof head);
        for (int t = 0; t < K; ++t) pack_rows(mine[std::size_t(t)], a, b, buf);
        sends.emplace_back();
        MPI_Isend(buf.data(), int(buf.size()), MPI_BYTE, band_owner(c, j), kBandTag, comm, &sends.back());
        ++count_to[std::size_t(band_owner(c, j))];
      }
    time.composite += since(t0);
  }
  auto t0 = Clock::now();
  // 2. How many band messages this rank receives, then all of them.
  int incoming = 0;
  MPI_Reduce_scatter_block(count_to.data(), &incoming, 1, MPI_INT, MPI_SUM, comm);
  struct Received {
    int camera, band, source;
    std::size_t index;
  };
  std::vector<Received> got;
  if (int(band_recv.size()) < incoming) band_recv.resize(std::size_t(incoming));
  for (int i = 0; i < incoming; ++i) {
    MPI_Status st;
    MPI_Probe(MPI_ANY_SOURCE, kBandTag, comm, &st);
    int bytes = 0;
    MPI_Get_count(&st, MPI_BYTE, &bytes);
    std::vector<char>& buf = band_recv[std::size_t(i)];
    buf.resize(std::size_t(bytes));
    MPI_Recv(buf.data(), bytes, MPI_BYTE, st.MPI_SOURCE, kBandTag, comm, MPI_STATUS_IGNORE);
    std::int32_t head[2] = {-1, -1};
    if (bytes >= int(sizeof head)) std::memcpy(head, buf.data(), sizeof head);
    if (head[0] < 0 || head[0] >= C || head[1] < 0 || head[1] >= T || band_owner(head[0], head[1]) != rank)
      throw Error("in-situ compositing: band message from rank " + std::to_string(st.MPI_SOURCE) + " names camera " +
                  std::to_string(head[0]) + " band " + std::to_string(head[1]) + ", which rank " + std::to_string(rank) +
                  " does not composite");
    got.push_back({head[0], head[1], st.MPI_SOURCE, std::size_t(i)});
  }
  // The same order of partials as direct send: by camera, band, then sending rank.
  std::sort(got.begin(), got.end(), [](const Received& x, const Received& y) {
    return std::tie(x.camera, x.band, x.source) < std::tie(y.camera, y.band, y.source);
  });
  // 3. Composite and finish every band this rank owns; its rows go to the camera's encoder.
  std::vector<Image>& images = batch[0];
  for (Image& im : images)
    if (im.width != W || im.height != H || im.channels != 4) im = Image(W, H, 4);
  std::size_t g = 0;
  for (int band = rank; band < C * T; band += size) {
    const int c = band / T, j = band % T;
    const camera::Camera& cam = cameras[std::size_t(c)];
    for (auto& p : parts) p.clear();
    std::size_t used = 0;
    while (g < got.size() && got[g].camera == c && got[g].band == j) {
      const std::vector<char>& buf = band_recv[got[g].index];
      const char* p = buf.data() + 2 * sizeof(std::int32_t);
      if (band_parts.size() <= used) band_parts.resize(used + 1, std::vector<render::PartialImage>(std::size_t(K)));
      for (int t = 0; t < K; ++t) {
        p = unpack(p, buf.data() + buf.size(), W, H, band_parts[used][std::size_t(t)]);
        parts[std::size_t(t)].push_back(&band_parts[used][std::size_t(t)]);
      }
      ++used, ++g;
    }
    const int y0 = band_y0(j), y1 = band_y0(j + 1);
    std::vector<char>* rows = nullptr;
    if (c != rank) {
      rows = &next_buffer();
      const std::int32_t head[2] = {c, j};
      rows->resize(sizeof head + std::size_t(K) * std::size_t(y1 - y0) * std::size_t(W) * 4);
      std::memcpy(rows->data(), head, sizeof head);
    }
    for (int t = 0; t < K; ++t) {
      const std::vector<const render::PartialImage*>& p = parts[std::size_t(t)];
      Image& out = band_image;
      if (p.empty()) {
        empty_partial.reset(W, H, {0, 0, 0, 0});
        render::finish_image_into(empty_partial, cam, grid, out, bg, outline);
      } else if (p.size() == 1) {
        note_shown(t, frame, *p[0]);
        render::finish_image_into(*p[0], cam, grid, out, bg, outline);
      } else {
        render::composite_into(specs[std::size_t(t)].kind, p, composited[std::size_t(t)]);
        note_shown(t, frame, composited[std::size_t(t)]);
        render::finish_image_into(composited[std::size_t(t)], cam, grid, out, bg, outline);
      }
      const std::size_t row_bytes = std::size_t(W) * 4, n = row_bytes * std::size_t(y1 - y0);
      if (rows)
        std::memcpy(rows->data() + 2 * sizeof(std::int32_t) + std::size_t(t) * n, out.row(y0), n);
      else
        std::memcpy(images[std::size_t(t)].row(y0), out.row(y0), n);
    }
    if (rows) {
      sends.emplace_back();
      MPI_Isend(rows->data(), int(rows->size()), MPI_BYTE, c, kRowsTag, comm, &sends.back());
    }
  }
  // 4. The encoder of camera `rank` gathers the rows the other band owners finished.
  if (rank < C) {
    int expected = 0;
    for (int j = 0; j < T; ++j) expected += band_owner(rank, j) != rank;
    for (int i = 0; i < expected; ++i) {
      MPI_Status st;
      MPI_Probe(MPI_ANY_SOURCE, kRowsTag, comm, &st);
      int bytes = 0;
      MPI_Get_count(&st, MPI_BYTE, &bytes);
      recv_buf.resize(std::size_t(bytes));
      MPI_Recv(recv_buf.data(), bytes, MPI_BYTE, st.MPI_SOURCE, kRowsTag, comm, MPI_STATUS_IGNORE);
      std::int32_t head[2] = {-1, -1};
      if (bytes >= int(sizeof head)) std::memcpy(head, recv_buf.data(), sizeof head);
      const int j = head[1];
      const std::size_t n = (head[0] == rank && j >= 0 && j < T) ? std::size_t(W) * 4 * std::size_t(band_y0(j + 1) - band_y0(j)) : 0;
      if (!n || std::size_t(bytes) != 2 * sizeof(std::int32_t) + std::size_t(K) * n)
        throw Error("in-situ compositing: finished rows from rank " + std::to_string(st.MPI_SOURCE) + " for camera " +
                    std::to_string(head[0]) + " band " + std::to_string(j) + " (" + std::to_string(bytes) +
                    " bytes) do not fit camera " + std::to_string(rank) + "'s frame");
      for (int t = 0; t < K; ++t)
        std::memcpy(images[std::size_t(t)].row(band_y0(j)), recv_buf.data() + 2 * sizeof(std::int32_t) + std::size_t(t) * n, n);
    }
    if (observer)
      for (int t = 0; t < K; ++t) observer(rank, t, frame, images[std::size_t(t)]);
    batch_camera[0] = rank;
    batch_n = 1;
  }
  if (!sends.empty()) MPI_Waitall(int(sends.size()), sends.data(), MPI_STATUSES_IGNORE);
  time.composite += since(t0);
  encode_batch();
}
#endif

}  // namespace panoptes::insitu
