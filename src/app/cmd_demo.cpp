// `panoptes demo [--out DIR]`: `panoptes run` on an embedded default (the same text as
// examples/demo.toml): a layered crust, a double-couple source, the paper's 130-camera Yin-Yang rig and
// its three tasks (p-waves orange, s-waves green, both), sized for about two minutes on two cores.
#include <cstdio>
#include <memory>
#include <string>

#include "app/command.hpp"
#include "app/seismic_run.hpp"

namespace panoptes::app {

namespace {

const char* kDemoConfig = R"TOML(# `panoptes demo`: the paper's demonstration at a size that runs in about two minutes on two cores.
# A double-couple (thrust) earthquake in a three-layer crust; 130 Yin-Yang cameras x 3 tasks
# (p-waves phi_p = div v in orange, s-waves phi_s = |curl v| in green, both together) = 390 movies.
# Run:  panoptes run examples/demo.toml          (or: mpirun -np 2 panoptes run examples/demo.toml)
# Full paper setting: examples/paper.toml.

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

[image]
width = 256
height = 224

[rig]
spec = "yinyang"       # the paper's 130 cameras: 5 x 13 cells per patch

[schedule]
every_steps = 20       # 24 snapshots

[video]                # measured on the demo's frames (docs/insitu.md): P-frames (gop > 1) save
gop = 1                # 3 % here for 3 MB per open writer; crf 23 saves 14 % over 20 at 45 dB
crf = 23
preset = "superfast"

[render]
sample_distance = 1.0
percentile = 0.999

[[task]]
name = "p-wave"
type = "volume"
field = "phi_p"
preset = "p-wave"
window = [0.0, 1.0]    # relative: multiples of the running 99.9th percentile of |phi_p|

[[task]]
name = "s-wave"
type = "volume"
field = "phi_s"
preset = "s-wave"
window = [0.0, 1.0]

[[task]]
name = "p+s"
type = "volume2"
fields = ["phi_p", "phi_s"]
preset = "p-wave"
preset2 = "s-wave"
window = [0.0, 1.0]
window2 = [0.0, 1.0]
)TOML";

CommandRegistration reg([](CLI::App& root) {
  auto opt = std::make_shared<SeismicRunOptions>();
  auto print = std::make_shared<bool>(false);
  auto* sub = root.add_subcommand(
      "demo",
      "Run the built-in seismic demo with in-situ visualization: a thrust earthquake in a layered crust seen "
      "by the paper's 130 Yin-Yang cameras x 3 tasks (p-waves orange, s-waves green, both) = 390 movies; "
      "about two minutes on two cores (also under mpirun -np N). Then: panoptes play DIR.");
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
    opt->command_line = "panoptes demo --out " + opt->out;
    run_seismic_insitu(kDemoConfig, "embedded demo configuration", ".", *opt);
  });
});

}  // namespace
}  // namespace panoptes::app
