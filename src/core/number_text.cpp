#include "core/number_text.hpp"

#include <sstream>

namespace panoptes {

std::string number_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace panoptes
