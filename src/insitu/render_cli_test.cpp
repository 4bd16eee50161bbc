// Frames of a known field rendered in situ equal the same field rendered by the `panoptes render`
// command (issue 5): the field is written to .npy files, fed through an in-situ Session, and the
// built panoptes binary (PANOPTES_BINARY, set by CMake) renders the files into a second database;
// both are read back through the store reader and compared frame by frame.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "insitu/session.hpp"
#include "panoptes.h"
#include "render/synthetic_fields.hpp"
#include "store/database.hpp"

#ifndef PANOPTES_BINARY
#error "PANOPTES_BINARY must name the panoptes executable"
#endif

using namespace panoptes;
namespace fs = std::filesystem;

namespace {

// NumPy .npy version 1.0, little-endian float32, C order = shape (nz, ny, nx).
void write_npy(const fs::path& path, const std::vector<float>& v, const render::Index3& dims) {
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + std::to_string(dims[2]) + ", " +
                       std::to_string(dims[1]) + ", " + std::to_string(dims[0]) + "), }";
  // Magic (6) + version (2) + length (2) + header + '\n' is padded to a multiple of 64 bytes.
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::ofstream out(path, std::ios::binary);
  out.write("\x93NUMPY\x01\x00", 8);
  const std::uint16_t len = std::uint16_t(header.size());
  const char len_le[2] = {char(len & 0xff), char(len >> 8)};
  out.write(len_le, 2);
  out.write(header.data(), std::streamsize(header.size()));
  out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(float)));
  ASSERT_TRUE(out.good()) << path;
}

double psnr_rgb(const Image& a, const Image& b, int& max_diff) {
  double se = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    if (i % 4 == 3) continue;
    const int d = int(a.pixels[i]) - int(b.pixels[i]);
    max_diff = std::max(max_diff, std::abs(d));
    se += double(d) * d;
    ++n;
  }
  return se == 0 ? INFINITY : 10 * std::log10(255.0 * 255.0 / (se / double(n)));
}

TEST(InsituRenderCli, FramesEqualPanoptesRender) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_render_cli_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  // Anisotropic spacing (given to the CLI with --spacing), odd image size (padded by the encoder).
  const render::GridGeometry grid{{34, 30, 26}, {0, 0, 0}, {1, 1, 1.25}};
  const int snapshots = 2;

  // Every window is absolute, so neither side's reference (percentile, running maximum) matters.
  insitu::SessionConfig cfg = insitu::parse_session_config_text(R"(
[image]
width = 61
height = 48
[rig]
spec = "fibonacci:4"
[schedule]
every_steps = 1
[video]
crf = 18
[render]
sample_distance = 0.5
adaptive = true  # as panoptes render's default
[[task]]
name = "hot"
type = "volume"
field = "a"
preset = "hot"
relative = false
window = [0.0, 0.8]
[[task]]
name = "iso"
type = "isosurface"
field = "a"
isovalue = 0.3
[[task]]
name = "slice"
type = "slice"
field = "a"
axis = "z"
position = 0.5
preset = "rainbow"
relative = false
window = [-1.0, 1.0]
)",
                                                                "render_cli_test");
  cfg.output_dir = (dir / "insitu_db").string();
  std::string files;
  {
    insitu::Session session(cfg, grid, insitu::LocalBlock::whole(grid));
    for (int s = 0; s < snapshots; ++s) {
      const double t = 0.7 * s;
      const std::vector<render::WaveFront> fronts{{grid.centre(), 5 + 3 * t, 2.5, 1.0},
                                                  {grid.centre() + Vec3{4, -3, 2}, 3 + 2 * t, 2.0, -0.7}};
      const std::vector<float> a = render::wave_field(grid, fronts);
      const fs::path npy = dir / ("a_" + std::to_string(s) + ".npy");
      write_npy(npy, a, grid.dims);
      files += " " + npy.string();
      ASSERT_TRUE(session.process(s, t, {{"a", a.data(), insitu::ScalarType::f32, {0, 0, 0}}}));
    }
    session.finalize();
  }

  const fs::path cli_db = dir / "cli_db";
  const std::string cmd = std::string(PANOPTES_BINARY) + " render" + files +
                          " --rig fibonacci:4 --size 61x48 --spacing 1,1,1.25 --sample-distance 0.5 --crf 18"
                          " --task volume:hot:0:0.8 --task iso:0.3 --task slice:z:0.5:rainbow:-1:1 --out " +
                          cli_db.string() + " > " + (dir / "render.log").string() + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;

  const store::Database a = store::Database::open(cfg.output_dir);
  const store::Database b = store::Database::open(cli_db);
  ASSERT_EQ(a.status(), store::Status::complete);
  ASSERT_EQ(b.status(), store::Status::complete);
  ASSERT_EQ(a.camera_count(), 4);
  ASSERT_EQ(b.camera_count(), 4);
  ASSERT_EQ(a.task_count(), 3);
  ASSERT_EQ(b.task_count(), 3);
  ASSERT_EQ(a.frame_count(), snapshots);
  ASSERT_EQ(b.frame_count(), snapshots);
  double worst = INFINITY;
  int max_diff = 0, identical = 0, frames = 0;
  for (int c = 0; c < 4; ++c)
    for (int t = 0; t < 3; ++t) {
      auto ra = a.stream(c, t);
      auto rb = b.stream(c, t);
      for (int f = 0; f < snapshots; ++f) {
        const Image ia = ra->read_rgba(f), ib = rb->read_rgba(f);
        ASSERT_EQ(ia.width, 61);
        ASSERT_EQ(ia.height, 48);
        ASSERT_EQ(ib.width, ia.width);
        ASSERT_EQ(ib.height, ia.height);
        // Not an empty scene: some pixel of every frame is far from the black background.
        int brightest = 0;
        for (std::size_t i = 0; i < ia.pixels.size(); ++i)
          if (i % 4 != 3) brightest = std::max(brightest, int(ia.pixels[i]));
        EXPECT_GT(brightest, 64) << "camera " << c << " task " << t << " frame " << f << " is (nearly) empty";
        int d = 0;
        const double p = psnr_rgb(ia, ib, d);
        worst = std::min(worst, p);
        max_diff = std::max(max_diff, d);
        identical += d == 0;
        ++frames;
        EXPECT_GE(p, 45.0) << "camera " << c << " task " << t << " frame " << f;
      }
    }
  std::printf("in situ vs panoptes render: %d frames, %d identical, worst PSNR %.1f dB, max difference %d/255\n",
              frames, identical, worst, max_diff);
  fs::remove_all(dir);
}

}  // namespace

namespace {

// Issue 30: `panoptes render` is a replay through the Session, so the same volumes and the same tasks
// given as --task shorthand and as [[task]] tables give the same manifest (task entries, axes,
// per-frame references) and bit-identical frames, with RELATIVE windows (the reference decides every
// pixel) on a grid above 65,536 points (where the session samples a lattice for its percentile).
TEST(InsituRenderCli, RenderIsASessionReplayWithRelativeWindows) {
  const fs::path dir = fs::temp_directory_path() / ("insitu_render_replay_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const render::GridGeometry grid{{48, 48, 48}, {0, 0, 0}, {1, 1, 1}};  // 110,592 points
  const int snapshots = 2;
  const std::string toml = R"(
[image]
width = 40
height = 32
[rig]
spec = "fibonacci:3"
up_axis = "z_up"
[schedule]
every_steps = 1
[render]
adaptive = true  # as panoptes render's default
[[task]]
name = "volume:hot"
type = "volume"
field = "volume"
preset = "hot"
[[task]]
name = "iso"
type = "isosurface"
field = "volume"
isovalues = [0.3, -0.2]
axis_name = "isovalue"
[[task]]
name = "slice:z:0.5:rainbow"
type = "slice"
field = "volume"
axis = "z"
position = 0.5
preset = "rainbow"
)";
  insitu::SessionConfig cfg = insitu::parse_session_config_text(toml, "render_replay_test");
  cfg.output_dir = (dir / "session_db").string();
  std::string files;
  std::vector<std::vector<float>> volumes;
  {
    insitu::Session session(cfg, grid, insitu::LocalBlock::whole(grid));
    for (int s = 0; s < snapshots; ++s) {
      const double t = double(s);  // render's snapshot times are the volume indices
      const std::vector<render::WaveFront> fronts{{grid.centre(), 8 + 5 * t, 3.0, 1.0},
                                                  {grid.centre() + Vec3{6, -5, 3}, 5 + 3 * t, 2.5, -0.7}};
      const std::vector<float> a = render::wave_field(grid, fronts);
      const fs::path npy = dir / ("v_" + std::to_string(s) + ".npy");
      write_npy(npy, a, grid.dims);
      files += " " + npy.string();
      session.snapshot(t, {{"volume", a.data(), insitu::ScalarType::f32, {0, 0, 0}}});
      volumes.push_back(a);
    }
    session.finalize();
  }
  // The C API (and so Fortran and Python, which call it) with the same TOML text.
  const fs::path capi_db = dir / "capi_db";
  {
    const std::string text = "[output]\ndir = \"" + capi_db.string() + "\"\n" + toml;
    panoptes_session* s = nullptr;
    ASSERT_EQ(panoptes_create(text.c_str(), 0, PANOPTES_COMM_WORLD, &s), 0);
    const int dims[3] = {grid.dims[0], grid.dims[1], grid.dims[2]}, zero[3] = {0, 0, 0};
    const double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1};
    ASSERT_EQ(panoptes_set_grid(s, dims, origin, spacing), 0);
    ASSERT_EQ(panoptes_set_block(s, zero, dims, zero, zero), 0);
    const long long contiguous[3] = {0, 0, 0};
    for (int f = 0; f < snapshots; ++f) {
      ASSERT_EQ(panoptes_set_field(s, "volume", volumes[std::size_t(f)].data(), PANOPTES_FLOAT32, contiguous), 0);
      ASSERT_EQ(panoptes_snapshot(s, double(f)), 0);
    }
    ASSERT_EQ(panoptes_finalize(s), 0);
    panoptes_destroy(s);
  }
  const fs::path cli_db = dir / "cli_db";
  const std::string cmd = std::string(PANOPTES_BINARY) + " render" + files +
                          " --rig fibonacci:3 --size 40x32 -q --task volume:hot --task iso:0.3 --task iso:-0.2"
                          " --task slice:z:0.5:rainbow --out " + cli_db.string() + " > " + (dir / "render.log").string() +
                          " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;

  const store::Database a = store::Database::open(cfg.output_dir);
  for (const fs::path& other : {cli_db, capi_db}) {
  SCOPED_TRACE(other.string());
  const store::Database b = store::Database::open(other);
  const store::Manifest& ma = a.manifest();
  const store::Manifest& mb = b.manifest();
  ASSERT_EQ(ma.tasks.size(), 4u);
  EXPECT_EQ(ma.tasks, mb.tasks);
  EXPECT_EQ(ma.axes, mb.axes);
  ASSERT_EQ(ma.fields.size(), 1u);
  EXPECT_EQ(ma.fields, mb.fields);  // per-frame references, bit for bit
  EXPECT_EQ(ma.fields[0].references, mb.fields.at(0).references);
  ASSERT_EQ(ma.fields[0].references.size(), std::size_t(snapshots));
  EXPECT_NE(ma.fields[0].references[0], ma.fields[0].references[1]);  // the reference does move
  EXPECT_EQ(ma.cameras.size(), mb.cameras.size());
  EXPECT_EQ(ma.domain.up_axis, mb.domain.up_axis);
  ASSERT_EQ(a.frame_count(), snapshots);
  ASSERT_EQ(b.frame_count(), snapshots);
  int differing = 0, lit = 0;
  for (int c = 0; c < a.camera_count(); ++c)
    for (int t = 0; t < a.task_count(); ++t) {
      auto ra = a.stream(c, t);
      auto rb = b.stream(c, t);
      for (int f = 0; f < snapshots; ++f) {
        const Image ia = ra->read_rgba(f), ib = rb->read_rgba(f);
        differing += ia.pixels != ib.pixels;
        int brightest = 0;
        for (std::size_t i = 0; i < ia.pixels.size(); ++i)
          if (i % 4 != 3) brightest = std::max(brightest, int(ia.pixels[i]));
        lit += brightest > 64;
      }
    }
  EXPECT_EQ(differing, 0) << "frames differ from the Session's";
    EXPECT_GE(lit, a.camera_count() * a.task_count() * snapshots * 3 / 4) << "too many (nearly) empty frames";
  }
  fs::remove_all(dir);
}

}  // namespace
