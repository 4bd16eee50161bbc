// `panoptes import-cinema IN.cdb OUT`: a Cinema image database (Spec D or A) as a movie database.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "app/command.hpp"
#include "cinema/import.hpp"

namespace cmd_import_cinema {  // named, not anonymous: the unity build joins the command units

struct Args {
  std::string in, out, group_by, title, angles, azimuth_zero, image_column;
  int crf = -1, threads = 0;
  bool overwrite = false;
};

void run(const Args& a) {
  using namespace panoptes;
  cinema::ImportOptions o;
  std::stringstream list(a.group_by);
  for (std::string item; std::getline(list, item, ',');)
    if (!item.empty()) o.group_by.push_back(item);
  o.title = a.title;
  o.angles = a.angles;
  o.azimuth_zero = a.azimuth_zero;
  o.image_column = a.image_column;
  o.command_line = "panoptes import-cinema " + a.in + " " + a.out + (a.group_by.empty() ? "" : " --group-by " + a.group_by) +
                   (a.angles.empty() ? "" : " --angles " + a.angles) + (a.azimuth_zero.empty() ? "" : " --azimuth-zero " + a.azimuth_zero) +
                   (a.image_column.empty() ? "" : " --image-column " + a.image_column);
  o.overwrite = a.overwrite;
  o.overwrite_option = "--overwrite";
  o.threads = a.threads;
  if (a.crf >= 0) o.video.crf = a.crf;
  o.video.validate();
  const bool tty = ::isatty(STDERR_FILENO);
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = cinema::import_cinema(a.in, a.out, o, [&](std::int64_t done, std::int64_t total) {
    if (tty) std::fprintf(stderr, "\rimport-cinema: %lld / %lld images", (long long)done, (long long)total), std::fflush(stderr);
  });
  if (tty) std::fprintf(stderr, "\n");
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("wrote %s from Cinema Spec %s: %d cameras x %d tasks = %d movies, %d frames each, in %.2f s\n",
              a.out.c_str(), r.spec.c_str(), r.cameras, r.tasks, r.cameras * r.tasks, r.frames, s);
  std::printf("cameras: %s\n", r.producer.c_str());
  for (const auto& w : r.warnings) std::fprintf(stderr, "panoptes: warning: %s\n", w.c_str());
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto args = std::make_shared<Args>();
  auto* sub = root.add_subcommand(
      "import-cinema",
      "Turn a Cinema image database (Spec D data.csv, or Spec A info.json + name_pattern as ParaView and Ascent "
      "write) into a movie database: the time column gives the frames, phi and theta the cameras (built as the "
      "producer built them: ParaView extractors, cinema_python and Ascent are recognised; views ParaView wrote upside "
      "down are turned upright; navigation graph computed), the other columns the tasks; numeric ones become "
      "parameter axes. A database exported by Panoptes gets its cameras, graph and tasks back exactly. Then "
      "`panoptes play OUT` switches between them instantly");
  sub->add_option("IN", args->in, "Cinema database directory (NAME.cdb)")->required();
  sub->add_option("OUT", args->out, "Movie database directory to write")->required();
  sub->add_option("--group-by", args->group_by,
                  "Comma-separated columns whose value combinations make the tasks (default: every column but time, "
                  "camera, phi, theta and FILE)");
  sub->add_option("--title", args->title, "Title of the database");
  sub->add_option("--angles", args->angles,
                  "How phi/theta were made, when the producer is not recognised or its evidence disagrees: paraview (5.11 image extractor, "
                  "Phi-Theta), cinema-python, ascent (theta polar from +z 0..180, or a latitude -90..90 as older Ascent wrote) or elevation (theta -90..90 above the x-y "
                  "plane, phi about +z)")
      ->check(CLI::IsMember({"paraview", "cinema-python", "ascent", "elevation"}));
  sub->add_option("--azimuth-zero", args->azimuth_zero,
                  "With --angles elevation: where phi = 0 lies, +x (phi counter-clockwise seen from +z, default) or -x "
                  "(clockwise)")
      ->check(CLI::IsMember({"+x", "-x"}));
  sub->add_option("--image-column", args->image_column,
                  "data.csv column holding each row's image (default FILE, or ParaView's FILE_<ext>; when rows hold "
                  "two images, e.g. FILE and FILE2, the first is imported and the others named in a warning)");
  sub->add_option("--crf", args->crf, "x264 quality 0..51 (default: the video default, 20)");
  sub->add_option("--threads", args->threads, "Streams encoded in parallel (0 = all cores)")->check(CLI::Range(0, 1024));
  sub->add_flag("--overwrite", args->overwrite, "Replace an existing database in OUT");
  sub->callback([args] { run(*args); });
});

}  // namespace
