#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "act_color/core/calibration.hpp"
#include "test_util.hpp"

using act_color::core::CalibrationError;
using act_color::core::parseCalibration;
using act_color::test::readFile;
using act_color::test::sourcePath;

namespace {

std::string contractText() { return readFile(sourcePath("test/data/contract_example.yaml")); }

std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return pos == std::string::npos ? text : text.replace(pos, from.size(), to);
}

// Message of the CalibrationError thrown for `text`, or "" if it was accepted.
std::string errorOf(const std::string& text) {
  try {
    parseCalibration(text, "cal.yaml");
  } catch (const CalibrationError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Calibration, ContractExampleLoads) {
  const auto c = act_color::test::contractCalibration();
  EXPECT_EQ(c.camera.width, 580);
  EXPECT_EQ(c.camera.height, 580);
  EXPECT_DOUBLE_EQ(c.camera.center_u, 290.0);
  EXPECT_EQ(c.camera.bearing_sign, 1);
  EXPECT_DOUBLE_EQ(c.camera.height_m, 0.75);
  EXPECT_DOUBLE_EQ(c.camera.chassis_radius_px, 42);
  ASSERT_EQ(c.camera.elevation_map.size(), 2u);
  EXPECT_DOUBLE_EQ(c.camera.elevation_map[1].second, 0.20);
  EXPECT_DOUBLE_EQ(c.field.length_m, 18.0);
  EXPECT_DOUBLE_EQ(c.field.goal_area_width_m, 3.5);
  EXPECT_DOUBLE_EQ(c.field.penalty_area_depth_m, 2.25);
  ASSERT_TRUE(c.field.penalty_mark_distance_m.has_value());
  EXPECT_DOUBLE_EQ(*c.field.penalty_mark_distance_m, 3.0);
  EXPECT_DOUBLE_EQ(c.field.goal_height_m, 1.0);
  EXPECT_EQ(c.field.yellow_goal_x_sign, 1);
}

TEST(Calibration, DefaultConfigLoads) { EXPECT_NO_THROW(act_color::test::defaultCalibration()); }

TEST(Calibration, PenaltyMarkIsOptional) {
  const auto c = parseCalibration(replaced(contractText(), "  penalty_mark_distance_m: 3.0", ""), "cal.yaml");
  EXPECT_FALSE(c.field.penalty_mark_distance_m.has_value());
}

TEST(Calibration, UnknownKeysAreRejectedByName) {
  EXPECT_NE(errorOf(contractText() + "extra: 1\n").find("cal.yaml: extra: unknown key"), std::string::npos);
  EXPECT_NE(
      errorOf(replaced(contractText(), "  height: 580", "  height: 580\n  focal: 3")).find("camera.focal: unknown key"),
      std::string::npos);
  EXPECT_NE(
      errorOf(replaced(contractText(), "{depth_m: 0.75, width_m: 3.5}", "{depth_m: 0.75, width_m: 3.5, color: 1}"))
          .find("field.goal_area.color: unknown key"),
      std::string::npos);
}

TEST(Calibration, MissingKeysAreRejectedByName) {
  EXPECT_NE(errorOf(replaced(contractText(), "  width_m: 12.0", "")).find("cal.yaml: field.width_m: missing"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "  height_m: 0.75", "")).find("camera.height_m: missing"),
            std::string::npos);
  EXPECT_NE(
      errorOf(replaced(contractText(), "{width_m: 2.0, height_m: 1.0, depth_m: 0.5}", "{width_m: 2.0, height_m: 1.0}"))
          .find("field.goal.depth_m: missing"),
      std::string::npos);
  // A misspelt key: the message names it and its place (it said only "camera.width: missing").
  const std::string misspelt = std::string("w\xc3\xad") + "dth";  // an accented i
  const std::string error = errorOf(replaced(contractText(), "  width: 580", "  " + misspelt + ": 580"));
  EXPECT_NE(error.find("camera.width: missing; is '" + misspelt + "' (line 2, column 11) meant?"), std::string::npos)
      << error;
  EXPECT_EQ(errorOf(replaced(contractText(), "  height_m: 0.75", "")).find("meant"), std::string::npos);
}

TEST(Calibration, ElevationMapMustIncreaseStrictly) {
  const std::string decreasing_r =
      replaced(contractText(), "    - [286.0, 0.20]", "    - [286.0, 0.20]\n    - [280.0, 0.25]");
  EXPECT_NE(errorOf(decreasing_r).find("camera.elevation_map[2]: r_px must increase strictly"), std::string::npos);
  const std::string decreasing_e =
      replaced(contractText(), "    - [286.0, 0.20]", "    - [200.0, 0.10]\n    - [286.0, 0.05]");
  EXPECT_NE(errorOf(decreasing_e).find("camera.elevation_map[2]: elevation_rad must increase strictly"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "    - [286.0, 0.20]\n", "")).find("camera.elevation_map"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "[286.0, 0.20]", "[286.0]")).find("camera.elevation_map[1]"),
            std::string::npos);
}

TEST(Calibration, ValuesAreRangeChecked) {
  EXPECT_NE(errorOf(replaced(contractText(), "bearing_sign: 1 ", "bearing_sign: 0 "))
                .find("camera.bearing_sign: must be 1 or -1"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "yellow_goal_x_sign: 1", "yellow_goal_x_sign: 2"))
                .find("field.yellow_goal_x_sign"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "height_m: 0.75", "height_m: -0.75")).find("camera.height_m: must be in"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "width: 580", "width: 580.5")).find("camera.width: must be an integer"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "center: [290.0, 290.0]", "center: [290.0]")).find("camera.center"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "chassis_radius_px: 42", "chassis_radius_px: 300"))
                .find("camera.chassis_radius_px"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "length_m: 18.0", "length_m: abc"))
                .find("field.length_m: must be a finite decimal number"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "goal: {width_m: 2.0", "goal: {width_m: 20.0")).find("field.goal.width_m"),
            std::string::npos);
}

TEST(Calibration, DuplicateKeysAreRejected) {
  EXPECT_NE(errorOf(replaced(contractText(), "  height: 580", "  height: 580\n  height: 581"))
                .find("camera.height: appears twice"),
            std::string::npos);
}

TEST(Calibration, MalformedYamlAndMissingFileNameTheFile) {
  EXPECT_NE(errorOf("camera: [1,\n").find("cal.yaml: not valid YAML"), std::string::npos);
  EXPECT_NE(errorOf("").find("cal.yaml"), std::string::npos);
  try {
    act_color::core::loadCalibration("/nonexistent/cal.yaml");
    FAIL() << "no error";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/cal.yaml"), std::string::npos);
  }
}

TEST(Calibration, YamlRoundTrip) {
  const auto c = act_color::test::defaultCalibration();
  const auto d = parseCalibration(act_color::core::toYaml(c), "roundtrip");
  EXPECT_EQ(act_color::core::toYaml(c), act_color::core::toYaml(d));
  EXPECT_EQ(c.camera.elevation_map, d.camera.elevation_map);
  EXPECT_EQ(c.field.penalty_mark_distance_m, d.field.penalty_mark_distance_m);
}

// Issue 12: lab fields. Penalty arcs and goals set back from the line (colored panels) are optional
// keys; a field without corner arcs has corner_arc_radius_m 0; unknown keys stay errors.
TEST(Calibration, LabFieldKeysAreOptionalAndRoundTrip) {
  const std::string lab = replaced(replaced(replaced(contractText(), "  penalty_mark_distance_m: 3.0",
                                                     "  penalty_arc: {radius_m: 1.5, center_distance_m: 2.25}"),
                                            "depth_m: 0.5}", "depth_m: 0.02, setback_m: 0.3}"),
                                   "corner_arc_radius_m: 0.75", "corner_arc_radius_m: 0");
  const auto c = parseCalibration(lab, "lab.yaml");
  ASSERT_TRUE(c.field.penalty_arc_radius_m.has_value());
  EXPECT_DOUBLE_EQ(*c.field.penalty_arc_radius_m, 1.5);
  EXPECT_DOUBLE_EQ(c.field.penalty_arc_center_m, 2.25);
  EXPECT_DOUBLE_EQ(c.field.goal_setback_m, 0.3);
  EXPECT_DOUBLE_EQ(c.field.goal_depth_m, 0.02);
  EXPECT_DOUBLE_EQ(c.field.corner_arc_radius_m, 0.0);
  const auto d = parseCalibration(act_color::core::toYaml(c), "roundtrip");
  EXPECT_EQ(act_color::core::toYaml(c), act_color::core::toYaml(d));
  EXPECT_EQ(d.field.penalty_arc_radius_m, c.field.penalty_arc_radius_m);
  EXPECT_DOUBLE_EQ(d.field.goal_setback_m, 0.3);
  // Without the keys: no arc, the goal at the line.
  const auto plain = act_color::test::contractCalibration();
  EXPECT_FALSE(plain.field.penalty_arc_radius_m.has_value());
  EXPECT_DOUBLE_EQ(plain.field.goal_setback_m, 0.0);
  EXPECT_EQ(act_color::core::toYaml(plain).find("penalty_arc"), std::string::npos);
  EXPECT_EQ(act_color::core::toYaml(plain).find("setback_m"), std::string::npos);
}

TEST(Calibration, LabFieldKeysAreChecked) {
  const std::string text = contractText();
  auto arc = [&](const std::string& value) {
    return errorOf(replaced(text, "  penalty_mark_distance_m: 3.0", "  penalty_arc: " + value));
  };
  EXPECT_EQ(arc("{radius_m: 1.5, center_distance_m: 2.25}"), "");
  EXPECT_NE(arc("{radius_m: 1.5}").find("field.penalty_arc.center_distance_m"), std::string::npos);
  EXPECT_NE(arc("{radius_m: 1.5, center_distance_m: 2.25, colour: 1}").find("field.penalty_arc.colour"),
            std::string::npos);
  EXPECT_NE(arc("{radius_m: 0, center_distance_m: 2.25}").find("field.penalty_arc.radius_m"), std::string::npos);
  // An arc that stays inside the penalty area (2.25 m deep) would never be drawn.
  EXPECT_NE(arc("{radius_m: 0.5, center_distance_m: 3.0}").find("reach out of the penalty area"), std::string::npos);
  EXPECT_NE(errorOf(replaced(text, "depth_m: 0.5}", "depth_m: 0.5, setback_m: 1.5}")).find("field.goal.setback_m"),
            std::string::npos);  // beyond the 1 m margin
  EXPECT_NE(errorOf(replaced(text, "corner_arc_radius_m: 0.75", "corner_arc_radius_m: -0.1"))
                .find("field.corner_arc_radius_m"),
            std::string::npos);
}

// Issue 12: a mirror axis off the vertical is the optional key camera.tilt (x, y, rad); a file
// without it is untilted and writes no such key.
TEST(Calibration, TiltIsOptionalCheckedAndRoundTrips) {
  const std::string text = contractText();
  auto tilted = [&](const std::string& value) {
    return replaced(text, "  height_m: 0.75", "  height_m: 0.75\n  tilt: " + value);
  };
  const auto c = parseCalibration(tilted("[0.02, -0.01]"), "cal.yaml");
  EXPECT_DOUBLE_EQ(c.camera.tilt_x_rad, 0.02);
  EXPECT_DOUBLE_EQ(c.camera.tilt_y_rad, -0.01);
  const auto d = parseCalibration(act_color::core::toYaml(c), "roundtrip");
  EXPECT_EQ(act_color::core::toYaml(c), act_color::core::toYaml(d));
  EXPECT_DOUBLE_EQ(d.camera.tilt_y_rad, -0.01);
  const auto plain = act_color::test::contractCalibration();
  EXPECT_EQ(plain.camera.tilt_x_rad, 0.0);
  EXPECT_EQ(act_color::core::toYaml(plain).find("tilt"), std::string::npos);
  EXPECT_NE(errorOf(tilted("[0.3, 0.3]")).find("camera.tilt: must be finite and at most"), std::string::npos);
  EXPECT_NE(errorOf(tilted("[0.01]")).find("camera.tilt"), std::string::npos);
  EXPECT_NE(errorOf(tilted("0.01")).find("camera.tilt"), std::string::npos);
}

// Issue 15: hostile calibration files are refused with a message, in bounded time and memory.
TEST(Calibration, NestingSizeAndSyntaxAreBoundedAndLocated) {
  // 40,000 levels of nesting (80 KB): refused at the limit, no stack overflow.
  std::string deep = "camera: " + std::string(40000, '[') + std::string(40000, ']') + "\n";
  EXPECT_NE(errorOf(deep).find("nested deeper than 16 levels"), std::string::npos) << errorOf(deep);
  std::string deep_block;
  for (int i = 0; i < 2000; ++i) deep_block += std::string(static_cast<size_t>(i), ' ') + "k:\n";
  EXPECT_NE(errorOf(deep_block).find("nested deeper"), std::string::npos) << errorOf(deep_block).substr(0, 200);
  // More than 4 MiB: refused before parsing.
  EXPECT_NE(errorOf(contractText() + "# " + std::string(5u << 20, 'x') + "\n").find("bytes, more than"),
            std::string::npos);
  // Syntax errors say where.
  const std::string bad = replaced(contractText(), "  height_m: 0.75", "  height_m: [0.75");
  EXPECT_NE(errorOf(bad).find("unclosed '['"), std::string::npos) << errorOf(bad);
  EXPECT_NE(errorOf("camera:\n  width: 1\n   height: 2\n").find("line 3, column 4: unexpected indentation"),
            std::string::npos)
      << errorOf("camera:\n  width: 1\n   height: 2\n");
  EXPECT_NE(errorOf("camera: &a {x: 1}\nfield: *a\n").find("anchors, aliases"), std::string::npos);
  EXPECT_NE(errorOf("camera:\n\twidth: 1\n").find("line 2, column 1: a tab"), std::string::npos);
}

TEST(Calibration, ByteOrderMarkAndAnyLineEndsRead) {
  // Editors on other systems save with a UTF-8 byte order mark, CR LF or (old Mac) CR alone.
  const std::string text = contractText();
  auto with_ends = [&](const std::string& end) {
    std::string out;
    for (const char c : text) out += c == '\n' ? end : std::string(1, c);
    return out;
  };
  EXPECT_EQ(errorOf("\xEF\xBB\xBF" + text), "");
  EXPECT_EQ(errorOf(with_ends("\r\n")), "");
  EXPECT_EQ(errorOf(with_ends("\r")), "");
  // A CR-only file's errors name their line as in the editor.
  const std::string bad = replaced(with_ends("\r"), "  height_m: 0.75", "  height_m: [0.75");
  const size_t line =
      static_cast<size_t>(std::count(text.begin(), text.begin() + text.find("  height_m: 0.75"), '\n')) + 1;
  EXPECT_NE(errorOf(bad).find("line " + std::to_string(line) + ","), std::string::npos) << errorOf(bad);
}

TEST(Calibration, ValuesAreReadInTheirRealType) {
  // No 32-bit wrap: 2^32 + 1 is not 1.
  EXPECT_NE(
      errorOf(replaced(contractText(), "height_m: 0.75", "height_m: 4294967297")).find("camera.height_m: must be in"),
      std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "bearing_sign: 1", "bearing_sign: 4294967295"))
                .find("camera.bearing_sign: must be 1 or -1, is '4294967295'"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "width: 580", "width: 99999999999999999999999"))
                .find("camera.width: must be an integer"),
            std::string::npos);
  // No octal: 0580 is refused, not read as something else.
  EXPECT_NE(errorOf(replaced(contractText(), "width: 580", "width: 0580")).find("camera.width: must be an integer"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "height_m: 0.75", "height_m: 0x1")).find("camera.height_m"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "height_m: 0.75", "height_m: .inf")).find("camera.height_m"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(contractText(), "height_m: 0.75", "height_m: \"0.75\"")).find("the string \"0.75\""),
            std::string::npos);
  // Flow and block styles, comments and quoted keys read alike.
  const std::string flow =
      replaced(contractText(), "  center: [290.0, 290.0]", "  \"center\": [290.0,\n     290.0]  # c");
  EXPECT_EQ(errorOf(flow), "");
}

TEST(Calibration, AnImageTooLargeOrAMapThatImagesNothingIsRefused) {
  EXPECT_NE(errorOf(replaced(replaced(contractText(), "width: 580", "width: 16384"), "height: 580", "height: 16384"))
                .find("camera.width: must be in [16, 8192]"),
            std::string::npos);
  EXPECT_NE(errorOf(replaced(replaced(contractText(), "width: 580", "width: 8000"), "height: 580", "height: 8000"))
                .find("larger than 16777216 pixels"),
            std::string::npos);
  // An elevation map beyond the image's corners: no pixel would see anything.
  std::string far = replaced(contractText(), "[42.0, -1.45]", "[1000.0, -1.45]");
  far = replaced(far, "[286.0, 0.20]", "[2000.0, 0.20]");
  EXPECT_NE(errorOf(far).find("images no pixel"), std::string::npos) << errorOf(far);
  // A map beginning 1e-7 px inside the mirror's rim: a ring no pixel centre lies in.
  std::string sliver = replaced(contractText(), "[42.0, -1.45]", "[285.9999999, -1.2]");
  sliver = replaced(sliver, "[286.0, 0.20]", "[400.0, -0.1]");
  EXPECT_NE(errorOf(sliver).find("camera.elevation_map: images the floor in 0 pixels, fewer than 3364"),
            std::string::npos)
      << errorOf(sliver);
}

TEST(Calibration, OnlyRegularFilesAreRead) {
  try {
    act_color::core::loadCalibration("/dev/zero");
    FAIL() << "no error";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
  }
}
