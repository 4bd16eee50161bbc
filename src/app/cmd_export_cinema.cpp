// `panoptes export-cinema DB OUT.cdb`: a movie database as a Cinema Spec D image database.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>

#include "app/command.hpp"
#include "cinema/export.hpp"
#include "player/legend_image.hpp"
#include "store/database.hpp"

namespace cmd_export_cinema {  // named, not anonymous: the unity build joins the command units

struct Args {
  std::string db, out, frames, format = "png";
  int quality = 95, threads = 0;
  bool overwrite = false;
  bool legend = false;  // Cinema images are data (import-cinema reads them back): a legend only when asked
};

void run(const Args& a) {
  using namespace panoptes;
  cinema::ExportOptions o;
  if (!a.frames.empty()) o.frames = cinema::parse_frame_list(a.frames, store::Database::open(a.db).frame_count());
  o.format = a.format;
  o.jpeg_quality = a.quality;
  o.overwrite = a.overwrite;
  o.threads = a.threads;
  std::optional<store::Manifest> manifest;
  if (a.legend) {
    manifest = store::Database::open(a.db).manifest();
    o.decorate = [&manifest](Image& image, int, int task, int frame) { player::draw_legend(image, *manifest, task, frame); };
  }
  const bool tty = ::isatty(STDERR_FILENO);
  const auto t0 = std::chrono::steady_clock::now();
  const auto report = cinema::export_cinema(a.db, a.out, o, [&](std::int64_t done, std::int64_t total) {
    if (tty) std::fprintf(stderr, "\rexport-cinema: %lld / %lld images", (long long)done, (long long)total), std::fflush(stderr);
  });
  if (tty) std::fprintf(stderr, "\n");
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("wrote %s: Cinema Spec D, %lld %s images + data.csv (%.1f MB) in %.2f s\n", a.out.c_str(),
              (long long)report.images, a.format.c_str(), report.bytes / 1e6, s);
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto args = std::make_shared<Args>();
  auto* sub = root.add_subcommand(
      "export-cinema",
      "Export a movie database as a Cinema Spec D image database for Cinema viewers (Cinema:View, Cinema:Explorer) "
      "and pycinema: data.csv, one image per camera, task and frame, and panoptes-cinema.json (cameras, shells, graph, "
      "tasks: import-cinema restores them). data.csv's numeric columns identify each image once, so every image is "
      "reachable from the viewers' sliders: time; phi (longitude) and theta (latitude) in degrees, and shell, when "
      "the cameras form that grid, else camera; the parameter axes when the tasks form their grid, else task (id). "
      "A failed export leaves nothing behind");
  sub->add_option("DB", args->db, "Movie database directory")->required();
  sub->add_option("OUT", args->out, "Cinema database directory to write (conventionally NAME.cdb)")->required();
  sub->add_option("--frames", args->frames,
                  "Frames to export: a list of frames and start:stop[:step] ranges (stop exclusive), e.g. 0,5,10:20:2 "
                  "(default: all complete frames)");
  sub->add_option("--format", args->format, "Image format")->check(CLI::IsMember({"png", "jpg"}))->capture_default_str();
  sub->add_option("--quality", args->quality, "JPEG quality 1..100")->check(CLI::Range(1, 100))->capture_default_str();
  sub->add_option("--threads", args->threads, "Streams decoded in parallel (0 = all cores)")->check(CLI::Range(0, 1024));
  sub->add_flag("--overwrite", args->overwrite, "Replace an existing Cinema database in OUT");
  sub->add_flag("--legend", args->legend,
                "Draw each image's colour legend (the task's window in physical units at that frame, its scale mode) "
                "into its bottom-left corner, as the players show it (default: off: the images stay the frames)");
  sub->callback([args] { run(*args); });
});

}  // namespace
