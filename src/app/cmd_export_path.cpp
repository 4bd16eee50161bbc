// `panoptes export-path DB --script FILE --out movie.mp4`: the sequence a scripted playback shows
// (the user's own path through the database, e.g. a fly-around for a talk) as one ordinary movie.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "app/command.hpp"
#include "core/error.hpp"
#include "player/headless.hpp"
#include "video/movie_writer.hpp"

namespace {

struct ExportArgs {
  std::string db, script, out;
  double duration = 0;
  int camera = 0, task = 0, frame = 0;
  int crf = -1;
  bool paused = false;
};

void run_export(const ExportArgs& a) {
  namespace player = panoptes::player;
  if (!std::filesystem::exists(std::filesystem::path(a.db) / "panoptes.json"))
    throw panoptes::FileError(a.db, std::filesystem::exists(a.db)
                                        ? "not a Panoptes database (no panoptes.json inside)"
                                        : "no such database directory");
  player::HeadlessOptions o;
  o.engine.camera = a.camera;
  o.engine.task = a.task;
  o.engine.frame = a.frame;
  o.engine.start_playing = !a.paused;
  o.script = player::read_script(a.script);
  if (a.duration > 0) o.duration = a.duration;
  // The writer is created at the first frame, when the frame size is known; the output settings follow
  // the database's (frame rate, CRF) unless --crf is given. All-frames-seekable is not needed here, so
  // the GOP is the usual one for ordinary players.
  std::unique_ptr<panoptes::video::MovieWriter> writer;
  const auto manifest = panoptes::store::Database::open(a.db).manifest();
  panoptes::video::VideoSettings settings = manifest.video;
  settings.gop = std::max(settings.gop, int(settings.fps));
  if (a.crf >= 0) settings.crf = a.crf;
  const auto parent = std::filesystem::path(a.out).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent))
    throw panoptes::FileError(a.out, "the output directory does not exist");
  o.on_frame = [&](const player::DisplayedFrame& f) {
    const auto image = panoptes::video::MovieReader::to_rgba(*f.shown.frame);
    if (!writer)
      writer = std::make_unique<panoptes::video::MovieWriter>(a.out, image.width, image.height, settings);
    writer->append(image);
  };
  const auto r = player::run_headless(a.db, o);
  if (writer) writer->close();
  std::printf("wrote %s: %d frames at %g fps (%d placeholders)\n", a.out.c_str(), r.frames_displayed, settings.fps,
              r.placeholders);
}

panoptes::app::CommandRegistration reg([](CLI::App& root) {
  auto args = std::make_shared<ExportArgs>();
  auto* sub = root.add_subcommand(
      "export-path",
      "Write the frames a scripted playback shows (your path through cameras, tasks and time) as one MP4");
  sub->footer("The script has the format of `panoptes play --headless --script` (see `panoptes play --help`).");
  sub->add_option("db", args->db, "Database directory (holds panoptes.json)")->required();
  sub->add_option("--script", args->script, "Script of timed commands, e.g. `t=0.5 key=Right`")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--out", args->out, "Output movie (.mp4)")->required();
  sub->add_option("--duration", args->duration, "Seconds to export (default: until the last command is shown)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--camera", args->camera, "Start camera id")->check(CLI::NonNegativeNumber);
  sub->add_option("--task", args->task, "Start task id")->check(CLI::NonNegativeNumber);
  sub->add_option("--frame", args->frame, "Start frame")->check(CLI::NonNegativeNumber);
  sub->add_flag("--paused", args->paused, "Start paused (the script's Space starts playback)");
  sub->add_option("--crf", args->crf, "x264 constant rate factor 0..51 (default: the database's)")
      ->check(CLI::Range(0, 51));
  sub->callback([args] { run_export(*args); });
});

}  // namespace
