#include "render/task_spec.hpp"

#include <utility>
#include <vector>

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

TaskSpec TaskSpec::mip(int field, TransferFunction colour_map, ValueWindow window, double reference) {
  TaskSpec t;
  t.kind = TaskKind::mip;
  t.field = field;
  t.tf = std::move(colour_map);
  t.window = window;
  t.reference = reference;
  return t;
}

Blend blend_of(TaskKind kind) {
  switch (kind) {
    case TaskKind::volume:
    case TaskKind::isosurface:
    case TaskKind::slice: return Blend::over;
    // A maximum does not depend on the order of the samples: any brick may hold it, and the one
    // that does decides the pixel alone (over in depth order would let the front brick's win).
    case TaskKind::mip: return Blend::max;
  }
  return Blend::over;
}

const char* to_string(TaskKind kind) {
  switch (kind) {
    case TaskKind::volume: return "volume";
    case TaskKind::isosurface: return "isosurface";
    case TaskKind::slice: return "slice";
    case TaskKind::mip: return "mip";
  }
  return "?";
}

std::string task_kind_words(std::string_view after_volume) {
  std::vector<std::string> words;
  for (TaskKind k : kTaskKinds) {
    words.emplace_back(to_string(k));
    if (k == TaskKind::volume && !after_volume.empty()) words.emplace_back(after_volume);
  }
  std::string s;
  for (std::size_t i = 0; i < words.size(); ++i)
    s += (i == 0 ? "" : i + 1 == words.size() ? " or " : ", ") + words[i];
  return s;
}

TaskKind parse_task_kind(std::string_view text) {
  for (TaskKind k : kTaskKinds)
    if (text == to_string(k)) return k;
  throw Error("render: task kind \"" + std::string(text) + "\"; expected " + task_kind_words());
}

}  // namespace panoptes::render
