#include "player/trace.hpp"

#include <nlohmann/json.hpp>

#include "core/error.hpp"

namespace panoptes::player {

std::string to_json_line(const TraceStep& s) {
  const nlohmann::ordered_json j = {{"step", s.step},
                                    {"line", s.line},
                                    {"command", s.command},
                                    {"camera", s.selection.camera},
                                    {"task", s.selection.task},
                                    {"frame", s.selection.frame},
                                    {"look", {s.look.yaw_deg, s.look.pitch_deg, s.look.fov_deg}}};
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
