// Issue 45 (helper h-march): a probe of the dense march on paraview_anchor's scene, for A/B runs.
//   march_probe ROUNDS [REF_DIR [save]]
// Renders the anchor's 8 cameras (dense_wave_scene p on 128x256x80, one p-wave volume task, 920x896,
// 1.0 voxel, adaptive on) ROUNDS times and prints the CPU-s per image, the marched pixels and samples,
// a hash of the partial images' float bits, and, with REF_DIR, the PSNR of each final image against
// REF_DIR/ref_<i>.raw (written there with "save", from a full march: adaptive off), with the largest
// channel error and the pixels per image off by more than 8/255. Environment: PROBE_SPARSE=1 (two
// fronts 2 voxels wide) or =thin (0.7 voxel) instead of the dense scene; PROBE_STEP (sample distance,
// voxels); PROBE_LIN (RenderOptions::adaptive_linear_tolerance in 1/255); PROBE_ISO (an isosurface
// task at 0.3 of the window as well: the hash then covers both images); PROBE_STRIDE (adaptive_stride);
// PROBE_TOL (adaptive_tolerance in 1/255); PROBE_MC (macro-cell size); PROBE_TILE (adaptive_tile);
// PROBE_SCALE (image size relative to 920x896).
// docs/rendering.md, Rounds 13 and 21.

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "core/image.hpp"
#include "render/renderer.hpp"
#include "render/synthetic_fields.hpp"
#include "anchor_scene.hpp"

using namespace panoptes;
using namespace panoptes::render;

int main(int argc, char** argv) {
  const int rounds = argc > 1 ? std::atoi(argv[1]) : 3;
  const std::string ref = argc > 2 ? argv[2] : "";
  const bool save = argc > 3 && std::strcmp(argv[3], "save") == 0;
  const GridGeometry grid{{128, 256, 80}, {0, 0, 0}, {1, 1, 1}};
  // PROBE_SPARSE: paper_snapshot_bench's sparse scene (two expanding fronts), or thinner fronts.
  const WaveFront pf[] = {{{64, 90, 45}, 75, 2, 1.0}, {{45, 190, 30}, 35, 2, 0.8}};
  const WaveFront thin[] = {{{64, 90, 45}, 75, 0.7, 1.0}, {{45, 190, 30}, 35, 0.7, 0.8}};
  const char* sp = std::getenv("PROBE_SPARSE");
  const DenseWaveScene waves = !sp ? dense_wave_scene(grid)
                               : DenseWaveScene{wave_field(grid, std::string(sp) == "thin" ? thin : pf), {}};
  const FieldView view = FieldView::whole(grid, waves.p.data());
  const double w = abs_percentile(view, 0.999);
  int opt_stride = 4;
  const double scale = std::getenv("PROBE_SCALE") ? std::atof(std::getenv("PROBE_SCALE")) : 1.0;
  std::vector<TaskSpec> tasks{TaskSpec::volume(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, w))};
  if (const char* s = std::getenv("PROBE_STRIDE")) opt_stride = std::atoi(s);
  if (std::getenv("PROBE_ISO")) tasks.push_back(TaskSpec::isosurface(0, float(0.3 * w)));  // a mixed march
  const std::vector<FieldView> views{view};
  const char* mc = std::getenv("PROBE_MC");
  const std::vector<PreparedField> fields = prepare_fields(views, tasks, mc ? std::atoi(mc) : MacroCells::kDefaultSize);
  std::vector<PartialImage> out(tasks.size());
  RenderOptions opt;
  opt.sample_distance = 1.0;
  opt.adaptive = !save;
  opt.adaptive_stride = opt_stride;
  if (const char* s = std::getenv("PROBE_STEP")) opt.sample_distance = std::atof(s);
  if (const char* s = std::getenv("PROBE_LIN")) opt.adaptive_linear_tolerance = float(std::atof(s) / 255);
  if (const char* s = std::getenv("PROBE_TOL")) opt.adaptive_tolerance = float(std::atof(s) / 255);
  if (const char* s = std::getenv("PROBE_TILE")) opt.adaptive_tile = std::atoi(s);
  if (const char* s = std::getenv("PROBE_TERM")) opt.termination_alpha = float(std::atof(s));
  Image image;
  std::uint64_t hash = 1469598103934665603ull, rays = 0, marched = 0, samples = 0, interp = 0;
  double worst = 1e9, sum = 0;
  int maxerr = 0;
  long over8 = 0;
  for (int i = 0; i < 8; ++i) {
    const camera::Camera cam = bench::anchor_camera(grid, i, scale);
    const RenderStats st = render_brick(cam, fields, tasks, out, opt);
    rays += st.rays, marched += st.marched_samples, samples += st.samples, interp += st.interpolated_pixels;
    for (const PartialImage& o : out)
      for (float f : o.rgba) {
        std::uint32_t b;
        std::memcpy(&b, &f, 4);
        hash = (hash ^ b) * 1099511628211ull;
      }
    finish_image_into(out[0], cam, grid, image, {0, 0, 0}, OutlineStyle{false});
    if (!ref.empty()) {
      const std::string path = ref + "/ref_" + std::to_string(i) + ".raw";
      if (save) {
        std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(image.pixels.data()), std::streamsize(image.pixels.size()));
      } else {
        Image r = image;
        std::ifstream(path, std::ios::binary).read(reinterpret_cast<char*>(r.pixels.data()), std::streamsize(r.pixels.size()));
        const double p = psnr(image, r);
        worst = std::min(worst, p), sum += p;
        for (int y = 0; y < image.height; ++y)
          for (int x = 0; x < image.width; ++x) {
            int e = 0;
            for (int c = 0; c < 3; ++c) e = std::max(e, std::abs(int(image.row(y)[image.channels * x + c]) - int(r.row(y)[r.channels * x + c])));
            maxerr = std::max(maxerr, e);
            over8 += e > 8;
          }
      }
    }
  }
  const double c0 = bench::process_cpu_seconds();
  for (int r = 0; r < rounds; ++r)
    for (int i = 0; i < 8; ++i) {
      const camera::Camera cam = bench::anchor_camera(grid, i, scale);
      render_brick(cam, fields, tasks, out, opt);
      finish_image_into(out[0], cam, grid, image, {0, 0, 0}, OutlineStyle{false});
    }
  const double cpu = (bench::process_cpu_seconds() - c0) / (8.0 * rounds);
  std::printf("cpu_s_per_image %.5f hash %016llx rays %.3f%% marched/ray %.1f samples/ray %.1f", cpu,
              (unsigned long long)hash, 100.0 * double(rays) / double(rays + interp), double(marched) / double(rays),
              double(samples) / double(rays));
  if (!ref.empty() && !save) std::printf(" psnr_min %.2f mean %.2f max_err %d px_over8_per_image %.1f", worst, sum / 8, maxerr, over8 / 8.0);
  std::printf("\n");
  return 0;
}
