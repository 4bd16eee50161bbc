#pragma once
// The task plan: what a session renders, built once from the user's words (the TOML [[task]] tables,
// or `panoptes render`'s --task shorthand, which means the same tables). It holds the renderer's task
// list, how each window or isovalue follows the per-field reference, the parameter axes of sweeps and
// the manifest's task entries — one vocabulary and one manifest wording for every door (issue 30).
// The task kinds are render::TaskKind; this file is the only insitu file that maps a kind's TOML keys,
// shorthand and manifest entry, so a new kind touches render/ plus task_plan.cpp (docs/extending.md).
#include <string>
#include <vector>

#include "insitu/config.hpp"
#include "render/renderer.hpp"
#include "store/manifest.hpp"

namespace panoptes::toml_keys {
struct Source;
}

namespace panoptes::insitu {

/// Reads one [[task]] table (the `index`-th, for messages): `type` is a render::TaskKind word
/// (render::task_kind_words()) or "volume2" (a volume of two fields); only the kind's keys are
/// accepted. Throws FileError naming `task[index].KEY` and what was expected.
TaskConfig parse_task_table(const toml_keys::Source& source, const toml::table& table, std::size_t index);

/// How many tasks `task` expands to (one per window, isovalue or slice position of a sweep).
std::size_t planned_task_count(const TaskConfig& task);

/// One rendered task: the renderer's spec (reference 1) and how its window / isovalue follow the
/// reference of the field it reads, with the manifest entry that describes it.
struct PlannedTask {
  render::TaskSpec spec;
  bool relative = false;      ///< window in multiples of the reference of spec.field
  bool relative2 = false;     ///< volume2: second window in multiples of the reference of spec.field2
  bool iso_relative = false;  ///< isovalue = iso_fraction x the reference of spec.field
  double iso_fraction = 0;
  /// volume2: both windows follow one reference, the larger of the two fields' (issue 41), so a
  /// field far weaker than the other stays dark instead of being stretched to look as strong.
  bool shared = false;
  store::TaskEntry entry;
};

/// The tasks of a session, in manifest order (a sweep gives one task per value, on its own axis).
class TaskPlan {
 public:
  TaskPlan() = default;
  /// Builds the plan of `tasks` on `grid` (slice positions are fractions of its domain); throws
  /// panoptes::Error naming the task when two tasks share a name.
  TaskPlan(const std::vector<TaskConfig>& tasks, const render::GridGeometry& grid);

  const std::vector<PlannedTask>& tasks() const { return tasks_; }
  std::size_t size() const { return tasks_.size(); }
  /// The sweeps' axes, for the manifest.
  const std::vector<store::ParameterAxis>& axes() const { return axes_; }
  /// Names of the fields the tasks read, in first-use order (TaskSpec::field indexes this list).
  const std::vector<std::string>& field_names() const { return field_names_; }
  /// Decides, for every two-field task, whether its fields share one reference: with
  /// ScaleSharing::units when their units (`field_units`, by field name) agree or are not given.
  /// Records the choice in the task's manifest parameters ("scale": "shared" / "own").
  void share_scales(const std::map<std::string, std::string>& field_units, ScaleSharing sharing);
  /// The specs of one snapshot: relative windows and isovalues resolved against `references`
  /// (one per field_names() entry). `specs` is resized to size().
  void resolve(const std::vector<double>& references, std::vector<render::TaskSpec>& specs) const;

 private:
  std::vector<PlannedTask> tasks_;
  std::vector<store::ParameterAxis> axes_;
  std::vector<std::string> field_names_;
};

/// `panoptes render`'s --task shorthand, as the [[task]] table it stands for (reading `field`):
///   volume:PRESET           name = TEXT, type = "volume", preset, relative window [0, 1]
///                           ([-1, 1] for "diverging")
///   volume:PRESET:LO:HI     the same with relative = false, window = [LO, HI]
///   iso:VALUE               type = "isosurface", isovalue = VALUE (absolute)
///   slice:x|y|z:F[:PRESET[:LO:HI]]  type = "slice", axis, position = F, preset (default "diverging"),
///                           relative window [-1, 1], or absolute [LO, HI]
///   mip:PRESET[:LO:HI]      type = "mip", preset, the window as volume's
/// Throws panoptes::Error naming `--task`, the text and the expected syntax.
TaskConfig parse_task_shorthand(const std::string& text, const std::string& field);

/// A list of shorthands as [[task]] tables. Several iso:VALUE form one isovalue sweep (task "iso",
/// tasks "iso VALUE", axis "isovalue", placed where the first one was) so the player steps through
/// them; a name given twice throws.
std::vector<TaskConfig> tasks_from_shorthand(const std::vector<std::string>& texts, const std::string& field);

/// The TOML [[task]] table of `task` (what a shorthand means; `panoptes render --print-tasks`).
std::string task_table_toml(const TaskConfig& task);

/// Every kind's --task shorthand, for help and errors: "volume:PRESET[:LO:HI], iso:VALUE, … or mip:…".
std::string task_shorthand_syntax();
/// The [[task]] section of the configuration help (config_keys_help()): every kind's keys.
std::string task_tables_help();

}  // namespace panoptes::insitu
