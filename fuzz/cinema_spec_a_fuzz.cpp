// A Cinema Spec A info.json (issue #31 row 4: nested 10^5 deep it overflowed the stack; row 9: 585
// bytes expanded to 3.2 GB): parsed by the bounded reader with the product bounded as
// read_cinema_database bounds it by the files present (here 4096), then the producer recognised from
// it (cinema_python's recorded camera, Ascent's "arguments") and each camera built. A crash, a
// sanitizer report, a hang or unbounded memory is a finding; every exception is accepted.
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
    t.source = "fuzz/info.json";
    t.spec = "A";
    cinema::parse_spec_a(fuzz::as_string(data, size), t, 4096);
    if (t.values.size() > 4096) std::abort();  // the bound held
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
    e.spec = "A";
    e.columns = t.columns;
    e.info = t.info;
    e.has_info_js = size % 2 == 1;
    e.time_count = 1 + int(size % 4);
    for (const auto& a : angles) e.thetas.push_back(a.second);
    std::sort(e.thetas.begin(), e.thetas.end());
    e.thetas.erase(std::unique(e.thetas.begin(), e.thetas.end()), e.thetas.end());
    const cinema::CameraModel model = cinema::detect_producer(e, "", "");
    for (const auto& [phi, theta] : angles) {
      const cinema::ProducerCamera cam = cinema::producer_camera(model, phi, theta);
      if (!std::isfinite(cam.position.x + cam.position.y + cam.position.z)) std::abort();
    }
  } catch (const std::exception&) {
  }
  return 0;
}
