#pragma once
// What one image of a march shows: the task kinds and their parameters (TaskSpec), apart from the
// renderer's interface. The march compiles a task list into its own plan (march_plan.hpp); a new
// kind starts here (docs/extending.md).
#include <array>
#include <string>
#include <string_view>

#include "render/transfer_function.hpp"

namespace panoptes::render {

/// What one image shows.
enum class TaskKind {
  volume,      ///< emission–absorption volume rendering of one field, or two fields mixed per sample
  isosurface,  ///< the first crossing of one isovalue, lit (headlight, Lambert + specular)
  slice,       ///< an axis-aligned plane coloured by a colour map
  mip,         ///< maximum-intensity projection: the colour map at the largest value along the ray, opaque
};

/// Every kind, in the order of their words: the one list that loops over kinds (tests, messages,
/// parse_task_kind()) read, so a kind added to the enum and here is tested and named everywhere.
inline constexpr std::array kTaskKinds = {TaskKind::volume, TaskKind::isosurface, TaskKind::slice, TaskKind::mip};

/// How the partial images of one (camera, task) from several bricks or ranks join into one image.
enum class Blend {
  /// Front-to-back "over" on premultiplied colour, partials ordered by their entry depth
  /// (emission–absorption along the ray: volume, isosurface, slice).
  over,
  /// The partial with the largest maximum wins whole (maximum-intensity projection). Such a
  /// kind's partials are opaque where their ray has a sample in the brick, and their `depth` holds
  /// max_key_depth() of the maximum instead of an entry depth (PartialImage).
  max,
};

/// The blend of a kind: the one place that says how its partial images join (compositing in
/// partial_image.hpp and the in-situ session's join of ranks follow it; docs/extending.md).
Blend blend_of(TaskKind kind);

/// One visualization task (one image per camera). Fields are indices into the `fields` span of
/// render_brick(). Windows may be relative; `reference` / `reference2` resolve them (see
/// ValueWindow). Build with the named constructors.
struct TaskSpec {
  TaskKind kind = TaskKind::volume;
  int field = 0;
  TransferFunction tf;  ///< volume: colour + extinction; slice: colour map
  ValueWindow window;
  double reference = 1;
  int field2 = -1;  ///< volume only: second field, composited with the first at every sample
  TransferFunction tf2;
  ValueWindow window2;
  double reference2 = 1;
  float isovalue = 0;
  Rgb surface_colour{0.85f, 0.85f, 0.85f};
  int slice_axis = 2;         ///< 0 = x, 1 = y, 2 = z
  double slice_position = 0;  ///< world coordinate of the plane along slice_axis
  float slice_opacity = 1;  ///< slice only

  static TaskSpec volume(int field, TransferFunction tf, ValueWindow window, double reference = 1);
  /// Two fields in one image (the paper's p-wave orange + s-wave green): per sample the extinctions
  /// add and the colours mix in proportion to them.
  static TaskSpec volume2(int field, TransferFunction tf, ValueWindow window, int field2, TransferFunction tf2,
                          ValueWindow window2, double reference = 1, double reference2 = 1);
  static TaskSpec isosurface(int field, float isovalue, Rgb colour = {0.85f, 0.85f, 0.85f});
  static TaskSpec slice(int field, int axis, double position, TransferFunction colour_map, ValueWindow window,
                        double reference = 1);
  /// Maximum-intensity projection of `field`: per pixel the colour map (`colour_map`'s colours; its
  /// opacity is not used) at the largest value of the window's coordinate along the ray — of |v| for
  /// an absolute-value map — clamped to the window; opaque where the ray crosses the domain.
  static TaskSpec mip(int field, TransferFunction colour_map, ValueWindow window, double reference = 1);
};

/// The kind's word in task descriptions and manifests: "volume", "isosurface", "slice", "mip".
const char* to_string(TaskKind kind);
/// Parses the words of to_string(); throws panoptes::Error naming the text and the accepted words.
TaskKind parse_task_kind(std::string_view text);
/// The words of kTaskKinds for messages and help: "volume, isosurface, slice or mip"; a non-empty
/// `after_volume` (the TOML's "volume2") is listed right after "volume".
std::string task_kind_words(std::string_view after_volume = "");

}  // namespace panoptes::render
