#pragma once
// Stamped test databases for the player's tests and benchmark: every frame carries the stamp of its
// (camera, task, frame), so a test can check exactly which frame the engine shows.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <random>
#include <set>
#include <string>
#include <utility>

#include "core/frame_stamp.hpp"
#include "core/image.hpp"
#include "store/database.hpp"
#include "store/manifest.hpp"
#include "store/test_support.hpp"

namespace panoptes::player::testing {

/// A fresh directory under the system temp dir, removed on destruction (shared with the store tests).
using TempDir = store::testing::TempDir;

/// A manifest with `cameras` cameras on a ring of latitude 0 (camera c at longitude 360°·c/cameras)
/// with a wrap-around left/right graph, `tasks` tasks on two axes when tasks = a × b ("iso" with a
/// values, "window" with b values; task = i_iso * b + i_window) or one axis otherwise.
inline store::Manifest ring_manifest(int cameras, int tasks, int width = 64, int height = 64, int axis_b = 1) {
  store::Manifest m;
  m.title = "player test";
  m.provenance.program = "player_test";
  m.image.width = width;
  m.image.height = height;
  m.video.gop = 5;
  m.video.crf = 18;
  m.video.fps = 30;
  m.rig.kind = "ring";
  for (int c = 0; c < cameras; ++c) {
    const double lon = 2 * M_PI * c / cameras;
    store::CameraEntry e;
    e.id = c;
    e.position = {3 * std::cos(lon), 3 * std::sin(lon), 0};
    e.up = {0, 0, 1};
    e.labels.lon_deg = lon * 180 / M_PI;
    m.cameras.push_back(e);
    store::Neighbours n;
    n.left = (c + cameras - 1) % cameras;
    n.right = (c + 1) % cameras;
    m.graph.neighbours.push_back(n);
  }
  const int axis_a = tasks / axis_b;
  store::ParameterAxis iso{"iso", {}, ""}, window{"window", {}, ""};
  for (int i = 0; i < axis_a; ++i) iso.values.push_back(0.1 * (i + 1));
  for (int j = 0; j < axis_b; ++j) window.values.push_back(j);
  m.axes.push_back(iso);
  if (axis_b > 1) m.axes.push_back(window);
  for (int t = 0; t < tasks; ++t) {
    store::TaskEntry e;
    e.id = t;
    e.name = "task" + std::to_string(t);
    e.method = "synthetic";
    e.axes.push_back({"iso", t / axis_b});
    if (axis_b > 1) e.axes.push_back({"window", t % axis_b});
    m.tasks.push_back(e);
  }
  return m;
}

/// The stamped frame of (camera, task, frame): a background colour depending on the stream and a
/// bar moving with the frame, so consecutive frames differ as in a real movie.
inline Image stamped_frame(int camera, int task, int frame, int width, int height) {
  Image im(width, height, 4);
  const std::uint8_t r = std::uint8_t(40 + 50 * (camera % 4)), g = std::uint8_t(60 + 40 * (task % 4));
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      std::uint8_t* p = im.at(x, y);
      const bool bar = ((x + 3 * frame) % width) < width / 8;
      p[0] = bar ? 230 : r, p[1] = bar ? 230 : g, p[2] = std::uint8_t((x * 255) / width), p[3] = 255;
    }
  draw_frame_stamp(im, FrameStamp{std::uint32_t(camera), std::uint32_t(task), std::uint32_t(frame)});
  return im;
}

/// Writes a complete stamped database with `frames` frames per stream.
inline void write_stamped(const std::filesystem::path& dir, const store::Manifest& manifest, int frames) {
  auto writer = store::DatabaseWriter::create(dir, manifest, true);
  for (int f = 0; f < frames; ++f) {
    for (int c = 0; c < manifest.camera_count(); ++c)
      for (int t = 0; t < manifest.task_count(); ++t)
        writer.append(c, t, stamped_frame(c, t, f, manifest.image.width, manifest.image.height));
    writer.set_time(f, 0.1 * f);
  }
  writer.finalize();
}

}  // namespace panoptes::player::testing
