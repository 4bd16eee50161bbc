#pragma once
// Panoptes database -> Cinema Spec D image database, so Cinema viewers (cinema_explorer, pycinema)
// open Panoptes output. Mapping: docs/formats.md, "Cinema databases".
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/image.hpp"

namespace panoptes::cinema {

/// Options of export_cinema.
struct ExportOptions {
  std::vector<int> frames;      ///< frames to export (empty = all complete frames), in this order
  std::string format = "png";   ///< "png" (lossless copy of the decoded frame) or "jpg"
  int jpeg_quality = 95;
  bool overwrite = false;       ///< replace an existing Cinema database (its data.csv and image/ tree)
  int threads = 0;              ///< streams decoded in parallel (0 = hardware concurrency)
  /// Called on every image before it is written (e.g. to draw its colour legend: export-cinema
  /// --legend); from several threads at once, so it must not share mutable state.
  std::function<void(Image& image, int camera, int task, int frame)> decorate;
};

/// What export_cinema wrote.
struct ExportReport {
  std::int64_t images = 0;
  std::int64_t bytes = 0;
};

/// Writes OUT.cdb: data.csv, image/c{camera}/t{task}_f{frame}.{png|jpg} (one image per camera, task
/// and frame, decoded as the player shows it) and panoptes-cinema.json (the manifest: cameras, shells,
/// graph, rig, tasks, axes, so import-cinema restores them exactly). data.csv's numeric columns
/// identify each image exactly once, so Cinema viewers (Cinema:View, Cinema:Explorer: one slider per
/// numeric column) reach every image: time; phi and theta (and shell with several shells) when the
/// cameras form that grid, else camera; the parameter axes when the tasks form their grid, else task
/// (the task id; task_name beside it when no name looks like a number). Numbers are the shortest
/// exact decimals (format_value). Every movie is checked before anything is created, and the
/// database is written into a temporary directory beside OUT and moved into place at the end: a
/// failed export leaves nothing behind. Throws FileError if `db_dir` is not a database, a movie is
/// missing, `out` exists and holds something else than a Cinema database (or one without
/// overwrite), or writing fails; Error for a frame out of range or an unknown format.
/// progress(done, total) in images, from one thread.
ExportReport export_cinema(const std::filesystem::path& db_dir, const std::filesystem::path& out,
                           const ExportOptions& options = {},
                           const std::function<void(std::int64_t, std::int64_t)>& progress = {});

/// Parses a frame list "0,3,10:20,30:60:5" (Python-style start:stop[:step], stop exclusive) against
/// `frame_count`. Throws Error naming the bad item.
std::vector<int> parse_frame_list(const std::string& text, int frame_count);

}  // namespace panoptes::cinema
