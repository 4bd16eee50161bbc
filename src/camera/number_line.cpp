#include "camera/number_line.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

#include "core/error.hpp"

namespace panoptes::camera {

std::vector<double> parse_number_line(std::string line, const std::string& path, const std::string& where) {
  if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
  for (char& ch : line)
    if (ch == ',' || ch == '\t' || ch == '\r') ch = ' ';
  std::istringstream fields(line);
  std::vector<double> v;
  std::string tok;
  while (fields >> tok) {
    double x = 0;
    const auto [end, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), x);
    if (ec != std::errc() || end != tok.data() + tok.size() || !std::isfinite(x))
      throw FileError(path, where + ": '" + tok + "' is not a number");
    v.push_back(x);
  }
  return v;
}

}  // namespace panoptes::camera
