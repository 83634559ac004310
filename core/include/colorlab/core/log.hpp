#pragma once
// Logging to stderr with sd-daemon "<N>" priority prefixes: journald turns them into
// priorities under systemd, and a terminal still reads them fine.
#include <string_view>

namespace colorlab::log {

enum class Level {
  error = 3,
  warning = 4,
  notice = 5,
  info = 6,
  debug = 7
};

void set_level(Level max_level);
void write(Level level, std::string_view component, std::string_view message);

inline void error(std::string_view c, std::string_view m) { write(Level::error, c, m); }
inline void warning(std::string_view c, std::string_view m) { write(Level::warning, c, m); }
inline void info(std::string_view c, std::string_view m) { write(Level::info, c, m); }
inline void debug(std::string_view c, std::string_view m) { write(Level::debug, c, m); }

}  // namespace colorlab::log
