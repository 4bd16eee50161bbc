#include <fstream>

#include "core/error.hpp"
#include "player/engine_impl.hpp"

namespace panoptes::player {

Summary summarize(std::vector<double> values) {
  Summary s;
  s.count = values.size();
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  double sum = 0;
  for (double v : values) sum += v;
  s.mean = sum / double(values.size());
  const auto pick = [&](double q) {
    const std::size_t i = std::min(values.size() - 1, std::size_t(std::ceil(q * double(values.size()))) - (q > 0 ? 1 : 0));
    return values[i];
  };
  s.p50 = pick(0.50);
  s.p99 = pick(0.99);
  s.max = values.back();
  return s;
}

nlohmann::json to_json(const Statistics& st) {
  const auto summary = [](const std::vector<double>& v) {
    const Summary s = summarize(v);
    return nlohmann::json{{"count", s.count}, {"mean_ms", s.mean}, {"p50_ms", s.p50}, {"p99_ms", s.p99}, {"max_ms", s.max}};
  };
  std::vector<double> latencies;
  latencies.reserve(st.switches.size());
  nlohmann::json switches = nlohmann::json::array();
  for (const auto& s : st.switches) {
    latencies.push_back(s.latency_ms);
    switches.push_back({{"command", s.command},
                        {"from", {{"camera", s.from.camera}, {"task", s.from.task}, {"frame", s.from.frame}}},
                        {"to", {{"camera", s.to.camera}, {"task", s.to.task}, {"frame", s.to.frame}}},
                        {"latency_ms", s.latency_ms},
                        {"cache_hit", s.cache_hit}});
  }
  return {{"frames_shown", st.frames_shown},
          {"cache", {{"hits", st.cache_hits},
                     {"misses", st.cache_misses},
                     {"waited_for_prefetch", st.waited_for_prefetch},
                     {"evictions", st.cache_evictions},
                     {"bytes", st.cache_bytes},
                     {"capacity_bytes", st.cache_capacity}}},
          {"decodes", {{"prefetch", st.prefetch_decodes}, {"display", st.display_decodes}}},
          {"readers", {{"opened", st.readers_opened}, {"evicted", st.readers_evicted},
                       {"open", st.readers_open}, {"capacity", st.reader_capacity}}},
          {"placeholders_shown", st.placeholders_shown},
          {"decode_time", summary(st.decode_ms)},
          {"switch_latency", summary(latencies)},
          {"switches", switches}};
}

Statistics Engine::statistics() const {
  const Impl& m = *impl_;
  Statistics st;
  {
    std::lock_guard lock(m.stats_mutex);
    st = m.stats;
  }
  st.cache_bytes = m.cache.bytes();
  st.cache_capacity = m.cache.capacity();
  st.cache_evictions = m.cache.evictions();
  st.readers_open = m.pool.open();
  st.reader_capacity = m.pool.capacity();
  st.readers_opened = m.pool.opened();
  st.readers_evicted = m.pool.evicted();
  return st;
}

void Engine::reset_statistics() {
  Impl& m = *impl_;
  std::lock_guard lock(m.stats_mutex);
  m.stats = Statistics{};
  m.decode_ring = 0;
}

void Engine::write_statistics(const std::filesystem::path& path) const {
  std::ofstream out(path);
  if (!out) throw FileError(path.string(), "cannot create the statistics file");
  out << to_json(statistics()).dump(2) << '\n';
  if (!out) throw FileError(path.string(), "cannot write the statistics file");
}

}  // namespace panoptes::player
