#pragma once
// `panoptes seismic` configuration files (TOML). Every key is documented by config_keys_help();
// unknown keys, wrong types and out-of-range values are errors naming the file and the key.
#include <string>
#include <vector>

#include "seismic/config.hpp"

namespace panoptes::seismic {

/// A run as read from a TOML file: the solver configuration plus where to write results.
struct RunConfig {
  SolverConfig solver;
  std::string output_dir = "seismic_out";  ///< [output] directory (relative to the working directory)
  std::vector<std::string> snapshot_fields;  ///< [output] snapshot_fields (Solver::field_names())
  int snapshot_every = 0;                    ///< [output] snapshot_every in steps (0: only after the last step)
};

/// Parses a TOML configuration file. Relative medium-file paths are relative to the file's folder.
/// Throws panoptes::FileError naming the file and the offending key.
RunConfig load_run_config(const std::string& path);
/// Parses TOML text (source_name is used in messages; base_dir resolves relative medium files).
RunConfig parse_run_config(const std::string& text, const std::string& source_name, const std::string& base_dir);

/// Documentation of every key, printed by `panoptes seismic --help`.
const char* config_keys_help();

}  // namespace panoptes::seismic
