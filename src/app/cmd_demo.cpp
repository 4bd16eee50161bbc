// `panoptes demo [--out DIR]`: `panoptes run` on an embedded default (the same text as
// examples/demo.toml): a layered crust, a double-couple source, the paper's 130-camera Yin-Yang rig and
// its three tasks (p-waves orange, s-waves green, both); its measured run time is the config's
// "# Measured:" line.
#include <cstdio>
#include <memory>
#include <string>

#include "app/command.hpp"
#include "app/seismic_run.hpp"

namespace panoptes::app {

namespace cmd_demo {  // named, not anonymous: the unity build joins the command units

const char* kDemoConfig = R"TOML(# `panoptes demo`: the paper's demonstration, sized to run in minutes on a 2-core machine.
# A double-couple (thrust) earthquake in a three-layer crust; 130 Yin-Yang cameras x 3 tasks
# (both together first, then p-waves phi_p = div v in orange, s-waves phi_s = |curl v| in green) = 390 movies.
# Run:  panoptes run examples/demo.toml          (or: mpirun -np 2 panoptes run examples/demo.toml)
# Full paper setting: examples/paper.toml.
# Measured: 129 s wall for the whole demo (48 snapshots at 528x512) with OpenMP waiting passively as scripts/demo runs it, 2026-11-30 04:49 UTC on the shared 2-core machine (AMD EPYC) with nothing else running (load 1.0 at start); 243 CPU-seconds (user + system); of the wall time render 76 %, encode 16 %, composite 7 %, simulation 1 %.

[grid]                 # 25.6 x 51.2 x 16 km, like the paper's domain, at h = 400 m (1/4 of its resolution)
nx = 64
ny = 128
nz = 40
h = 400.0

[time]
steps = 480            # ~ 13 s of ground motion (dt ~ 27 ms)

[medium]
type = "layered"
[[medium.layer]]       # sediments
top = 0.0
rho = 2300.0
vp = 3000.0
vs = 1700.0
[[medium.layer]]       # upper crust
top = 2000.0
rho = 2600.0
vp = 5500.0
vs = 3200.0
[[medium.layer]]       # lower crust
top = 8000.0
rho = 2900.0
vp = 6500.0
vs = 3700.0

[boundary]
free_surface = true
pml_cells = 10

[[source]]             # M 5.9 thrust at 6 km depth
type = "double_couple"
position = [12800.0, 25600.0, 6000.0]
strike = 30.0
dip = 45.0
rake = 90.0
m0 = 1.0e18
stf = "kupper"
duration = 4.0

[output]
dir = "panoptes_demo"
title = "Seismic waves from a thrust earthquake (panoptes demo)"

[image]                # the paper's 920x896 aspect at 512 pixels high: 3.5-4 pixels per voxel of this grid
width = 528            # (issue 45 brought it back from 400x390 once the march had got faster)
height = 512

[rig]
spec = "yinyang"       # the paper's 130 cameras: 5 x 13 cells per patch
up_axis = "z_down"     # z is depth: the sky is -z (poles, latitudes, image up and the Up key follow it)
# Cameras INSIDE the volume instead (docs/cameras.md): a 4x4x3 lattice of 360-degree cameras; the player
# then shows a look-around (left-drag, wheel) and the arrows / PgUp / PgDn walk between lattice nodes.
# Use a 2:1 image (e.g. width = 1024, height = 512). Full example: examples/lattice_inside.toml.
# spec = "lattice:4x4x3@0.05"
# projection = "equirectangular"

[schedule]
every_steps = 10       # 48 snapshots

[video]                # intra-only: the player's fastest random access, ~1 MB per open writer (P-frames keep a
gop = 1                # 3 MB encoder per writer; their size gain is unmeasured: docs/measurements/insitu.md); crf 23: -14 %, 45 dB
crf = 23
preset = "superfast"
playback_fps = 10      # the player shows the 48 snapshots in 4.8 s (the movies themselves are 30 fps)

[render]               # 1.0 voxel: the largest step whose frames look like 0.5 voxel's. Measured on the demo's
sample_distance = 1.0  # mid-run frames (6 cameras x 3 tasks, lossless movies) against 0.5, with the windows below
percentile = 0.999     # and phi without the surface sheet (2026-11-25): PSNR mean 55-56 dB, min 44.7 (p+s, the view
                       # down onto the surface); 1.5 voxel: min 39.1 dB. (With the sheet and the former windows the
                       # saturated p rings at the surface gave min 34 dB at 1.0, 26 at 1.5: docs/measurements/insitu.md.)
                       # 0.5 voxel would cost more march for no visible gain.
adaptive = true        # 3-4 px per voxel: interpolate smooth cells of every 4th pixel's rays; frames within
                       # 65.6 dB (min) of marching every pixel, the thin gaps kept (docs/rendering.md, Round 4)

# Windows are relative: multiples of the running maximum of the 99.9th percentile of |phi_p| (|phi_s|),
# the default [render] reference = "running" (issue 41): the scale never shrinks, so a colour keeps its
# value in 1/s along the movie and the waves darken as they spread (the legend shows the window in 1/s).
# Per snapshot (the former default) camera 0's p-wave movie brightened by +70 % at frame 20 while the
# field weakened. The references peak near the source at frame 6 (phi_s 6.3e-4 1/s) and the waves fall to
# about 0.1 of that by the end, so the windows end at 0.15 of the reference: the near-source frames
# saturate, the rings stay readable to the last frame.
[[task]]               # first: the paper's two-colour picture is what the player opens on
name = "p+s"
type = "volume2"
fields = ["phi_p", "phi_s"]
preset = "p-wave"
preset2 = "s-wave"
# Both fields are in 1/s, so they share one reference, the larger (phi_s's: 2-5x phi_p's; [render]
# share_scale = "units"): a weak field stays dark (an explosion shows orange p and no green, where each
# field on its own scale showed an all-green picture). p's window is a third of s's, the ratio of the
# two in this source, so both ring families show; the legend gives both windows in 1/s.
window = [0.0, 0.05]
window2 = [0.0, 0.15]

[[task]]
name = "p-wave"
type = "volume"
field = "phi_p"
preset = "p-wave"
# phi_p's running reference is set near the source by the reference floor (0.02 x max |phi_p|: 4.6e-4 1/s
# against a percentile of 1.5e-4), so its window ends at a third of s's fraction: the same 2.3e-5 1/s.
window = [0.0, 0.05]

[[task]]
name = "s-wave"
type = "volume"
field = "phi_s"
preset = "s-wave"
window = [0.0, 0.15]
)TOML";

// The demo's measured run time, stated once: the configuration's "# Measured: ..." comment line
// (README.md quotes it verbatim; cli.demo checks both).
std::string measured_time() {
  const std::string text = kDemoConfig;
  const std::string key = "\n# Measured: ";
  const auto at = text.find(key);
  if (at == std::string::npos) return "";
  const auto begin = at + key.size();
  return text.substr(begin, text.find('\n', begin) - begin);
}

// Printed under the overhead line, which for the demo alone reads as alarming, and so does the size line
// above it: its simulation is tiny on purpose. The paper-scale figures are the measured paper run of
// 2026-11-29 (docs/rendering.md, round 14: 18.1-19.0 min in four runs, database 580 MB = 5.8 % of the raw fields).
const char* kOverheadNote =
    "  (the demo's grid, 64x128x40, is small so that the demo runs in minutes: its simulation is cheap and this\n"
    "  ratio large. At the paper's 256x512x160 grid, panoptes run examples/paper.toml (60 snapshots, 390 movies\n"
    "  of 920x896) took 18-19 min on 2 cores, visualization 3.4x the simulation in wall time: docs/rendering.md, round 14.)\n"
    "  Why the movies outweigh the raw fields here: movies grow with cameras x pixels (390 pictures of 528x512\n"
    "  per snapshot), raw fields with the grid (2 x 0.33 M voxels here). At the paper's size the same 390\n"
    "  movies took 580 MB against 10.1 GB of raw phi_p, phi_s: 5.8 % (measured 2026-11-29, docs/rendering.md);\n"
    "  the larger the simulation, the smaller that share.";

CommandRegistration reg([](CLI::App& root) {
  auto opt = std::make_shared<SeismicRunOptions>();
  auto print = std::make_shared<bool>(false);
  auto* sub = root.add_subcommand(
      "demo",
      "Run the built-in seismic demo with in-situ visualization: a thrust earthquake in a layered crust seen "
      "by the paper's 130 Yin-Yang cameras x 3 tasks (p+s: p-waves orange and s-waves green together, then "
      "each alone) = 390 movies, "
      "48 snapshots of 528x512 pixels (also under mpirun -np N). Measured: " + measured_time() +
      " Then: panoptes play DIR.");
  sub->add_option("--out", opt->out, "Database directory")->capture_default_str();
  opt->out = "panoptes_demo";
  sub->add_flag("--overwrite", opt->overwrite, "Replace an existing database in --out");
  sub->add_flag("-q,--quiet", opt->quiet, "No progress output");
  sub->add_flag("--print-config", *print, "Print the embedded configuration (a starting point for panoptes run) and exit");
  sub->callback([opt, print] {
    if (*print) {
      std::fputs(kDemoConfig, stdout);
      return;
    }
    opt->overhead_note = kOverheadNote;
    opt->existing_database_advice = "add --overwrite to replace it, or give another --out";
    opt->command_line = "panoptes demo --out " + opt->out + (opt->overwrite ? " --overwrite" : "");
    run_seismic_insitu(kDemoConfig, "embedded demo configuration", ".", *opt);
  });
});

}  // namespace
}  // namespace panoptes::app
