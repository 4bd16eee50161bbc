#pragma once
// Synthetic databases: every frame carries the stamp of its (camera, task, frame) plus some visible
// moving content, so player tests and benchmarks can verify *which* frame is shown.
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/image.hpp"
#include "store/manifest.hpp"
#include "video/video_settings.hpp"

namespace panoptes::store {

/// What to generate.
struct SyntheticOptions {
  int cameras = 8;
  int tasks = 2;
  int frames = 10;
  int width = 64, height = 64;
  video::VideoSettings video;   ///< encoder settings of every stream
  bool overwrite = false;
  /// WriterOptions::layout as text: "auto", "files" or "packed" (packed needs video.gop 1).
  std::string layout = "auto";
  std::string overwrite_option;  ///< named by the refusal of an existing database (WriterOptions)
  int threads = 0;              ///< streams encoded in parallel (0 = hardware concurrency)
  std::string title = "synthetic database";
  std::string command_line;     ///< recorded in the provenance
  /// Cameras on an nx x ny x nz lattice inside the domain instead of the sphere (all > 0 to use it):
  /// camera i + nx·(j + ny·k) at the cell centre (i, j, k) of the domain [−1, 1]³, looking +y with +z up,
  /// and the world-axis graph of camera/volume_rigs.hpp (right/left = ±x, in/out = ±y, up/down = ±z).
  /// `cameras` is ignored then.
  std::array<int, 3> lattice{0, 0, 0};
  /// Camera shells of the sphere (issue 43: Z / X in key tests): `cameras` per shell, shell s at radius
  /// 3 / (1 + s/2) (0 = outermost), camera id s·cameras + c, graph in/out = same c one shell closer /
  /// farther. 1 with a lattice.
  int shells = 1;
  /// Value counts of the parameter axes ("isovalue", "opacity", "window", "blend"), the first varying
  /// fastest over the tasks; empty = one "isovalue" axis of `tasks` values. Non-empty replaces `tasks`
  /// by the product (issue 43: A / Shift+A / PageUp in key tests need several axes).
  std::vector<int> axes;
  /// Recorded as rig parameter "projection" when not "perspective" (frames are stamped all the same).
  std::string projection = "perspective";
};

/// The manifest of a synthetic database: cameras on a Fibonacci sphere (radius 3, looking at the
/// origin, labelled with latitude/longitude; more shells inside it with `shells`), a ring navigation
/// graph per shell (left/right = previous/next camera, in/out = the next shell), tasks on one
/// "isovalue" axis or on `axes`, times 0.1 s apart. Throws Error on non-positive counts.
Manifest synthetic_manifest(const SyntheticOptions& options);

/// Frame `frame` of stream (camera, task): coloured background, a disc moving with time and camera,
/// and the frame stamp in the top-left corner. RGBA.
Image synthetic_frame(int camera, int task, int frame, int width, int height);
/// Same, drawn into an existing image of the right size (no allocation; for hot loops).
void draw_synthetic_frame(Image& image, int camera, int task, int frame);

/// Writes the database (every stream in parallel, each movie closed as soon as it is complete, so
/// memory stays bounded by the number of threads). progress(done_streams, total) is called from one
/// thread now and then. Throws like DatabaseWriter.
void write_synthetic_database(const std::filesystem::path& dir, const SyntheticOptions& options,
                              const std::function<void(std::int64_t, std::int64_t)>& progress = {});

}  // namespace panoptes::store
