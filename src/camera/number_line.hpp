#pragma once
// One line of a whitespace/comma-separated number file (camera files, path files).
#include <string>
#include <vector>

namespace panoptes::camera {

/// The numbers on one line of `path` ('#' starts a comment; spaces, tabs and commas separate); empty
/// for a blank or comment line. Throws FileError naming `path`, `where` (e.g. "line 3") and the token
/// that is not a finite number.
std::vector<double> parse_number_line(std::string line, const std::string& path, const std::string& where);

}  // namespace panoptes::camera
