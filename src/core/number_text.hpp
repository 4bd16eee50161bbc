#pragma once
// A number as messages and manifest notes show it.
#include <string>

namespace panoptes {

/// `v` as `std::ostream` writes it by default (6 significant digits, no trailing zeros): "0.25", "1e+18".
std::string number_text(double v);

}  // namespace panoptes
