#pragma once
// Minimal leveled logging to stderr; quiet by default in tests.
#include <string_view>

namespace panoptes::log {

enum class Level { debug = 0, info = 1, warn = 2, error = 3, off = 4 };

/// Sets the lowest level printed (default: info; PANOPTES_LOG=debug|info|warn|error|off overrides).
void set_level(Level level);
Level level();
void write(Level level, std::string_view message);

inline void debug(std::string_view m) { write(Level::debug, m); }
inline void info(std::string_view m) { write(Level::info, m); }
inline void warn(std::string_view m) { write(Level::warn, m); }
inline void error(std::string_view m) { write(Level::error, m); }

}  // namespace panoptes::log
