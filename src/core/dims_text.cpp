#include "core/dims_text.hpp"

namespace panoptes {

// By hand rather than with <regex>: std::regex cost ~5 CPU-s of compiling in every unit that used it
// for these patterns, on a first build a new user waits for (issue 34).
std::optional<std::vector<int>> parse_dims_text(std::string_view text, int parts, int max_digits) {
  std::vector<int> out;
  std::size_t i = 0;
  for (int p = 0; p < parts; ++p) {
    if (p > 0) {
      if (i >= text.size() || text[i] != 'x') return std::nullopt;
      ++i;
    }
    int value = 0, digits = 0;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9') {
      if (++digits > max_digits) return std::nullopt;
      value = value * 10 + (text[i] - '0');
      ++i;
    }
    if (digits == 0) return std::nullopt;
    out.push_back(value);
  }
  if (i != text.size()) return std::nullopt;
  return out;
}

}  // namespace panoptes
