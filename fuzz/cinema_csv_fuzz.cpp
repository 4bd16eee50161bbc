// A Cinema Spec D data.csv (issue #31: import-cinema took a stranger's table): parsed as
// import-cinema parses it, then the producer's convention is recognised and every distinct (phi,
// theta) turned into a camera, as plan_import does before it looks at any image. A crash, a sanitizer
// report, a hang or unbounded memory is a finding; every exception is accepted.
#include <algorithm>
#include <cmath>
#include <exception>
#include <set>
#include <string>

#include "cinema/cinema_database.hpp"
#include "cinema/conventions.hpp"
#include "cinema/csv.hpp"
#include "fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace panoptes;
  try {
    cinema::CinemaTable t;
    t.source = "fuzz/data.csv";
    t.spec = "D";
    cinema::parse_spec_d(fuzz::as_string(data, size), t);
    int c_phi = -1, c_theta = -1;
    for (std::size_t c = 0; c < t.columns.size(); ++c) {
      if (t.columns[c] == "phi") c_phi = int(c);
      if (t.columns[c] == "theta") c_theta = int(c);
    }
    std::set<std::pair<double, double>> angles;
    for (const auto& row : t.values) {
      double phi = 0, theta = 0;
      if (c_phi >= 0 && !cinema::parse_number(row[std::size_t(c_phi)], phi)) return 0;
      if (c_theta >= 0 && !cinema::parse_number(row[std::size_t(c_theta)], theta)) return 0;
      angles.insert({phi, theta});
    }
    cinema::ProducerEvidence e;
    e.spec = "D";
    e.columns = t.columns;
    e.file_column = t.file_column;
    for (const auto& a : angles) e.thetas.push_back(a.second);
    std::sort(e.thetas.begin(), e.thetas.end());
    e.thetas.erase(std::unique(e.thetas.begin(), e.thetas.end()), e.thetas.end());
    const std::string angle_option = size % 3 == 0 ? "" : size % 3 == 1 ? "paraview" : "elevation";
    const cinema::CameraModel model = cinema::detect_producer(e, angle_option, "");
    for (const auto& [phi, theta] : angles) {
      const cinema::ProducerCamera cam = cinema::producer_camera(model, phi, theta);
      if (!(std::isfinite(cam.position.x) && std::isfinite(cam.up.z))) std::abort();  // finite angles give a camera
      (void)cinema::format_value(phi);
    }
  } catch (const std::exception&) {
  }
  return 0;
}
