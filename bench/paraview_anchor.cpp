// Issue 45 point 1 (ParaView side by side): the panoptes half of bench/paraview_bench.sh, which runs
// ParaView 5.11's pvbatch (bench/paraview_anchor.py) on the same field and cameras in the same run.
// Not a *_bench program: scripts/bench runs it through paraview_bench.
//
//   paraview_anchor DIR [ROUNDS]
//
// The anchor scene of paper_snapshot_bench's BM_ParaViewAnchor: render::dense_wave_scene's p on
// 128x256x80 float32 points (spacing 1), one p-wave volume task over [0, 99.9th percentile of |p|],
// 8 cameras on the diagonals (±1, ±1, ±0.6) at 1.1x the domain diagonal from the centre, up +z, 30°
// view angle (ParaView's default), 920x896, black background, no outline (ParaView draws none).
// Writes DIR/field.raw (float32, x fastest, little-endian as the host) and DIR/window.txt (the
// window's top), then for each sample distance (1.0 voxel: ParaView's ray cast default of one world
// unit; 0.5: panoptes render's default), with adaptive sampling on as `panoptes render` has it:
// one round of the 8 images (warm-up, saved as DIR/panoptes_step<D>_<i>.png), then ROUNDS rounds
// (default 3) timed by the process's CPU time around render + final RGBA frame. Prints one line per
// sample distance: "step D cpu_s_per_image X images N".

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/image.hpp"
#include "core/png.hpp"
#include "render/renderer.hpp"
#include "render/synthetic_fields.hpp"
#include "anchor_scene.hpp"

using namespace panoptes;
using namespace panoptes::render;

int main(int argc, char** argv) try {
  const char* usage =
      "usage: %s DIR [ROUNDS]\n"
      "panoptes' half of paraview_bench (issue 45): writes DIR/field.raw and DIR/window.txt (the anchor\n"
      "scene for bench/paraview_anchor.py), renders its 8 cameras at 1.0 and 0.5 voxel per sample\n"
      "(PNGs in DIR) and prints the process CPU-seconds per image over ROUNDS rounds (default 3).\n";
  if (argc >= 2 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h")) {
    std::printf(usage, argv[0]);
    return 0;
  }
  if (argc < 2 || argc > 3 || argv[1][0] == '-') {
    std::fprintf(stderr, usage, argv[0]);
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  const int rounds = argc == 3 ? std::atoi(argv[2]) : 3;
  if (rounds < 1) throw Error(std::string("ROUNDS \"") + argv[2] + "\": expected a positive count");
  std::filesystem::create_directories(dir);
  const GridGeometry grid{{128, 256, 80}, {0, 0, 0}, {1, 1, 1}};
  const DenseWaveScene waves = dense_wave_scene(grid);
  const FieldView view = FieldView::whole(grid, waves.p.data());
  const double ref = abs_percentile(view, 0.999);
  {
    std::ofstream raw(dir / "field.raw", std::ios::binary);
    raw.write(reinterpret_cast<const char*>(waves.p.data()), std::streamsize(waves.p.size() * sizeof(float)));
    std::ofstream w(dir / "window.txt");
    w.precision(9);
    w << ref << "\n";
    if (!raw || !w) throw FileError((dir / "field.raw").string(), "cannot write the anchor field");
  }
  const std::vector<TaskSpec> tasks{TaskSpec::volume(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, ref))};
  const std::vector<FieldView> views{view};
  const std::vector<PreparedField> fields = prepare_fields(views, tasks);
  std::vector<PartialImage> out(1);
  Image image;
  for (const double step : {1.0, 0.5}) {
    RenderOptions opt;
    opt.sample_distance = step;
    opt.adaptive = true;  // panoptes render's default
    auto one = [&](int i) {
      const camera::Camera cam = bench::anchor_camera(grid, i);
      render_brick(cam, fields, tasks, out, opt);
      finish_image_into(out[0], cam, grid, image, {0, 0, 0}, OutlineStyle{false});
    };
    char name[64];
    for (int i = 0; i < 8; ++i) {
      one(i);
      std::snprintf(name, sizeof name, "panoptes_step%.1f_%d.png", step, i);
      write_png((dir / name).string(), image);
    }
    const double c0 = bench::process_cpu_seconds();
    for (int r = 0; r < rounds; ++r)
      for (int i = 0; i < 8; ++i) one(i);
    std::printf("step %.1f cpu_s_per_image %.5f images %d\n", step, (bench::process_cpu_seconds() - c0) / (8.0 * rounds), 8 * rounds);
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "paraview_anchor: %s\n", e.what());
  return 1;
}
