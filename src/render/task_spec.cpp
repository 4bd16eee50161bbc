#include "render/task_spec.hpp"

#include <utility>

#include "core/error.hpp"

namespace panoptes::render {

TaskSpec TaskSpec::volume(int field, TransferFunction tf, ValueWindow window, double reference) {
  TaskSpec t;
  t.kind = TaskKind::volume;
  t.field = field;
  t.tf = std::move(tf);
  t.window = window;
  t.reference = reference;
  return t;
}

TaskSpec TaskSpec::volume2(int field, TransferFunction tf, ValueWindow window, int field2, TransferFunction tf2,
                           ValueWindow window2, double reference, double reference2) {
  TaskSpec t = volume(field, std::move(tf), window, reference);
  t.field2 = field2;
  t.tf2 = std::move(tf2);
  t.window2 = window2;
  t.reference2 = reference2;
  return t;
}

TaskSpec TaskSpec::isosurface(int field, float isovalue, Rgb colour) {
  TaskSpec t;
  t.kind = TaskKind::isosurface;
  t.field = field;
  t.isovalue = isovalue;
  t.surface_colour = colour;
  return t;
}

TaskSpec TaskSpec::slice(int field, int axis, double position, TransferFunction colour_map, ValueWindow window,
                         double reference) {
  TaskSpec t;
  t.kind = TaskKind::slice;
  t.field = field;
  t.slice_axis = axis;
  t.slice_position = position;
  t.tf = std::move(colour_map);
  t.window = window;
  t.reference = reference;
  return t;
}

const char* to_string(TaskKind kind) {
  switch (kind) {
    case TaskKind::volume: return "volume";
    case TaskKind::isosurface: return "isosurface";
    case TaskKind::slice: return "slice";
  }
  return "?";
}

TaskKind parse_task_kind(std::string_view text) {
  for (TaskKind k : {TaskKind::volume, TaskKind::isosurface, TaskKind::slice})
    if (text == to_string(k)) return k;
  throw Error("render: task kind \"" + std::string(text) + "\"; expected volume, isosurface or slice");
}

}  // namespace panoptes::render
