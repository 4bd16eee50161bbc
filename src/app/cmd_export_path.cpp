// `panoptes export-path DB --script FILE --out movie.mp4`: the sequence a scripted playback shows
// (the user's own path through the database, e.g. a fly-around for a talk) as one ordinary movie.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "app/command.hpp"
#include "app/task_option.hpp"
#include "core/error.hpp"
#include "player/headless.hpp"
#include "player/legend_image.hpp"
#include "player/look.hpp"
#include "video/movie_writer.hpp"

namespace cmd_export_path {  // named, not anonymous: the unity build joins the command units

struct ExportArgs {
  std::string db, script, out;
  double duration = 0;
  int camera = 0, frame = 0;
  std::string task = "0";  // an index or a name
  int crf = -1;
  bool paused = false;
  std::string view_size = "1280x720";
  double speed = 0;  // 0 = automatic (the players' short-run rule)
  bool legend = true;  // the shown task's colour legend in the bottom-left corner, as the players show it
};

void run_export(const ExportArgs& a) {
  namespace player = panoptes::player;
  if (!std::filesystem::exists(std::filesystem::path(a.db) / "panoptes.json"))
    throw panoptes::FileError(a.db, std::filesystem::exists(a.db)
                                        ? "not a Panoptes database (no panoptes.json inside)"
                                        : "no such database directory");
  player::HeadlessOptions o;
  o.engine.camera = a.camera;
  o.engine.task = panoptes::app::resolve_task_option(a.db, a.task);
  o.engine.frame = a.frame;
  o.engine.start_playing = !a.paused;
  o.speed = a.speed;  // 0: the short-run rule, as the window starts
  o.script = player::read_script(a.script);
  if (a.duration > 0) o.duration = a.duration;
  // The writer is created at the first frame, when the frame size is known; the output settings follow
  // the database's (CRF) unless --crf is given. The movie's rate is the player's (the manifest's
  // playback_fps if set): the headless run shows one frame per 1/rate s of its clock, so a 5 s path is
  // a 5 s movie. All-frames-seekable is not needed here, so the GOP is the usual one for ordinary players.
  std::unique_ptr<panoptes::video::MovieWriter> writer;
  const auto manifest = panoptes::store::Database::open(a.db).manifest();
  panoptes::video::VideoSettings settings = manifest.video;
  if (manifest.playback_fps > 0) settings.fps = manifest.playback_fps;  // as player::Engine::fps()
  settings.gop = std::max(settings.gop, int(settings.fps));
  if (a.crf >= 0) settings.crf = a.crf;
  const auto parent = std::filesystem::path(a.out).parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent))
    throw panoptes::FileError(a.out, "the output directory does not exist");
  // 360-degree databases: the movie shows the script's look (look=) cut out of each frame, as the window does.
  const bool equirect = player::is_equirectangular(manifest);
  int view_w = 0, view_h = 0;
  if (equirect && (std::sscanf(a.view_size.c_str(), "%dx%d", &view_w, &view_h) != 2 || view_w < 16 || view_h < 16 ||
                   view_w > 8192 || view_h > 8192 || view_w % 2 || view_h % 2))
    throw panoptes::Error("--view-size \"" + a.view_size + "\": expected an even WIDTHxHEIGHT between 16 and 8192, e.g. 1280x720");
  o.on_frame = [&](const player::DisplayedFrame& f) {
    auto image = panoptes::video::MovieReader::to_rgba(*f.shown.frame);
    if (equirect) {
      panoptes::Image view(view_w, view_h, image.channels);
      player::perspective_cutout(image, player::camera_basis(manifest.cameras[std::size_t(f.shown.selection.camera)]),
                                 f.look, view);
      image = std::move(view);
    }
    // Issue 41: a preview shown outside Panoptes still says what its colours stand for (the legend of
    // the shown task at the shown frame, with its scale line).
    if (a.legend) player::draw_legend(image, manifest, f.shown.selection.task, f.shown.selection.frame);
    if (!writer)
      writer = std::make_unique<panoptes::video::MovieWriter>(a.out, image.width, image.height, settings);
    writer->append(image);
  };
  const auto r = player::run_headless(a.db, o);
  if (writer) writer->close();
  std::printf("wrote %s: %d frames at %g fps = %.1f s, the player's rate (%d placeholders)\n", a.out.c_str(),
              r.frames_displayed, settings.fps, r.frames_displayed / settings.fps, r.placeholders);
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
  sub->add_option("--task", args->task, "Start task: its id or its name (e.g. p+s)");
  sub->add_option("--frame", args->frame, "Start frame")->check(CLI::NonNegativeNumber);
  sub->add_option("--speed", args->speed,
                  "Playback speed factor (0.25 .. 8) of the database's playback rate (default: x1, slowed down as "
                  "the players do so that a run of few frames lasts at least 4 s)")
      ->check(CLI::Range(0.25, 8.0));
  sub->add_flag("--paused", args->paused, "Start paused (the script's Space starts playback)");
  sub->add_option("--view-size", args->view_size,
                  "360-degree databases: size of the perspective view cut out of each frame (the script's look=)")
      ->capture_default_str();
  sub->add_option("--crf", args->crf, "x264 constant rate factor 0..51 (default: the database's)")
      ->check(CLI::Range(0, 51));
  sub->add_flag("--legend,!--no-legend", args->legend,
                "Draw the shown task's colour legend (window in physical units, scale mode) into the bottom-left "
                "corner of each frame (default: on)");
  sub->callback([args] { run_export(*args); });
});

}  // namespace
