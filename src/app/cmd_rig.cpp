// `panoptes rig`: builds a camera rig and its navigation graph and prints them with quality figures,
// so users can compare rigs before a run (and tools can read the --json dump).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "app/command.hpp"
#include "camera/navigation.hpp"
#include "camera/rig_spec.hpp"
#include "camera/rig_stats.hpp"
#include "core/error.hpp"

namespace cmd_rig {  // named, not anonymous: the unity build joins the command units

using namespace panoptes;
using namespace panoptes::camera;

struct Options {
  std::string spec = "yinyang";
  std::vector<double> origin{0, 0, 0};
  std::vector<double> extent{1, 1, 1};
  bool list = false;
  bool json = false;
  bool no_stats = false;
  std::vector<double> nearest;  // lat, lon in degrees
  int nearest_shell = 0;
};

Vec3 vec3(const std::vector<double>& v) { return {v[0], v[1], v[2]}; }

nlohmann::json to_json(const Vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

void run(const Options& o) {
  const Domain domain{vec3(o.origin), vec3(o.extent)};
  domain.validate();
  auto t0 = std::chrono::steady_clock::now();
  const Rig rig = make_rig(o.spec, domain);
  const double make_ms = ms_since(t0);
  t0 = std::chrono::steady_clock::now();
  const NavigationGraph graph = build_navigation_graph(rig);
  const double graph_ms = ms_since(t0);
  // Cameras inside the volume: angles seen from the centre mean nothing there, distances do.
  const bool inside = rig.is_lattice() || rig.path;
  RigStatistics st;
  VolumeRigStatistics vst;
  double stats_ms = 0;
  if (!o.no_stats) {
    t0 = std::chrono::steady_clock::now();
    if (inside)
      vst = volume_rig_statistics(rig, graph);
    else
      st = rig_statistics(rig, graph);
    stats_ms = ms_since(t0);
  }
  int nearest = -1;
  if (!o.nearest.empty()) {
    constexpr double d = std::numbers::pi / 180;
    const double lat = o.nearest[0] * d, lon = o.nearest[1] * d;
    if (o.nearest_shell < 0 || o.nearest_shell >= rig.shell_count)
      throw Error("rig: --shell " + std::to_string(o.nearest_shell) + "; expected 0.." + std::to_string(rig.shell_count - 1));
    nearest = CameraLocator(rig).nearest({std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat)},
                                         o.nearest_shell);
  }

  if (o.json) {
    nlohmann::json j;
    j["spec"] = rig.spec;
    j["domain"] = {{"origin", to_json(domain.origin)}, {"extent", to_json(domain.extent)}, {"radius", domain.radius()}};
    j["center"] = to_json(rig.center);
    j["shells"] = rig.shell_count;
    nlohmann::json cams = nlohmann::json::array();
    for (int c = 0; c < rig.size(); ++c) {
      const RigCamera& k = rig.cameras[c];
      const Neighbours& nb = graph.neighbours[c];
      cams.push_back({{"id", c},
                      {"position", to_json(k.position)},
                      {"look_at", to_json(k.look_at)},
                      {"up", to_json(k.up)},
                      {"fov_y_degrees", k.fov_y_degrees},
                      {"patch", k.patch},
                      {"latitude_deg", k.latitude_deg},
                      {"longitude_deg", k.longitude_deg},
                      {"shell", k.shell},
                      {"radius", k.radius},
                      {"neighbours",
                       {{"right", nb.right}, {"left", nb.left}, {"up", nb.up}, {"down", nb.down}, {"in", nb.in},
                        {"out", nb.out}}}});
    }
    j["cameras"] = std::move(cams);
    if (!o.no_stats && inside)
      j["statistics"] = {{"lattice", vst.lattice},
                         {"spacing", to_json(vst.spacing)},
                         {"box_lo", to_json(vst.box_lo)},
                         {"box_hi", to_json(vst.box_hi)},
                         {"min_step", vst.min_step},
                         {"max_step", vst.max_step},
                         {"path_length", vst.path_length},
                         {"reverse_return", vst.reverse_return},
                         {"missing_moves", vst.missing_moves},
                         {"reachable_from_0", vst.reachable_from_0},
                         {"strongly_connected", vst.strongly_connected}};
    else if (!o.no_stats)
      j["statistics"] = {{"min_nearest_deg", st.min_nearest_deg},
                         {"max_nearest_deg", st.max_nearest_deg},
                         {"covering_deg", st.covering_deg},
                         {"right_left_return", st.right_left_return},
                         {"up_down_return", st.up_down_return},
                         {"left_right_return", st.left_right_return},
                         {"down_up_return", st.down_up_return},
                         {"right_left_undo", st.right_left_undo},
                         {"left_right_undo", st.left_right_undo},
                         {"up_down_undo", st.up_down_undo},
                         {"down_up_undo", st.down_up_undo},
                         {"missing_moves", st.missing_moves},
                         {"reachable_from_0", st.reachable_from_0},
                         {"strongly_connected", st.strongly_connected}};
    if (nearest >= 0 || !o.nearest.empty()) j["nearest"] = nearest;
    std::printf("%s\n", j.dump(1).c_str());
    return;
  }

  std::map<std::string, int> patches;
  for (const RigCamera& k : rig.cameras) ++patches[k.patch];
  std::printf("rig %s\n", rig.spec.c_str());
  std::printf("domain               origin %g,%g,%g extent %g,%g,%g (bounding-sphere radius R = %g)\n", domain.origin.x,
              domain.origin.y, domain.origin.z, domain.extent.x, domain.extent.y, domain.extent.z, domain.radius());
  if (inside) {
    std::printf("cameras              %d inside the domain (%s)\n", rig.size(), rig.is_lattice() ? "lattice" : "path");
    std::printf("field of view        %.3f deg for perspective frames (360-degree frames see everything)\n",
                rig.cameras.empty() ? 0.0 : rig.cameras[0].fov_y_degrees);
    if (!o.no_stats) {
      if (rig.is_lattice())
        std::printf("lattice              %d x %d x %d nodes, spacing %g, %g, %g (x, y, z)\n", vst.lattice[0], vst.lattice[1],
                    vst.lattice[2], vst.spacing.x, vst.spacing.y, vst.spacing.z);
      else
        std::printf("path                 length %g along the cameras\n", vst.path_length);
      std::printf("camera box           x %g..%g  y %g..%g  z %g..%g\n", vst.box_lo.x, vst.box_hi.x, vst.box_lo.y,
                  vst.box_hi.y, vst.box_lo.z, vst.box_hi.z);
      std::printf("neighbour distance   %g .. %g (one walk step)\n", vst.min_step, vst.max_step);
      std::printf("opposite move        returns for %.1f %% of moves\n", 100 * vst.reverse_return);
      std::printf("missing moves        %.1f %% of the six moves (%s)\n", 100 * vst.missing_moves,
                  rig.is_lattice() ? "lattice faces" : "path ends, sideways");
      std::printf("reachable            %d of %d from camera 0, %s\n", vst.reachable_from_0, rig.size(),
                  vst.strongly_connected ? "strongly connected" : "NOT strongly connected");
    }
  } else {
    std::printf("cameras              %d on %d shell%s\n", rig.size(), rig.shell_count, rig.shell_count == 1 ? "" : "s");
    for (int s = 0; s < rig.shell_count; ++s) {
      int count = 0;
      double rmin = 1e300, rmax = 0;
      for (const RigCamera& k : rig.cameras)
        if (k.shell == s) {
          ++count;
          rmin = std::min(rmin, k.radius);
          rmax = std::max(rmax, k.radius);
        }
      if (rmin == rmax)
        std::printf("  shell %-3d          %d cameras at radius %g (%.4g R)\n", s, count, rmin, rmin / domain.radius());
      else
        std::printf("  shell %-3d          %d cameras at radius %g..%g\n", s, count, rmin, rmax);
    }
    std::printf("patches             ");
    for (const auto& [name, count] : patches) std::printf(" %s %d", name.c_str(), count);
    std::printf("\nfield of view        %.3f deg (vertical, square or landscape images)\n",
                rig.cameras.empty() ? 0.0 : rig.cameras[0].fov_y_degrees);
    if (!o.no_stats) {
      std::printf("nearest neighbour    %.3f .. %.3f deg (max/min %.3f)\n", st.min_nearest_deg, st.max_nearest_deg,
                  st.min_nearest_deg > 0 ? st.max_nearest_deg / st.min_nearest_deg : 0.0);
      std::printf("covering radius      %.3f deg (no direction farther from a camera)\n", st.covering_deg);
      // What a user sees (the players retrace the last moves) and what the graph alone gives.
      const struct {
        const char* name;
        double undo, graph;
      } pairs[] = {{"right then left", st.right_left_undo, st.right_left_return},
                   {"left then right", st.left_right_undo, st.left_right_return},
                   {"up then down", st.up_down_undo, st.up_down_return},
                   {"down then up", st.down_up_undo, st.down_up_return}};
      for (const auto& p : pairs)
        std::printf("%-20s returns for %.1f %% of cameras in the players (graph alone %.1f %%)\n", p.name, 100 * p.undo,
                    100 * p.graph);
      std::printf("missing moves        %.1f %% of right/left/up/down\n", 100 * st.missing_moves);
      std::printf("reachable            %d of %d from camera 0, %s\n", st.reachable_from_0, rig.size(),
                  st.strongly_connected ? "strongly connected" : "NOT strongly connected");
    }
  }
  std::printf("time                 rig %.2f ms, graph %.2f ms%s", make_ms, graph_ms, o.no_stats ? "\n" : "");
  if (!o.no_stats) std::printf(", statistics %.1f ms\n", stats_ms);
  if (!o.nearest.empty())
    std::printf("nearest to lat %g lon %g on shell %d: camera %d\n", o.nearest[0], o.nearest[1], o.nearest_shell, nearest);
  if (o.list) {
    std::printf("\n%6s %-9s %5s %8s %9s %10s %6s %6s %6s %6s %6s %6s\n", "id", "patch", "shell", "lat", "lon", "radius",
                "right", "left", "up", "down", "in", "out");
    for (int c = 0; c < rig.size(); ++c) {
      const RigCamera& k = rig.cameras[c];
      const Neighbours& nb = graph.neighbours[c];
      std::printf("%6d %-9s %5d %8.3f %9.3f %10.4g %6d %6d %6d %6d %6d %6d\n", c, k.patch.c_str(), k.shell,
                  k.latitude_deg, k.longitude_deg, k.radius, nb.right, nb.left, nb.up, nb.down, nb.in, nb.out);
    }
  }
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto opts = std::make_shared<Options>();
  auto* sub = root.add_subcommand(
      "rig",
      "Build a camera rig and its navigation graph; print camera count, spacing, coverage and how well the "
      "arrow-key moves reverse");
  sub->footer(
      "RIG syntax: yinyang[:NTxNP] (default 5x13 = 130), latlon[:NLATxNLON[+poles]] (default 8x16+poles),\n"
      "fibonacci[:N] (default 130), file:PATH or PATH (text: 'x y z [lx ly lz [ux uy uz [fov [shell]]]]' per line;\n"
      "or JSON {\"cameras\": [{\"position\": [x,y,z], ...}]}). Built-in kinds take @R1,R2,... = shell radii in\n"
      "bounding-sphere radii (default @3), e.g. shells:yinyang@1.5,2.5,4. Inside the volume: lattice:NXxNYxNZ[@MARGIN]\n"
      "and path:FILE (statistics in world units: spacing, walk steps). See docs/cameras.md.\n"
      "Examples:\n"
      "  panoptes rig yinyang\n"
      "  panoptes rig fibonacci:10000 --extent 256,512,160\n"
      "  panoptes rig shells:yinyang:8x20@2,4 --json > rig.json");
  sub->add_option("RIG", opts->spec, "Rig spec or camera file (default yinyang)");
  sub->add_option("--origin", opts->origin, "Domain origin X,Y,Z (default 0,0,0)")->delimiter(',')->expected(3);
  sub->add_option("--extent", opts->extent, "Domain extent X,Y,Z (default 1,1,1)")->delimiter(',')->expected(3);
  sub->add_flag("--list", opts->list, "Also print every camera with its labels and neighbours");
  sub->add_flag("--json", opts->json, "Print the rig, its graph and statistics as JSON instead");
  sub->add_flag("--no-stats", opts->no_stats, "Skip the statistics (they take seconds for 10^6 cameras)");
  sub->add_option("--nearest", opts->nearest, "Print the camera nearest to the direction LAT,LON (degrees)")
      ->delimiter(',')
      ->expected(2);
  sub->add_option("--shell", opts->nearest_shell, "Shell for --nearest (default 0 = outermost)");
  sub->callback([opts] { run(*opts); });
});

}  // namespace
