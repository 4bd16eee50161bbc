// Slice legends and the value readout (issue 41) against pictures of a known field: an analytic field is
// written as .npy volumes, rendered and encoded to H.264 by the real `panoptes render` (a slice of z,
// the default diverging map over the relative window -1..1 x each volume's reference), decoded as the
// player decodes it, and every pixel's colour is compared with the legend's colour at the true value
// and read back into a value.
#include "player/value_readout.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "camera/camera.hpp"
#include "player/legend.hpp"
#include "store/database.hpp"
#include "store/test_support.hpp"

using namespace panoptes;
using namespace panoptes::player;
namespace fs = std::filesystem;

namespace {

constexpr int kNx = 64, kNy = 48, kNz = 32, kW = 256, kH = 192;
constexpr double kAmplitude[2] = {3e-5, 6e-5};  // two snapshots: the reference doubles
constexpr double kSliceZ = 0.5 * (kNz - 1);

// The field (grid spacing 1, origin 0): one period along x, half a period along y, constant along z.
double field(double x, double y, double amplitude) {
  return amplitude * std::sin(2 * std::numbers::pi * x / (kNx - 1)) * std::cos(std::numbers::pi * y / (kNy - 1));
}

// NumPy .npy version 1.0, little-endian float32, C order = shape (nz, ny, nx).
void write_npy(const fs::path& path, double amplitude) {
  std::vector<float> v(std::size_t(kNx) * kNy * kNz);
  for (int z = 0; z < kNz; ++z)
    for (int y = 0; y < kNy; ++y)
      for (int x = 0; x < kNx; ++x) v[(std::size_t(z) * kNy + y) * kNx + x] = float(field(x, y, amplitude));
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + std::to_string(kNz) + ", " +
                       std::to_string(kNy) + ", " + std::to_string(kNx) + "), }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::ofstream out(path, std::ios::binary);
  out.write("\x93NUMPY\x01\x00", 8);
  const char len[2] = {char(header.size() & 0xff), char(header.size() >> 8)};
  out.write(len, 2);
  out.write(header.data(), std::streamsize(header.size()));
  out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(float)));
}

// One camera straight above the slice, the whole plane in view with background around it.
const fs::path& slice_database() {
  static const fs::path db = [] {
    static store::testing::TempDir dir("player-readout");
    for (int s = 0; s < 2; ++s) write_npy(dir.path / ("f_" + std::to_string(s) + ".npy"), kAmplitude[s]);
    std::ofstream(dir.path / "camera.txt") << 0.5 * (kNx - 1) << " " << 0.5 * (kNy - 1) << " " << kSliceZ + 80 << " "
                                           << 0.5 * (kNx - 1) << " " << 0.5 * (kNy - 1) << " " << kSliceZ
                                           << " 0 1 0 40\n";
    const fs::path out = dir.path / "db";
    const std::string cmd = std::string(PANOPTES_BINARY) + " render " + (dir.path / "f_0.npy").string() + " " +
                            (dir.path / "f_1.npy").string() + " --rig " + (dir.path / "camera.txt").string() +
                            " --task slice:z:0.5 --size " + std::to_string(kW) + "x" + std::to_string(kH) +
                            " --no-outline -q --out " + out.string();
    if (std::system(cmd.c_str()) != 0) throw std::runtime_error("failed: " + cmd);
    return out;
  }();
  return db;
}

struct Truth {
  bool on = false;
  double value = 0;
};

// Where the ray of pixel (x, y) meets the slice, through the renderer's own camera (Camera::ray).
Truth truth(const store::Manifest& m, int x, int y, double amplitude) {
  const auto& c = m.cameras[0];
  const camera::Camera cam(c.position, c.look_at, c.up, c.fov_y_deg, m.image.width, m.image.height);
  const camera::Ray r = cam.ray(x + 0.5, y + 0.5);
  const double t = (kSliceZ - r.origin.z) / r.direction.z;
  const Vec3 p = r.origin + r.direction * t;
  if (!(t > 0) || p.x < 0 || p.x > kNx - 1 || p.y < 0 || p.y > kNy - 1) return {};
  return {true, field(p.x, p.y, amplitude)};
}

// The legend bar's colour (0..255) at value v, as a bar draws it: linear between its samples.
std::array<double, 3> legend_colour(const LegendBar& bar, double v) {
  const double s = std::clamp((v - bar.lo) / (bar.hi - bar.lo), 0.0, 1.0) * double(bar.colours.size() - 1);
  const std::size_t i = std::min(std::size_t(s), bar.colours.size() - 2);
  const double w = s - double(i);
  std::array<double, 3> out{};
  for (int k = 0; k < 3; ++k) out[k] = 255 * (bar.colours[i][k] * (1 - w) + bar.colours[i + 1][k] * w);
  return out;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::size_t(std::lround(q * double(v.size() - 1)))];
}

}  // namespace

// Issue 41.4: the legend draws each value in the colour the slice shows it in. Before, the legend drew
// every task as a thin translucent layer over black: near zero the diverging map's light grey on the
// plane was black in the legend (median difference ~150 levels over this slice).
TEST(SliceLegend, PixelsOfARenderedSliceHaveTheLegendsColourAtTheirValue) {
  const store::Database db = store::Database::open(slice_database());
  const store::Manifest& m = db.manifest();
  ASSERT_EQ(m.frames_written, 2);
  ASSERT_EQ(m.fields.size(), 1u);
  const int frame = 1;
  const auto bars = task_legend(m, 0, frame);
  ASSERT_EQ(bars.size(), 1u);
  ASSERT_TRUE(bars[0].physical);
  ASSERT_EQ(bars[0].colours.size(), std::size_t(kLegendSamples));
  video::YuvFrame f;
  db.stream(0, 0)->read(frame, f);
  std::vector<double> diff;
  for (int y = 2; y < kH - 2; ++y)
    for (int x = 2; x < kW - 2; ++x) {
      // Inside the slice by 2 pixels (its edge blends with the background in the picture).
      if (!truth(m, x - 2, y - 2, 1).on || !truth(m, x + 2, y + 2, 1).on) continue;
      const Truth t = truth(m, x, y, kAmplitude[frame]);
      if (t.value <= bars[0].lo || t.value >= bars[0].hi) continue;
      const auto px = rgb_at(f, x, y);
      const auto lc = legend_colour(bars[0], t.value);
      double d = 0;
      for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(px[k] - lc[k]));
      diff.push_back(d);
    }
  ASSERT_GT(diff.size(), 10000u);
  const double p50 = quantile(diff, 0.5), p95 = quantile(diff, 0.95), mx = quantile(diff, 1.0);
  std::printf("slice pixel vs legend colour at its true value, max over r, g, b (levels): median %.1f, p95 %.1f, "
              "max %.1f over %zu pixels\n", p50, p95, mx, diff.size());
  EXPECT_LE(p50, 3) << "the legend's colours are not the slice's";
  EXPECT_LE(p95, 8);
}

// The value under the cursor, read from the H.264 picture and the frame's recorded reference, against
// the field: errors in units of the colour map's resolution (window width / distinguishable colours).
TEST(ValueReadout, ReadsTheFieldBackFromAnH264SliceWithinTheColourMapsResolution) {
  const store::Database db = store::Database::open(slice_database());
  const store::Manifest& m = db.manifest();
  const int frame = 1;
  const SliceReadout r = slice_readout(m, 0, frame);
  ASSERT_TRUE(r.usable);
  ASSERT_TRUE(r.have_box);
  EXPECT_EQ(r.axis, 2);
  EXPECT_DOUBLE_EQ(r.position, kSliceZ);
  EXPECT_DOUBLE_EQ(r.hi, m.fields[0].references[frame]) << "the frame's own reference scales the window";
  const double res = r.resolution();
  std::printf("window %.4g .. %.4g, %zu distinguishable colours, resolution %.3g\n", r.lo, r.hi, r.table.colours.size(),
              res);
  EXPECT_GT(r.table.colours.size(), 300u);
  video::YuvFrame f;
  db.stream(0, 0)->read(frame, f);
  std::vector<double> err, edge_err, colour_distance;
  int on = 0, read = 0, bounds = 0, no_reading_on = 0, off = 0, off_read = 0;
  double bound_steps = 0;  // how far inside the window the true value of a pixel read as a bound lay
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const Truth t = truth(m, x, y, kAmplitude[frame]);
      const ValueReading v = read_pixel(m, r, 0, x, y, rgb_at(f, x, y));
      if (!t.on) {
        ++off;
        off_read += v.kind != ValueReading::Kind::none;
        continue;
      }
      ++on;
      const bool interior = truth(m, x - 2, y - 2, 1).on && truth(m, x + 2, y + 2, 1).on;
      if (v.kind == ValueReading::Kind::none) {
        no_reading_on += interior;
        continue;
      }
      if (v.kind != ValueReading::Kind::value) {
        ++bounds;
        bound_steps = std::max(bound_steps, v.kind == ValueReading::Kind::below ? (t.value - r.lo) / res : (r.hi - t.value) / res);
        // A bound says the value is at or beyond the window's end: true within the worst error.
        if (interior) {
          EXPECT_TRUE(v.kind == ValueReading::Kind::below ? t.value <= r.lo + 16 * res : t.value >= r.hi - 16 * res)
              << "pixel (" << x << ", " << y << ") true " << t.value;
        }
        continue;
      }
      ++read;
      (interior ? err : edge_err).push_back(std::abs(v.value - t.value) / res);
      if (interior) colour_distance.push_back(v.colour_distance);
    }
  const double p50 = quantile(err, 0.5), p95 = quantile(err, 0.95), mx = quantile(err, 1.0);
  std::printf("readout error / resolution over %zu interior pixels: median %.2f, p95 %.2f, max %.2f; %zu edge pixels: "
              "median %.2f, max %.2f\n", err.size(), p50, p95, mx, edge_err.size(), quantile(edge_err, 0.5),
              quantile(edge_err, 1.0));
  std::printf("interior pixels' distance to the nearest map colour (levels): median %.2f, p99 %.2f, max %.2f\n",
              quantile(colour_distance, 0.5), quantile(colour_distance, 0.99), quantile(colour_distance, 1.0));
  std::printf("on the slice %d pixels: %d values, %d bounds (true values at most %.1f steps inside the window), %d "
              "interior without a reading; off it %d pixels, %d read\n",
              on, read, bounds, bound_steps, no_reading_on, off, off_read);
  EXPECT_EQ(off_read, 0) << "a pixel off the slice gave a value";
  EXPECT_LE(no_reading_on, on / 100) << "interior slice pixels without a reading";
  EXPECT_GT(err.size(), 10000u);
  // Measured 1.23 / 3.72 / 13.2 (docs/ui.md); kReadoutUncertaintySteps states the p95.
  EXPECT_LE(p50, 1.5);
  EXPECT_LE(p95, kReadoutUncertaintySteps + 0.5);
  EXPECT_LE(mx, 16);
}

// The rule on colours alone: the map's ends are bounds, colours far from the map and colours the map
// takes twice give no reading, and the text names value, unit and resolution.
TEST(ValueReadout, BoundsAmbiguityAndText) {
  store::Manifest m;
  m.fields = {{"vz", "m/s", {2.0}, ""}};
  store::TaskEntry t;
  t.method = "slice", t.name = "slice", t.fields = {"vz"};
  t.parameters = {{"axis", "z"}, {"position", 0.5}, {"window", {-1.0, 1.0}}, {"relative", true},
                  {"transfer_function", {{"colour", {{0, 0, 0, 0}, {1, 1, 1, 1}}}, {"extinction", {{0, 0}, {1, 1}}}}}};
  store::TaskEntry loop = t;  // black -> white -> black: every grey but white twice
  loop.parameters["transfer_function"]["colour"] = {{0, 0, 0, 0}, {0.5, 1, 1, 1}, {1, 0, 0, 0}};
  store::TaskEntry volume = t;
  volume.method = "volume";
  m.tasks = {t, loop, volume};
  const SliceReadout r = slice_readout(m, 0, 0);
  ASSERT_TRUE(r.usable);
  EXPECT_EQ(r.table.colours.size(), 256u) << "a grey ramp has 256 distinguishable colours";
  EXPECT_FALSE(r.have_box) << "no domain recorded: no geometry";
  EXPECT_NEAR(r.resolution(), 4.0 / 256, 1e-12);
  const ValueReading mid = read_colour(r, {128, 128, 128});
  ASSERT_EQ(mid.kind, ValueReading::Kind::value);
  EXPECT_NEAR(mid.value, 0.0, r.resolution());
  EXPECT_EQ(read_colour(r, {0, 0, 0}).kind, ValueReading::Kind::below);
  EXPECT_EQ(read_colour(r, {255, 255, 255}).kind, ValueReading::Kind::above);
  EXPECT_EQ(read_colour(r, {255, 0, 0}).reason, "not a colour of the map");
  EXPECT_EQ(reading_text(r, mid).substr(0, 5), "vz = ");
  EXPECT_NE(reading_text(r, mid).find("m/s  (+-0.0625)"), std::string::npos) << reading_text(r, mid);
  EXPECT_EQ(reading_text(r, read_colour(r, {0, 0, 0})), "vz <= -2 m/s");
  const SliceReadout l = slice_readout(m, 1, 0);
  EXPECT_EQ(read_colour(l, {100, 100, 100}).reason, "ambiguous colour");
  EXPECT_FALSE(slice_readout(m, 2, 0).usable) << "volumes have no readout";
  store::TaskEntry bare = t;  // no plane recorded (e.g. an imported database): the colour alone decides
  bare.parameters.erase("axis");
  m.tasks.push_back(bare);
  EXPECT_TRUE(slice_readout(m, 3, 0).usable);
  EXPECT_EQ(read_pixel(m, slice_readout(m, 3, 0), 0, 0, 0, {128, 128, 128}).kind, ValueReading::Kind::value);
  EXPECT_FALSE(slice_readout(m, 7, 0).usable);
  EXPECT_TRUE(slice_readout_json(m, 2).is_null());
  const auto j = slice_readout_json(m, 0);
  EXPECT_EQ(j["colours"].size(), 256u);
  EXPECT_EQ(j["axis"], 2);
  // rgb_at: BT.601 limited range, the chroma sample covering the pixel.
  video::YuvFrame f;
  f.width = 2, f.height = 2, f.y = {16, 235, 126, 126}, f.u = {128}, f.v = {128};
  EXPECT_EQ(rgb_at(f, 0, 0), (std::array<int, 3>{0, 0, 0}));
  EXPECT_EQ(rgb_at(f, 1, 0), (std::array<int, 3>{255, 255, 255}));
  EXPECT_THROW(rgb_at(f, 2, 0), Error);
}
