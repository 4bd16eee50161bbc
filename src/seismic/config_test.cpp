// TOML configuration: every section parses; unknown keys and wrong types are errors naming the key.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "seismic/config_toml.hpp"

using namespace panoptes::seismic;

namespace {
const char* kValid = R"(
[grid]
nx = 30
ny = 30
nz = 25
h = 50.0
[time]
steps = 10
record_every = 2
[medium]
type = "layered"
[[medium.layer]]
top = 0
rho = 2000
vp = 2000
vs = 1100
qp = 100
qs = 50
[[medium.layer]]
top = 300.0
rho = 2500
vp = 4000
vs = 2300
[boundary]
pml_cells = 8
[[source]]
type = "double_couple"
position = [700, 700, 400]
strike = 30
dip = 60
rake = 90
m0 = 1e15
stf = "ricker"
frequency = 2.0
[[source]]
type = "force"
position = [700, 700, 0]
force = [0, 0, 1e9]
stf = "kupper"
duration = 0.5
[[receiver]]
name = "a"
position = [800, 700, 0]
[[receiver_line]]
name = "line"
start = [500, 700, 0]
end = [1000, 700, 0]
count = 3
[output]
directory = "out"
)";

std::string error_of(const std::string& text) {
  try {
    parse_run_config(text, "test.toml", ".");
  } catch (const panoptes::Error& e) {
    return e.what();
  }
  return "";
}

std::string replace(std::string s, const std::string& a, const std::string& b) {
  const auto p = s.find(a);
  EXPECT_NE(p, std::string::npos) << a;
  return s.replace(p, a.size(), b);
}
}  // namespace

TEST(SeismicConfig, ParsesEverySection) {
  const auto rc = parse_run_config(kValid, "test.toml", ".");
  EXPECT_EQ(rc.solver.grid.nx, 30);
  EXPECT_EQ(rc.solver.medium.layers.size(), 2u);
  EXPECT_EQ(rc.solver.medium.layers[0].qs, 50);
  EXPECT_TRUE(std::isinf(rc.solver.medium.layers[1].qp));
  ASSERT_EQ(rc.solver.sources.size(), 2u);
  EXPECT_NEAR(rc.solver.sources[0].moment[2], 1e15 * std::sin(120 * M_PI / 180), 1e3);  // thrust: Mzz = M0 sin 2δ
  EXPECT_EQ(rc.solver.sources[1].stf.kind, SourceTimeFunction::Kind::kupper);
  ASSERT_EQ(rc.solver.receivers.size(), 4u);
  EXPECT_EQ(rc.solver.receivers[3].name, "line_002");
  EXPECT_DOUBLE_EQ(rc.solver.receivers[2].position[0], 750);
  EXPECT_EQ(rc.output_dir, "out");
  EXPECT_EQ(rc.solver.record_every, 2);
}

TEST(SeismicConfig, ErrorsNameTheKey) {
  EXPECT_NE(error_of(replace(kValid, "nx = 30", "nx = 30\nnxx = 3")).find("grid.nxx: unknown key"), std::string::npos);
  EXPECT_NE(error_of(replace(kValid, "h = 50.0", "h = \"50\"")).find("grid.h: expected a number"), std::string::npos);
  EXPECT_NE(error_of(replace(kValid, "steps = 10", "steps = 1.5")).find("time.steps: expected an integer"),
            std::string::npos);
  EXPECT_NE(error_of(replace(kValid, "stf = \"kupper\"", "stf = \"boxcar\"")).find("source[1].stf"), std::string::npos);
  EXPECT_NE(error_of(replace(kValid, "position = [800, 700, 0]", "position = [800, 700]")).find("receiver[0].position"),
            std::string::npos);
  EXPECT_NE(error_of(replace(kValid, "position = [800, 700, 0]", "position = [8000, 700, 0]")).find("outside"),
            std::string::npos);
  EXPECT_NE(error_of(replace(kValid, "[grid]", "[grids]")).find("grids: unknown key"), std::string::npos);
  EXPECT_NE(error_of("[grid\n").find("TOML syntax error"), std::string::npos);
  EXPECT_NE(error_of(replace(kValid, "type = \"layered\"", "type = \"fluid\"")).find("medium.type"), std::string::npos);
}
