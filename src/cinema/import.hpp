#pragma once
// Cinema image database (Spec D or Spec A) -> Panoptes movie database: parameter columns become the
// time axis, the cameras (phi/theta -> directions on a sphere, navigation graph computed) and the
// tasks with their parameter axes; the images become one movie per (camera, task). Mapping:
// docs/formats.md, "Cinema databases".
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "store/manifest.hpp"
#include "video/video_settings.hpp"

namespace panoptes::cinema {

/// Options of import_cinema.
struct ImportOptions {
  /// Columns whose value combinations make the tasks (numeric ones also become parameter axes).
  /// Empty = every column except time, camera, phi, theta and FILE.
  std::vector<std::string> group_by;
  std::string title;              ///< manifest title (default: "Cinema database <name>")
  std::string command_line;       ///< recorded in the provenance
  video::VideoSettings video;     ///< encoder settings of every movie
  bool overwrite = false;
  std::string overwrite_option;  ///< named by the refusal of an existing database (store::WriterOptions)
  int threads = 0;                ///< streams encoded in parallel (0 = hardware concurrency)
  /// The phi/theta convention ("paraview", "cinema-python", "ascent", "elevation"); empty = recognise
  /// the producer (cinema/conventions.hpp) and refuse when it cannot be told.
  std::string angles;
  std::string azimuth_zero;       ///< "+x" or "-x" for angles "elevation" (empty = +x)
  /// data.csv's column holding each row's image (--image-column; empty = FILE or FILE_<ext>, the first
  /// image column when a row has two).
  std::string image_column;
};

/// How a Cinema table maps onto a Panoptes database (plan_import's result; no image read yet).
struct ImportPlan {
  store::Manifest manifest;       ///< cameras, graph, tasks, axes, times; image size filled in
  /// files[(camera * tasks + task) * frames + frame] = the image's absolute path.
  std::vector<std::filesystem::path> files;
  /// Per camera: the producer's pictures are upside down, imported turned by 180 degrees.
  std::vector<bool> rotated;
  std::string spec;               ///< "D" or "A"
  std::string producer;           ///< the recognised producer and why, for the report
  /// What was read other than at face value (one line each, naming the file, the column or value and
  /// the option that changes it): a second image column, rows whose FILE is not an image, columns
  /// ignored as per-image measures, a time column named timestep, latitude-style Ascent theta, a
  /// Static camera whose position was not recorded.
  std::vector<std::string> warnings;
};

/// Reads IN.cdb and plans the database: the producer's convention gives each image's camera (position,
/// view direction, up; conventions.hpp), Panoptes' own export restores its cameras, graph and tasks
/// from panoptes-cinema.json. Time and memory are linear in the table. Throws FileError/Error (naming
/// the file, the row and the value) for: an unknown phi/theta convention, or evidence naming two
/// producers (asks for --angles); a table with no PNG/JPEG row; a
/// non-numeric time, phi or theta; two rows for the same (camera, task, frame); a (camera, task,
/// frame) without an image; a FILE outside the database; a missing or unreadable image; images of
/// different sizes; a --group-by column that does not exist.
ImportPlan plan_import(const std::filesystem::path& cdb, const ImportOptions& options = {});

/// What import_cinema wrote.
struct ImportReport {
  int cameras = 0, tasks = 0, frames = 0;
  std::string spec;
  std::string producer;  ///< see ImportPlan::producer
  std::vector<std::string> warnings;  ///< see ImportPlan::warnings
};

/// plan_import, then writes the movie database to `out` (DatabaseWriter; refuses an existing database
/// without overwrite). progress(done, total) in images, from one thread.
ImportReport import_cinema(const std::filesystem::path& cdb, const std::filesystem::path& out,
                           const ImportOptions& options = {},
                           const std::function<void(std::int64_t, std::int64_t)>& progress = {});

}  // namespace panoptes::cinema
