#include "player/trace.hpp"

#include <nlohmann/json.hpp>

#include "core/error.hpp"
#include "player/controls.hpp"
#include "player/headless.hpp"

namespace panoptes::player {

TraceStep trace_step(int step, const ScriptCommand& c, const Engine& engine, const Controls& controls,
                     std::string refusal) {
  TraceStep s;
  s.step = step;
  s.line = c.line;
  s.command = describe(c);
  s.selection = engine.selection();
  s.look = controls.look();
  s.axis = engine.active_axis();
  const auto& cameras = engine.manifest().cameras;
  if (s.selection.camera >= 0 && std::size_t(s.selection.camera) < cameras.size())
    s.shell = cameras[std::size_t(s.selection.camera)].labels.shell;
  s.refusal = std::move(refusal);
  return s;
}

std::string to_json_line(const TraceStep& s) {
  nlohmann::ordered_json j = {{"step", s.step},
                              {"line", s.line},
                              {"command", s.command},
                              {"camera", s.selection.camera},
                              {"task", s.selection.task},
                              {"frame", s.selection.frame},
                              {"axis", s.axis},
                              {"shell", s.shell},
                              {"look", {s.look.yaw_deg, s.look.pitch_deg, s.look.fov_deg}}};
  if (!s.refusal.empty()) j["refusal"] = s.refusal;
  return j.dump();
}

TraceWriter::TraceWriter(const std::filesystem::path& path) : path_(path), out_(path) {
  if (!out_) throw FileError(path.string(), "cannot create the trace file");
}

void TraceWriter::write(const TraceStep& step) {
  out_ << to_json_line(step) << '\n';
  out_.flush();
  if (!out_) throw FileError(path_.string(), "cannot write the trace file");
}

}  // namespace panoptes::player
