#include "core/log.hpp"

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <string>

namespace panoptes::log {
namespace {
Level initial_level() {
  const char* env = std::getenv("PANOPTES_LOG");
  if (!env) return Level::info;
  const std::string s(env);
  if (s == "debug") return Level::debug;
  if (s == "warn") return Level::warn;
  if (s == "error") return Level::error;
  if (s == "off") return Level::off;
  return Level::info;
}
std::atomic<Level> g_level{initial_level()};
std::mutex g_mutex;
}  // namespace

void set_level(Level l) { g_level = l; }
Level level() { return g_level; }

void write(Level l, std::string_view message) {
  if (l < g_level.load()) return;
  static const char* names[] = {"debug", "info", "warning", "error", ""};
  std::lock_guard lock(g_mutex);
  std::fprintf(stderr, "panoptes: %s: %.*s\n", names[int(l)], int(message.size()), message.data());
}

}  // namespace panoptes::log
