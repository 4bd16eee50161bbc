// TOML configuration: every section parses; unknown keys and wrong types are errors naming the key.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "core/error.hpp"
#include "seismic/config_toml.hpp"
#include "seismic/resources.hpp"

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

// Issue 15: absurd values are refused before the run, naming the key, instead of being narrowed,
// accepted or ending in std::bad_alloc.
TEST(SeismicConfig, IntegersAreRangeCheckedBeforeNarrowing) {
  // 4294967336 = 2^32 + 40 would run as nx = 40 if narrowed to int unchecked.
  EXPECT_NE(error_of(replace(kValid, "nx = 30", "nx = 4294967336"))
                .find("grid.nx: 4294967336 is out of range (expected an integer in 1 .. 1048576)"),
            std::string::npos);
  EXPECT_NE(error_of(replace(kValid, "steps = 10", "steps = 9223372036854775807")).find("time.steps: 9223372036854775807 is out of range"),
            std::string::npos);
  EXPECT_NE(error_of(replace(kValid, "steps = 10", "steps = 0")).find("time.steps: 0 is out of range"), std::string::npos);
  EXPECT_NE(error_of(replace(kValid, "pml_cells = 8", "pml_cells = 4294967304")).find("boundary.pml_cells"),
            std::string::npos);
}

TEST(SeismicConfig, LayersMustStartAtTheSurfaceAndGoDown) {
  const std::string above = replace(kValid, "top = 0\n", "top = -500\n");
  EXPECT_NE(error_of(above).find("medium.layer[0].top = -500"), std::string::npos) << error_of(above);
  EXPECT_NE(error_of(above).find("must start at the surface"), std::string::npos);
  const std::string order = replace(kValid, "top = 300.0", "top = 0");
  EXPECT_NE(error_of(order).find("medium.layer[1].top = 0"), std::string::npos) << error_of(order);
  EXPECT_NE(error_of(order).find("from the surface down"), std::string::npos);
}

TEST(SeismicConfig, GridsBeyondTheSolversIndexRangeAreRefused) {
  std::string big = replace(replace(kValid, "nx = 30", "nx = 100000"), "ny = 30", "ny = 100000");
  EXPECT_NE(error_of(big).find("is too large"), std::string::npos) << error_of(big);
}

TEST(SeismicConfig, ManyReceiversValidateQuickly) {
  // Receiver names used to be compared pairwise: 3 lines of 10^5 took minutes.
  std::string text = kValid;
  for (int l = 0; l < 3; ++l)
    text += "[[receiver_line]]\nname = \"l" + std::to_string(l) +
            "\"\nstart = [500, 500, 0]\nend = [900, 900, 0]\ncount = 100000\n";
  const auto t0 = std::chrono::steady_clock::now();
  const RunConfig rc = parse_run_config(text, "test.toml", ".");
  EXPECT_GE(rc.solver.receivers.size(), 300000u);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
}

TEST(SeismicResources, EstimateCountsTheArraysAndTheTraces) {
  const RunConfig rc = parse_run_config(kValid, "test.toml", ".");
  SolverConfig c = rc.solver;
  c.grid = {2000, 2000, 2000, 10.0};
  // 2000^3 nodes x (9 wavefield + 2 derived + 18 memory variables floats) alone is ~0.9 TB.
  const double big = estimate_solver_memory(c, 1).total();
  EXPECT_GT(big, 8e11);
  EXPECT_LT(estimate_solver_memory(c, 4).total(), big / 3.5);  // z-slabs split it over ranks
  c = rc.solver;
  c.steps = 2147483647;
  c.record_every = 1;
  // The receiver traces are reserved for every step: 8 bytes x (1 + 3 x receivers) x 2^31.
  EXPECT_GT(estimate_solver_memory(c, 1).total(), 1.7e10);
}
