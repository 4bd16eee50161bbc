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

namespace {

struct Args {
  std::string in, out, group_by, title;
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
  o.command_line = "panoptes import-cinema " + a.in + " " + a.out + (a.group_by.empty() ? "" : " --group-by " + a.group_by);
  o.overwrite = a.overwrite;
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
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto args = std::make_shared<Args>();
  auto* sub = root.add_subcommand(
      "import-cinema",
      "Turn a Cinema image database (Spec D data.csv, or Spec A info.json + name_pattern as ParaView and Ascent "
      "write) into a movie database: the time column gives the frames, phi (azimuth) and theta (elevation) in "
      "degrees the camera directions (navigation graph computed), the other columns the tasks; numeric ones "
      "become parameter axes. Then `panoptes play OUT` switches between them instantly");
  sub->add_option("IN", args->in, "Cinema database directory (NAME.cdb)")->required();
  sub->add_option("OUT", args->out, "Movie database directory to write")->required();
  sub->add_option("--group-by", args->group_by,
                  "Comma-separated columns whose value combinations make the tasks (default: every column but time, "
                  "camera, phi, theta and FILE)");
  sub->add_option("--title", args->title, "Title of the database");
  sub->add_option("--crf", args->crf, "x264 quality 0..51 (default: the video default, 20)");
  sub->add_option("--threads", args->threads, "Streams encoded in parallel (0 = all cores)")->check(CLI::Range(0, 1024));
  sub->add_flag("--overwrite", args->overwrite, "Replace an existing database in OUT");
  sub->callback([args] { run(*args); });
});

}  // namespace
