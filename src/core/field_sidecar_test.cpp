#include "core/field_sidecar.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "core/error.hpp"

namespace panoptes {
namespace {

FieldSidecar seismic_snapshot() {
  FieldSidecar s;
  s.data = "phi_p_000020.npy";
  s.field = "phi_p";
  s.field_units = "1/s";
  s.dims = {24, 48, 16};
  s.origin = Vec3(0, 0, 0);
  s.spacing = {1066.6667, 1066.6667, 1066.6667};
  s.length_units = "m";
  s.up_axis = "z_down";
  s.time = 0.1 + 0.2;  // not a short decimal: must survive the text exactly
  s.time_units = "s";
  s.step = 20;
  return s;
}

// The message of the FileError parse_field_sidecar throws for `text` ("" when it accepts it).
std::string error_of(const std::string& text) {
  try {
    parse_field_sidecar(text, "snap/phi_p_000020.json");
  } catch (const FileError& e) {
    return e.what();
  }
  return "";
}

TEST(FieldSidecar, RoundTripKeepsEveryValue) {
  const FieldSidecar s = seismic_snapshot();
  const std::string text = field_sidecar_json(s);
  const FieldSidecar r = parse_field_sidecar(text, "x.json");
  EXPECT_EQ(r.data, s.data);
  EXPECT_EQ(r.field, s.field);
  EXPECT_EQ(r.field_units, s.field_units);
  EXPECT_EQ(r.dims, s.dims);
  EXPECT_EQ(r.origin, s.origin);
  EXPECT_EQ(r.spacing, s.spacing);
  EXPECT_EQ(r.length_units, s.length_units);
  EXPECT_EQ(r.up_axis, s.up_axis);
  ASSERT_TRUE(r.time.has_value());
  EXPECT_EQ(*r.time, *s.time);  // bitwise: shortest exact decimals
  EXPECT_EQ(r.time_units, s.time_units);
  ASSERT_TRUE(r.step.has_value());
  EXPECT_EQ(*r.step, 20);
  // One key per line, readable.
  EXPECT_NE(text.find("\n  \"up_axis\": \"z_down\",\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\"format\": \"panoptes field sidecar\""), std::string::npos) << text;
}

TEST(FieldSidecar, WritesAndFindsTheSidecarBesideItsArray) {
  const auto dir = std::filesystem::temp_directory_path() / ("panoptes_sidecar_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string npy = (dir / "phi_p_000020.npy").string();
  EXPECT_EQ(field_sidecar_path(npy), (dir / "phi_p_000020.json").string());
  EXPECT_FALSE(find_field_sidecar(npy).has_value());  // none: the caller keeps its defaults
  write_field_sidecar(field_sidecar_path(npy), seismic_snapshot());
  const auto found = find_field_sidecar(npy);
  ASSERT_TRUE(found.has_value());
  EXPECT_EQ(found->up_axis, "z_down");
  EXPECT_EQ(found->dims, (std::array<int, 3>{24, 48, 16}));
  // A sidecar beside another array (copied or renamed without it) is refused, naming both files.
  std::filesystem::copy_file(field_sidecar_path(npy), dir / "phi_p_000040.json");
  try {
    find_field_sidecar((dir / "phi_p_000040.npy").string());
    ADD_FAILURE() << "a sidecar describing another array was accepted";
  } catch (const FileError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("phi_p_000040.json: data: the sidecar describes \"phi_p_000020.npy\""), std::string::npos) << m;
  }
  std::filesystem::remove_all(dir);
}

TEST(FieldSidecar, OptionalKeysMayBeLeftOut) {
  const FieldSidecar s = parse_field_sidecar(R"({"version": 1, "dims": [4, 5, 6], "spacing": [1, 2, 3], "up_axis": "z_up"})", "m.json");
  EXPECT_FALSE(s.origin.has_value());
  EXPECT_EQ(s.spacing, Vec3(1, 2, 3));
  EXPECT_FALSE(s.time.has_value());
  EXPECT_FALSE(s.step.has_value());
  EXPECT_TRUE(s.field_units.empty());
}

TEST(FieldSidecar, MalformedSidecarNamesTheFileAndTheKey) {
  const std::string good_tail = R"("dims": [4, 5, 6], "spacing": [1, 1, 1], "up_axis": "z_down")";
  EXPECT_EQ(error_of(R"({"version": 1, )" + good_tail + "}"), "");
  const std::string file = "snap/phi_p_000020.json: ";
  EXPECT_EQ(error_of(R"({"version": 1, "dims": [4, 5, 6], "up_axis": "z_down"})"),
            file + "spacing: expected an array of 3 numbers > 0, but the key is missing");
  EXPECT_EQ(error_of(R"({"version": 1, "dims": [4, 5, 6], "spacing": [1, 0, 1], "up_axis": "z_down"})"),
            file + "spacing: expected an array of 3 numbers > 0, got [1,0,1]");
  EXPECT_EQ(error_of(R"({"version": 1, "dims": [4, 5], "spacing": [1, 1, 1], "up_axis": "z_down"})"),
            file + "dims: expected an array of 3 integers >= 1 (points along x, y, z), got [4,5]");
  EXPECT_EQ(error_of(R"({"version": 1, "dims": [4, 5, 6], "spacing": [1, 1, 1], "up_axis": "down"})"),
            file + "up_axis: expected \"z_up\" or \"z_down\" (z is depth), got \"down\"");
  EXPECT_EQ(error_of(R"({"version": 1, "dims": [4, 5, 6], "spacing": [1, 1, 1]})"),
            file + "up_axis: expected a string, but the key is missing");
  EXPECT_EQ(error_of(R"({"version": 2, )" + good_tail + "}"),
            file + "version: expected the integer 1 (this build reads version 1), got 2");
  EXPECT_EQ(error_of(R"({"version": 1, "time": "soon", )" + good_tail + "}"),
            file + "time: expected a finite number, got \"soon\"");
  EXPECT_EQ(error_of(R"({"version": 1, "step": -3, )" + good_tail + "}"), file + "step: expected an integer >= 0, got -3");
  EXPECT_EQ(error_of(R"({"version": 1, "format": "vtk", )" + good_tail + "}"),
            file + "format: expected \"panoptes field sidecar\", got \"vtk\"");
  EXPECT_EQ(error_of(R"({"version": 1, "data": "../x.npy", )" + good_tail + "}"),
            file + "data: expected a file name without a directory, got \"../x.npy\"");
  EXPECT_EQ(error_of("[1, 2]"), file + "expected a JSON object (a field sidecar), got [1,2]");
  const std::string broken = error_of(R"({"version": 1, "dims": [4, 5, )");
  EXPECT_EQ(broken.rfind(file + "malformed JSON: ", 0), 0u) << broken;
}

}  // namespace
}  // namespace panoptes
