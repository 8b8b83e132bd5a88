// MirrorCalibrator on the simulator's random cameras (sim::makeFamilyScene: mirror profiles,
// heights, image sizes, off-centre mirrors, bearing signs and offsets, struts, fields 6x4 to
// 18x12 m), where the true calibration is known: the fitted mapping against the true one over the
// floor pixels within the field. Also the NuBot import and the field presets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <tuple>

#include "act_color/core/calibration.hpp"
#include "act_color/core/mirror_calibrator.hpp"
#include "act_color/core/omni_camera_model.hpp"
#include "act_color/sim/calibrator_check.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scene_family.hpp"

namespace core = act_color::core;
namespace sim = act_color::sim;

namespace {

cv::Mat renderBgr(const sim::FamilyScene& scene) {
  const sim::Renderer renderer(scene.calibration, scene.renderer);
  cv::Mat bgr;
  cv::cvtColor(renderer.render(scene.scenario.frames.front().scene).rgb, bgr, cv::COLOR_RGB2BGR);
  return bgr;
}

}  // namespace

// Random cameras of the family (sim::checkCalibrator: the rough pose 0.36 m and 12 degrees off, a
// guessed height). Not every camera of the family is fitted this well yet (12 of seeds 0-15 and
// 1000-1007: `act_calibrate --family`, README "act_calibrate"); these six are, from both splits,
// and must stay so.
TEST(MirrorCalibrator, FitsRandomSimulatedCameras) {
  for (uint32_t seed : {0u, 1u, 3u, 4u, 1002u, 1003u}) {
    const sim::CalibratorCheck c = sim::checkCalibrator(seed);
    std::printf("%s", sim::formatCalibratorChecks({c}).c_str());
    ASSERT_TRUE(c.fitted) << c.refusal;
    EXPECT_EQ(c.refusal, "") << seed;
    EXPECT_GT(c.lines.pixels, 1000u) << seed;
    EXPECT_LT(c.lines.distance_p95, 0.02) << seed;
    EXPECT_LT(c.lines.bearing_p95_deg, 1.0) << seed;
    EXPECT_LT(c.whole.distance_median, 0.02) << seed;
    EXPECT_LT(c.whole.bearing_p95_deg, 1.0) << seed;
    EXPECT_LT(c.whole.unmapped, c.whole.pixels / 50) << seed;
    EXPECT_TRUE(c.sign_right) << seed;
    EXPECT_TRUE(c.passed()) << seed;
    EXPECT_EQ(c.tilt_x_rad, 0.0) << seed;  // upright cameras: no tilt taken
    EXPECT_EQ(c.tilt_y_rad, 0.0) << seed;
  }
}

// A camera mounted 1.6-2 degrees askew (camera.tilt; NuBot's nubot_2 and nubot_101 are, by their
// fit), told its height: the calibrator finds the tilt and the mapping is within the targets. An
// upright fit of the same images was off by a bearing of 4-10 degrees and a p95 distance of 5-11%
// (seeds 8, 22, 30). Not every tilted camera is fitted this well yet: seeds 0 and 1003, tilted
// likewise, came within 0.9 and 0.5 degrees but 15% and 2.6% (p95), and 4 was refused.
TEST(MirrorCalibrator, FindsATiltedMirrorAxis) {
  for (const auto& [seed, tx, ty] :
       {std::tuple<uint32_t, double, double>{8u, 0.03, 0.0}, {22u, 0.02, -0.02}, {30u, 0.0, -0.035}}) {
    const sim::CalibratorCheck c = sim::checkCalibrator(seed, tx, ty);
    std::printf("%s", sim::formatCalibratorChecks({c}).c_str());
    ASSERT_TRUE(c.fitted) << c.refusal;
    EXPECT_TRUE(c.passed()) << seed;
    EXPECT_NEAR(c.tilt_x_rad, tx, 0.01) << seed;
    EXPECT_NEAR(c.tilt_y_rad, ty, 0.01) << seed;
  }
}

// The image geometry the fit starts from (its centre prior is 1% of the mirror radius) where a
// small field seen from afar leaves more of the mirror to the hall than to the carpet: the carpet's
// color is the chroma histogram's mode weighted towards the image centre. Unweighted, the hall's
// lilac (seed 36) and grey (41, 46) were taken for the carpet and the centre was found 100, 30
// and 60 px off; the three were refused and are now fitted within the targets (`act_calibrate
// --family 36-46`). And a goal is no chassis, though large and compact too: seed 44's yellow goal
// was taken for it (and seed 24's blue one, where the mid-grey chassis counts as floor: now no
// chassis is found there and the fit's centre search finds the mirror).
TEST(MirrorCalibrator, FindsTheCarpetBesideALargeHall) {
  for (uint32_t seed : {36u, 41u, 46u, 44u}) {
    const sim::FamilyScene scene = sim::makeFamilyScene(seed, sim::ScenarioLength::kSmall, /*ball_looks=*/false);
    const core::MirrorCalibrator calibrator(scene.calibration.field, core::MirrorCalibratorOptions{});
    const core::ImageGeometry g = calibrator.estimateImageGeometry(renderBgr(scene));
    const core::CameraCalibration& truth = scene.calibration.camera;
    EXPECT_TRUE(g.chassis_found) << seed;
    EXPECT_LT(std::hypot(g.center_px.x() - truth.center_u, g.center_px.y() - truth.center_v),
              0.01 * truth.mirror_radius_px)
        << seed;
    EXPECT_NEAR(g.chassis_radius_px, truth.chassis_radius_px, 0.1 * truth.chassis_radius_px) << seed;
    EXPECT_NEAR(g.mirror_radius_px, truth.mirror_radius_px, 0.02 * truth.mirror_radius_px) << seed;
  }
}

// No field in the image: refused, not fitted (noise, which takes a whole fit to refuse, is in the
// CLI test, test_act_calibrate.cpp).
TEST(MirrorCalibrator, RejectsImagesWithoutAField) {
  const core::MirrorCalibrator calibrator(core::fieldPreset("msl2007"), core::MirrorCalibratorOptions{});
  const cv::Mat grey(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
  EXPECT_THROW(calibrator.fit(grey), core::CalibrationFitError);
  // A field image whose lines are painted over (the carpet and the hall stay): no fit.
  const sim::FamilyScene scene = sim::makeFamilyScene(1002u, sim::ScenarioLength::kSmall, /*ball_looks=*/false);
  cv::Mat image = renderBgr(scene);
  cv::Mat hsv, whitish;
  cv::cvtColor(image, hsv, cv::COLOR_BGR2HSV);
  cv::inRange(hsv, cv::Scalar(0, 0, 150), cv::Scalar(180, 60, 255), whitish);
  cv::dilate(whitish, whitish, cv::Mat(), {-1, -1}, 2);
  image.setTo(cv::Scalar(60, 130, 50), whitish);
  core::MirrorCalibratorOptions options;
  options.pose = scene.scenario.frames.front().scene.robot_pose;
  try {
    core::MirrorCalibrator(scene.calibration.field, options).fit(image);
    ADD_FAILURE() << "a field without lines was fitted";
  } catch (const core::CalibrationFitError& e) {
    std::printf("refused: %s\n", e.what());
  }
}

TEST(MirrorCalibrator, FieldPresetsAreValid) {
  for (const std::string& name : core::fieldPresetNames()) {
    core::Calibration c;
    c.field = core::fieldPreset(name);
    c.camera.width = c.camera.height = 100;
    c.camera.center_u = c.camera.center_v = 50;
    c.camera.height_m = 0.7;
    c.camera.chassis_radius_px = 5;
    c.camera.mirror_radius_px = 45;
    c.camera.elevation_map = {{5, -1.2}, {45, 0.1}};
    EXPECT_NO_THROW(core::validateCalibration(c, name)) << name;
  }
  EXPECT_EQ(core::fieldPreset("lab6x4").length_m, 6.0);
  EXPECT_EQ(core::fieldPreset("msl2007").width_m, 12.0);
  EXPECT_THROW(core::fieldPreset("nope"), std::invalid_argument);
}

namespace {
std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = testing::TempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}
}  // namespace

// The import samples d = a tan(b r) densely: the file's mapping gives NuBot's ground distances.
TEST(NubotImport, SamplesTheirModel) {
  const std::string mirror =
      writeTemp("mirror_calib.xml",
                "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<opencv_storage>\n"
                "   <center_coloum>3.3e+02</center_coloum>\n   <center_row>2.4e+02</center_row>\n"
                "   <para_a>2.1</para_a>\n   <para_b>5.8e-03</para_b>\n</opencv_storage>\n");
  const std::string roi = writeTemp("ROI.xml",
                                    "<?xml version=\"1.0\"?>\n<opencv_storage>\n<big_radius>193</big_radius>\n"
                                    "<small_radius>38</small_radius>\n</opencv_storage>\n");
  const core::CameraCalibration c = core::importNubotMirror(mirror, roi, 640, 480, 0.7);
  EXPECT_DOUBLE_EQ(c.center_u, 330.0);
  EXPECT_DOUBLE_EQ(c.center_v, 240.0);
  EXPECT_DOUBLE_EQ(c.mirror_radius_px, 193.0);
  EXPECT_DOUBLE_EQ(c.chassis_radius_px, 38.0);
  const core::OmniCameraModel model(c);
  for (double r : {45.0, 100.0, 150.0, 190.0}) {
    const core::PixelRay ray = model.computeRay(330.0 + r, 240.0);
    ASSERT_EQ(ray.region, core::PixelRegion::kFloor);
    const double expected = 2.1 * std::tan(5.8e-3 * r);
    EXPECT_NEAR(std::hypot(ray.ground_x_m, ray.ground_y_m), expected, 0.005 * expected) << r;
  }
  // Missing, malformed and implausible values are errors that name the key.
  const std::string no_b = writeTemp("no_b.xml",
                                     "<opencv_storage><center_coloum>330</center_coloum><center_row>240</center_row>"
                                     "<para_a>2.1</para_a></opencv_storage>");
  try {
    core::importNubotMirror(no_b, "", 640, 480, 0.7);
    ADD_FAILURE() << "no exception";
  } catch (const core::CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("para_b: missing"), std::string::npos) << e.what();
  }
  const std::string bad = writeTemp("bad.xml",
                                    "<opencv_storage><center_coloum>33O</center_coloum><center_row>240</center_row>"
                                    "<para_a>2.1</para_a><para_b>0.0058</para_b></opencv_storage>");
  EXPECT_THROW(core::importNubotMirror(bad, "", 640, 480, 0.7), core::CalibrationError);
  const std::string other_model = writeTemp("other.xml",
                                            "<opencv_storage><center_coloum>246</center_coloum><center_row>243"
                                            "</center_row><para_a>1.09e-03</para_a><para_b>2.99e-03</para_b>"
                                            "</opencv_storage>");
  EXPECT_THROW(core::importNubotMirror(other_model, "", 480, 480, 0.7), core::CalibrationError);
}
