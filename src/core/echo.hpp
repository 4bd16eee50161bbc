#pragma once
// Values from a stranger's file, quoted in an error message: a 1 MB task name or a key full of
// control characters must not become a 1 MB or multi-line error line. Every message that repeats a
// value it did not make goes through echo().
#include <cstddef>
#include <string>
#include <string_view>

namespace panoptes {

/// Longest part of a value echo() repeats, in bytes.
inline constexpr std::size_t kEchoMaxBytes = 80;

/// `value` as it may appear in a one-line message: at most max_bytes of it (cut at a UTF-8
/// character boundary, then "... (N bytes)"), control characters and backslashes escaped as \n, \t,
/// \\ or \xHH so the message stays one line.
std::string echo(std::string_view value, std::size_t max_bytes = kEchoMaxBytes);

}  // namespace panoptes
