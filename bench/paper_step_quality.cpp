// Issue 10, round 6p: which sample distance the paper setting (examples/paper.toml) can afford,
// measured on the dense synthetic scene AND on the real paper wavefield. Not a *_bench program, so
// scripts/bench does not run it (the solver part takes minutes).
//
//   paper_step_quality fields DIR STEP...
//       runs the solver of examples/paper.toml and writes DIR/phi_p_STEP.f32, DIR/phi_s_STEP.f32
//       (raw float32, x fastest, the paper grid) at each STEP, so trials do not recompute them.
//   paper_step_quality real DIR STEPS CAMERAS CANDIDATES [PNG_DIR]
//       renders the saved snapshots (STEPS = 1200,2400) from Yin-Yang CAMERAS (= 5,40,64,100) x the
//       paper's 3 tasks with the session's windows (relative [0, 1] of the snapshot's 99.9th
//       percentile, camera up (0,0,-1) as `panoptes run`), at each candidate (CANDIDATES = step/tol
//       pairs, e.g. 1.0/4,1.5/4,2.0/6: sample distance in voxels / adaptive tolerance in 1/255) against
//       render_brick at 0.5 voxel without adaptive sampling (79.8 dB from the reference path on the
//       dense scene, Round 2). Prints PSNR, pixels off by > 8/255, the largest channel error, and
//       CPU-s per camera (3 images), all candidates of a camera rendered alternately, 2 rounds.
//       PNG_DIR: side-by-side crops (reference | candidate | 8x difference) of the first camera.
//   paper_step_quality real-nosheet DIR STEPS CAMERAS CANDIDATES [PNG_DIR]
//       the same with the free-surface plane z = 0 of both fields replaced by the plane z = 1: a
//       diagnosis, not the product's images. Solver::compute_derived() evaluates phi_p and phi_s at
//       k = 0 from the ghost velocities above the free surface; that one-voxel sheet is 10-30x the
//       interior waves (step 600: max |phi_p| at z = 0 is 3.4x the 99.9th percentile, at z >= 1 at
//       most 0.24x) and sets the window, so the real images are dominated by a one-voxel sheet.
//   paper_step_quality cost DIR STEPS EVERY
//       the render CPU cost of a real snapshot against the dense synthetic one (BM_DenseSnapshot's
//       scene): every EVERY-th camera of the 130 x the 3 tasks at examples/paper.toml's render options,
//       each camera rendered on the real fields of every STEP and on the dense scene in turn
//       (render_brick only: no composite, no encode).
//   paper_step_quality session DIR STEPS
//       (STEPS of cost and session: a step written 1200n is loaded without the free-surface sheet)
//       one snapshot of each real STEP and of the dense scene through the in-situ session exactly as
//       BM_DenseSnapshot drives it (examples/paper.toml, 130 cameras x 3 tasks, encode included), in
//       turn: CPU-s and the session's render / composite / encode / copy split.
//   paper_step_quality synthetic CAMERAS CANDIDATES [PNG_DIR]
//       the same on render::dense_wave_scene (256x512x160, spacing 1, BM_Quality's cameras 5,64,100)
//       against the reference path (render_reference) at 0.5 voxel, as BM_Quality.
#include <omp.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "camera/rig_spec.hpp"
#include "core/error.hpp"
#include "core/image.hpp"
#include "core/png.hpp"
#include "insitu/config.hpp"
#include "insitu/session.hpp"
#include "render/reference_renderer.hpp"
#include "render/renderer.hpp"
#include "render/synthetic_fields.hpp"
#include "seismic/config_toml.hpp"
#include "seismic/solver.hpp"

using namespace panoptes;
using namespace panoptes::render;

namespace {

constexpr int kWidth = 920, kHeight = 896;

double cpu_seconds() {
  timespec t{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw FileError(path, "cannot open");
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, sep);)
    if (!item.empty()) out.push_back(item);
  return out;
}

const std::vector<std::string> kSeismicSections{"grid",   "time",   "medium",   "boundary",
                                                "attenuation", "source", "receiver", "receiver_line"};
const std::string kPaper = std::string(PANOPTES_SOURCE_DIR) + "/examples/paper.toml";

seismic::RunConfig paper_run_config() {
  std::string seis_text;
  insitu::parse_combined_config(read_text(kPaper), kPaper, kSeismicSections, seis_text);
  return seismic::parse_run_config(seis_text, kPaper, std::string(PANOPTES_SOURCE_DIR) + "/examples");
}

std::string field_path(const std::string& dir, const char* name, int step) {
  return dir + "/" + name + "_" + std::to_string(step) + ".f32";
}

void write_floats(const std::string& path, const std::vector<float>& v) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * sizeof(float)));
  if (!out) throw FileError(path, "cannot write " + std::to_string(v.size()) + " floats");
}

std::vector<float> read_floats(const std::string& path, std::size_t n) {
  std::vector<float> v(n);
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(v.data()), std::streamsize(n * sizeof(float)));
  if (!in) throw FileError(path, "expected " + std::to_string(n) + " float32 values (the paper grid)");
  return v;
}

int cmd_fields(const std::string& dir, std::vector<int> steps) {
  std::sort(steps.begin(), steps.end());
  std::filesystem::create_directories(dir);
  seismic::Solver solver(paper_run_config().solver);
  for (int s : steps) {
    const double w0 = omp_get_wtime();
    solver.run(s - solver.steps_done());
    solver.compute_derived();
    write_floats(field_path(dir, "phi_p", s), solver.gather_field("phi_p"));
    write_floats(field_path(dir, "phi_s", s), solver.gather_field("phi_s"));
    std::printf("step %d written (%.1f s wall)\n", s, omp_get_wtime() - w0);
    std::fflush(stdout);
  }
  return 0;
}

struct Candidate {
  double step = 1.0;
  double tol = 4;  // 1/255
  std::string name() const {
    char b[64];
    std::snprintf(b, sizeof b, "%.2f/%g", step, tol);
    return b;
  }
};

struct Scene {
  std::string name;
  GridGeometry grid;
  std::vector<float> p, s;
  std::vector<PreparedField> fields;
  double ref_p = 1, ref_s = 1;
  void prepare() {
    const FieldView vp = FieldView::whole(grid, p.data()), vs = FieldView::whole(grid, s.data());
    ref_p = std::max(abs_percentile(vp, 0.999), 1e-30);
    ref_s = std::max(abs_percentile(vs, 0.999), 1e-30);
    fields = {PreparedField(vp), PreparedField(vs)};
  }
  std::vector<TaskSpec> tasks() const {
    return {TaskSpec::volume(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, ref_p)),
            TaskSpec::volume(1, TransferFunction::preset("s-wave"), ValueWindow::absolute(0, ref_s)),
            TaskSpec::volume2(0, TransferFunction::preset("p-wave"), ValueWindow::absolute(0, ref_p), 1,
                              TransferFunction::preset("s-wave"), ValueWindow::absolute(0, ref_s))};
  }
};

struct Diff {
  double psnr = 99;
  long over8 = 0;
  int max = 0;
};

Diff compare(const Image& a, const Image& ref) {
  Diff d;
  d.psnr = std::min(99.0, psnr(a, ref));
  const std::size_t n = std::size_t(a.width) * std::size_t(a.height);
  for (std::size_t i = 0; i < n; ++i) {
    int m = 0;
    for (int c = 0; c < 3; ++c)
      m = std::max(m, std::abs(int(a.pixels[i * std::size_t(a.channels) + std::size_t(c)]) -
                               int(ref.pixels[i * std::size_t(ref.channels) + std::size_t(c)])));
    d.over8 += m > 8;
    d.max = std::max(d.max, m);
  }
  return d;
}

// Reference | candidate | 8x |difference|, each cropped to the window [x0, x0+w) x [y0, y0+h) and
// enlarged `zoom` times (nearest), side by side.
void write_side_by_side(const std::string& path, const Image& ref, const Image& cand, int x0, int y0, int w, int h,
                        int zoom) {
  Image out(3 * w * zoom + 2 * 4, h * zoom, 4);
  std::fill(out.pixels.begin(), out.pixels.end(), std::uint8_t(255));
  for (int panel = 0; panel < 3; ++panel)
    for (int y = 0; y < h * zoom; ++y)
      for (int x = 0; x < w * zoom; ++x) {
        const int sx = std::min(ref.width - 1, x0 + x / zoom), sy = std::min(ref.height - 1, y0 + y / zoom);
        const std::uint8_t* r = ref.at(sx, sy);
        const std::uint8_t* c = cand.at(sx, sy);
        std::uint8_t* o = out.at(panel * (w * zoom + 4) + x, y);
        for (int k = 0; k < 3; ++k)
          o[k] = panel == 0 ? r[k] : panel == 1 ? c[k] : std::uint8_t(std::min(255, 8 * std::abs(int(r[k]) - int(c[k]))));
        o[3] = 255;
      }
  write_png(path, out);
}

struct Acc {
  double min_psnr = 99, sum_psnr = 0;
  int n = 0;
  long over8 = 0;
  int max = 0;
  double cpu = 0;
  int renders = 0;
  std::uint64_t rays = 0, interpolated = 0;
};

int run_trials(std::vector<Scene>& scenes, const std::vector<int>& cams, const std::vector<Candidate>& cands,
               bool reference_path, Vec3 up, const std::string& png_dir) {
  const char* task_names[] = {"p", "s", "p+s"};
  std::vector<std::vector<Acc>> acc(cands.size(), std::vector<Acc>(3));  // [candidate][task]
  std::vector<Acc> acc_all(cands.size());
  for (Scene& sc : scenes) {
    sc.prepare();
    const std::vector<TaskSpec> tasks = sc.tasks();
    const camera::Domain domain{sc.grid.domain_lo(), sc.grid.domain_hi() - sc.grid.domain_lo()};
    camera::RigSpec spec = camera::RigSpec::parse("yinyang");
    spec.up = up;
    const camera::Rig rig = camera::make_rig(spec, domain);
    for (int c : cams) {
      const camera::Camera cam = rig.camera(c, kWidth, kHeight);
      std::vector<PartialImage> ref(3);
      RenderOptions half;
      half.sample_distance = 0.5;
      const double r0 = cpu_seconds();
      if (reference_path)
        render_reference(cam, std::vector<FieldView>{sc.fields[0].view, sc.fields[1].view}, tasks, ref, half);
      else
        render_brick(cam, sc.fields, tasks, ref, half);
      const double ref_cpu = cpu_seconds() - r0;
      std::vector<Image> ref_img;
      for (int t = 0; t < 3; ++t) ref_img.push_back(finish_image(ref[std::size_t(t)], cam, sc.grid));
      std::vector<std::vector<PartialImage>> out(cands.size(), std::vector<PartialImage>(3));
      // Two rounds, the candidates alternating, so load drifts hit them alike (CPU-s summed).
      for (int round = 0; round < 2; ++round)
        for (std::size_t k = 0; k < cands.size(); ++k) {
          RenderOptions opt;
          opt.sample_distance = cands[k].step;
          opt.adaptive = true;
          opt.adaptive_tolerance = float(cands[k].tol / 255);
          const double c0 = cpu_seconds();
          const RenderStats st = render_brick(cam, sc.fields, tasks, out[k], opt);
          acc_all[k].cpu += cpu_seconds() - c0;
          ++acc_all[k].renders;
          if (round == 0) acc_all[k].rays += st.rays, acc_all[k].interpolated += st.interpolated_pixels;
        }
      std::printf("%s camera %d: reference %.2f CPU-s\n", sc.name.c_str(), c, ref_cpu);
      for (std::size_t k = 0; k < cands.size(); ++k) {
        for (int t = 0; t < 3; ++t) {
          const Image img = finish_image(out[k][std::size_t(t)], cam, sc.grid);
          const Diff d = compare(img, ref_img[std::size_t(t)]);
          for (Acc* a : {&acc[k][std::size_t(t)], &acc_all[k]}) {
            a->min_psnr = std::min(a->min_psnr, d.psnr);
            a->sum_psnr += d.psnr;
            ++a->n;
            a->over8 += d.over8;
            a->max = std::max(a->max, d.max);
          }
          std::printf("  %-10s %-3s psnr %6.2f dB  >8/255 %7ld px  max %3d\n", cands[k].name().c_str(), task_names[t],
                      d.psnr, d.over8, d.max);
          if (!png_dir.empty() && c == cams.front()) {
            std::filesystem::create_directories(png_dir);
            const std::string base = png_dir + "/" + sc.name + "_cam" + std::to_string(c) + "_" + task_names[t] + "_" +
                                     std::to_string(int(std::lround(cands[k].step * 100))) + "_tol" +
                                     std::to_string(int(cands[k].tol));
            write_side_by_side(base + "_full.png", ref_img[std::size_t(t)], img, 0, 0, kWidth, kHeight, 1);
            write_side_by_side(base + "_zoom.png", ref_img[std::size_t(t)], img, kWidth / 2 - 120, kHeight / 2 - 120,
                               240, 240, 3);
            if (k == 0) write_png(png_dir + "/" + sc.name + "_cam" + std::to_string(c) + "_" + task_names[t] + "_ref.png",
                                  ref_img[std::size_t(t)]);
          }
        }
      }
      std::fflush(stdout);
    }
    sc.fields.clear();
  }
  std::printf("\n| candidate (voxel / tol) | task | PSNR min / mean dB | px > 8/255 per image | max error /255 |\n");
  for (std::size_t k = 0; k < cands.size(); ++k)
    for (int t = 0; t < 3; ++t) {
      const Acc& a = acc[k][std::size_t(t)];
      std::printf("| %s | %s | %.2f / %.2f | %.0f | %d |\n", cands[k].name().c_str(), task_names[t], a.min_psnr,
                  a.sum_psnr / a.n, double(a.over8) / a.n, a.max);
    }
  std::printf("\n| candidate | PSNR min / mean dB (all) | px > 8/255 per image | max | CPU-s per camera (3 images) | vs first | rays marched %% |\n");
  const double base = acc_all[0].cpu / acc_all[0].renders;
  for (std::size_t k = 0; k < cands.size(); ++k) {
    const Acc& a = acc_all[k];
    std::printf("| %s | %.2f / %.2f | %.0f | %d | %.3f | %.2f | %.1f |\n", cands[k].name().c_str(), a.min_psnr,
                a.sum_psnr / a.n, double(a.over8) / a.n, a.max, a.cpu / a.renders, a.cpu / a.renders / base,
                100.0 * double(a.rays) / double(a.rays + a.interpolated));
  }
  return 0;
}

int cmd_cost(std::vector<Scene>& scenes, int every) {
  std::string seis_text;
  const RenderOptions opt = insitu::parse_combined_config(read_text(kPaper), kPaper, kSeismicSections, seis_text).render;
  std::vector<camera::Rig> rigs;
  std::vector<std::vector<TaskSpec>> tasks;
  for (Scene& sc : scenes) {
    sc.prepare();
    tasks.push_back(sc.tasks());
    const camera::Domain domain{sc.grid.domain_lo(), sc.grid.domain_hi() - sc.grid.domain_lo()};
    camera::RigSpec spec = camera::RigSpec::parse("yinyang");
    spec.up = {0, 0, -1};  // as panoptes run and BM_DenseSnapshot
    rigs.push_back(camera::make_rig(spec, domain));
  }
  std::vector<double> cpu(scenes.size(), 0);
  std::vector<std::uint64_t> rays(scenes.size(), 0), interp(scenes.size(), 0);
  std::vector<PartialImage> out(3);
  int cams = 0;
  for (int c = 0; c < rigs[0].size(); c += every, ++cams)
    for (std::size_t k = 0; k < scenes.size(); ++k) {
      const camera::Camera cam = rigs[k].camera(c, kWidth, kHeight);
      const double c0 = cpu_seconds();
      const RenderStats st = render_brick(cam, scenes[k].fields, tasks[k], out, opt);
      cpu[k] += cpu_seconds() - c0;
      rays[k] += st.rays, interp[k] += st.interpolated_pixels;
    }
  std::printf("paper.toml options: %.2f voxel, adaptive %d, tolerance %.1f/255; %d cameras x 3 tasks\n",
              opt.sample_distance, int(opt.adaptive), double(opt.adaptive_tolerance) * 255, cams);
  std::printf("| scene | CPU-s per camera (3 images) | x 130 cameras | vs dense | rays marched %% |\n");
  const double dense = cpu.back() / cams;
  for (std::size_t k = 0; k < scenes.size(); ++k)
    std::printf("| %s | %.3f | %.1f | %.2f | %.1f |\n", scenes[k].name.c_str(), cpu[k] / cams, 130 * cpu[k] / cams,
                cpu[k] / cams / dense, 100.0 * double(rays[k]) / double(rays[k] + interp[k]));
  return 0;
}

int cmd_session(const std::vector<Scene>& scenes) {
  std::string seis_text;
  insitu::SessionConfig cfg = insitu::parse_combined_config(read_text(kPaper), kPaper, kSeismicSections, seis_text);
  cfg.output_dir = (std::filesystem::temp_directory_path() / "paper_step_quality_session").string();
  cfg.mode = insitu::OutputMode::overwrite;
  cfg.up = {0, 0, -1};  // as panoptes run: depth is +z
  cfg.validate();
  std::printf("| scene | wall s | CPU-s | render s | composite s | encode s | copy s |\n");
  for (const Scene& sc : scenes) {
    insitu::Session session(cfg, sc.grid, insitu::LocalBlock::whole(sc.grid));
    auto input = [](const char* name, const std::vector<float>& v) {
      return insitu::FieldInput{name, v.data(), insitu::ScalarType::f32, {0, 0, 0}};
    };
    const double w0 = omp_get_wtime(), c0 = cpu_seconds();
    session.snapshot(0.0, {input("phi_p", sc.p), input("phi_s", sc.s)});
    const double wall = omp_get_wtime() - w0, cpu = cpu_seconds() - c0;
    const insitu::SessionStats st = session.stats();
    session.finalize();
    std::printf("| %s | %.1f | %.1f | %.1f | %.2f | %.2f | %.2f |\n", sc.name.c_str(), wall, cpu, st.time.render,
                st.time.composite, st.time.encode, st.time.copy);
    std::fflush(stdout);
  }
  std::filesystem::remove_all(cfg.output_dir);
  return 0;
}

// The saved real snapshots named in `list` (e.g. "1200,2400"); a step written "1200n", or every step
// when `nosheet`, gets the free-surface plane z = 0 replaced by z = 1 (the diagnosis of `real-nosheet`).
std::vector<Scene> real_scenes(const std::string& dir, const std::string& list, bool nosheet) {
  const auto g = paper_run_config().solver.grid;
  const GridGeometry grid{{g.nx, g.ny, g.nz}, {0, 0, 0}, {g.h, g.h, g.h}};
  const std::size_t n = std::size_t(g.nx) * std::size_t(g.ny) * std::size_t(g.nz);
  std::vector<Scene> scenes;
  for (const std::string& item : split(list, ',')) {
    const int step = std::stoi(item);
    Scene sc;
    sc.name = "step" + std::to_string(step);
    sc.grid = grid;
    sc.p = read_floats(field_path(dir, "phi_p", step), n);
    sc.s = read_floats(field_path(dir, "phi_s", step), n);
    if (nosheet || item.back() == 'n') {
      sc.name += "_nosheet";
      const std::size_t plane = std::size_t(g.nx) * std::size_t(g.ny);
      std::copy_n(sc.p.begin() + std::ptrdiff_t(plane), plane, sc.p.begin());
      std::copy_n(sc.s.begin() + std::ptrdiff_t(plane), plane, sc.s.begin());
    }
    scenes.push_back(std::move(sc));
  }
  return scenes;
}

std::vector<Candidate> parse_candidates(const std::string& s) {
  std::vector<Candidate> out;
  for (const std::string& item : split(s, ',')) {
    const auto parts = split(item, '/');
    if (parts.size() != 2) throw Error("candidate '" + item + "': expected STEP/TOLERANCE, e.g. 1.5/4");
    out.push_back({std::stod(parts[0]), std::stod(parts[1])});
  }
  if (out.empty()) throw Error("no candidates in '" + s + "'");
  return out;
}

std::vector<int> parse_ints(const std::string& s) {
  std::vector<int> out;
  for (const std::string& item : split(s, ',')) out.push_back(std::stoi(item));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::vector<std::string> a(argv + 1, argv + argc);
    if (a.size() >= 3 && a[0] == "fields") {
      std::vector<int> steps;
      for (std::size_t i = 2; i < a.size(); ++i) steps.push_back(std::stoi(a[i]));
      return cmd_fields(a[1], steps);
    }
    if (a.size() >= 5 && (a[0] == "real" || a[0] == "real-nosheet")) {
      std::vector<Scene> scenes = real_scenes(a[1], a[2], a[0] == "real-nosheet");
      return run_trials(scenes, parse_ints(a[3]), parse_candidates(a[4]), false, {0, 0, -1}, a.size() > 5 ? a[5] : "");
    }
    if ((a.size() >= 4 && a[0] == "cost") || (a.size() >= 3 && a[0] == "session")) {
      std::vector<Scene> scenes = real_scenes(a[1], a[2], false);
      Scene dense;
      dense.name = "dense";
      dense.grid = GridGeometry{{256, 512, 160}, {0, 0, 0}, {1, 1, 1}};
      DenseWaveScene w = dense_wave_scene(dense.grid);
      dense.p = std::move(w.p);
      dense.s = std::move(w.s);
      scenes.push_back(std::move(dense));
      if (a[0] == "session") {
        // The dense snapshot in the middle of the real ones, so load drifts hit both sides.
        std::rotate(scenes.begin() + std::ptrdiff_t(scenes.size() / 2), scenes.end() - 1, scenes.end());
        return cmd_session(scenes);
      }
      return cmd_cost(scenes, std::stoi(a[3]));
    }
    if (a.size() >= 3 && a[0] == "synthetic") {
      const GridGeometry grid{{256, 512, 160}, {0, 0, 0}, {1, 1, 1}};
      std::vector<Scene> scenes(1);
      scenes[0].name = "dense";
      scenes[0].grid = grid;
      DenseWaveScene w = dense_wave_scene(grid);
      scenes[0].p = std::move(w.p);
      scenes[0].s = std::move(w.s);
      return run_trials(scenes, parse_ints(a[1]), parse_candidates(a[2]), true, {0, 0, 0}, a.size() > 3 ? a[3] : "");
    }
    std::cerr << "usage: paper_step_quality fields DIR STEP... | real[-nosheet] DIR STEPS CAMERAS CANDIDATES [PNG_DIR] |"
                 " cost DIR STEPS EVERY | session DIR STEPS | synthetic CAMERAS CANDIDATES [PNG_DIR]\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "paper_step_quality: " << e.what() << "\n";
    return 1;
  }
}
