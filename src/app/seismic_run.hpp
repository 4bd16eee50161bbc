#pragma once
// The seismic solver with in-situ visualization, shared by `panoptes run` and `panoptes demo`.
#include <string>

namespace panoptes::app {

/// Options of a seismic in-situ run.
struct SeismicRunOptions {
  std::string out;  ///< overrides [output] dir when not empty
  bool overwrite = false;  ///< [output] mode = "overwrite"
  bool resume = false;     ///< [output] mode = "resume"
  bool quiet = false;
  std::string command_line;
  bool force = false;  ///< start even when the memory estimate exceeds what a rank has available
  std::string overhead_note;  ///< printed under the in-situ overhead line (the demo explains its ratio)
  /// What the refusal of an existing database advises (the command's own options); empty: run's.
  std::string existing_database_advice;
};

/// Runs the solver with in-situ visualization from TOML text (defined in cmd_run.cpp).
void run_seismic_insitu(const std::string& text, const std::string& source, const std::string& base_dir,
                        const SeismicRunOptions& options);

}  // namespace panoptes::app
