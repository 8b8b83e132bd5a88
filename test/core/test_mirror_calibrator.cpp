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

#include "act_color/core/calibration.hpp"
#include "act_color/core/mirror_calibrator.hpp"
#include "act_color/core/omni_camera_model.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scene_family.hpp"

namespace core = act_color::core;
namespace sim = act_color::sim;

namespace {

constexpr double kPi = 3.14159265358979323846;

double wrap(double a) { return std::atan2(std::sin(a), std::cos(a)); }

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::numeric_limits<double>::infinity();
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(q * (v.size() - 1))];
}

struct MappingError {
  size_t pixels = 0;        // floor pixels of the truth within the field (and the radii asked for)
  size_t unmapped = 0;      // of them, not floor under the fit
  double distance_p95 = 0;  // relative ground-distance error, 95th percentile
  double distance_median = 0;
  double bearing_p95_deg = 0;  // field-frame bearing error
};

// The fitted mapping against the truth: ground distance from the robot and the field-frame
// bearing (heading + bearing: one image sees only their sum) of every 3rd pixel whose true floor
// point lies within the field, at radii in [r_min, r_max] from the true centre.
MappingError compare(const core::Calibration& truth, const core::Pose2D& true_pose, const core::CameraCalibration& fit,
                     const core::Pose2D& fit_pose, double r_min = 0.0, double r_max = 1e9) {
  const core::OmniCameraModel t(truth.camera), f(fit);
  const double c = std::cos(true_pose.theta_rad), s = std::sin(true_pose.theta_rad);
  std::vector<double> distance, bearing;
  MappingError e;
  for (int v = 0; v < truth.camera.height; v += 3) {
    for (int u = 0; u < truth.camera.width; u += 3) {
      const core::PixelRay& rt = t.ray(u, v);
      if (rt.region != core::PixelRegion::kFloor) continue;
      const double r = std::hypot(u - truth.camera.center_u, v - truth.camera.center_v);
      if (r < r_min || r > r_max) continue;
      const double wx = true_pose.x_m + c * rt.ground_x_m - s * rt.ground_y_m;
      const double wy = true_pose.y_m + s * rt.ground_x_m + c * rt.ground_y_m;
      if (std::abs(wx) > truth.field.length_m / 2 || std::abs(wy) > truth.field.width_m / 2) continue;
      ++e.pixels;
      const core::PixelRay& rf = f.ray(u, v);
      if (rf.region != core::PixelRegion::kFloor) {
        ++e.unmapped;
        continue;
      }
      const double dt = std::hypot(rt.ground_x_m, rt.ground_y_m), df = std::hypot(rf.ground_x_m, rf.ground_y_m);
      distance.push_back(std::abs(df - dt) / dt);
      bearing.push_back(std::abs(wrap(fit_pose.theta_rad + rf.bearing_rad - true_pose.theta_rad - rt.bearing_rad)));
    }
  }
  e.distance_p95 = percentile(distance, 0.95);
  e.distance_median = percentile(distance, 0.5);
  e.bearing_p95_deg = percentile(bearing, 0.95) * 180 / kPi;
  return e;
}

cv::Mat renderBgr(const sim::FamilyScene& scene) {
  const sim::Renderer renderer(scene.calibration, scene.renderer);
  cv::Mat bgr;
  cv::cvtColor(renderer.render(scene.scenario.frames.front().scene).rgb, bgr, cv::COLOR_RGB2BGR);
  return bgr;
}

}  // namespace

// Random cameras of the family, the rough pose 0.36 m and 12 degrees off, a guessed height
// (0.7 m: ground distances depend only on height and elevation jointly). Not every camera of the
// family is fitted this well yet (12 of seeds 0-15 and 1000-1007, README "act_calibrate"): these
// six are, from both splits, and must stay so.
TEST(MirrorCalibrator, FitsRandomSimulatedCameras) {
  for (uint32_t seed : {0u, 1u, 3u, 4u, 1002u, 1003u}) {
    const sim::FamilyScene scene = sim::makeFamilyScene(seed, sim::ScenarioLength::kSmall, /*ball_looks=*/false);
    const core::Pose2D truth = scene.scenario.frames.front().scene.robot_pose;
    core::MirrorCalibratorOptions options;
    options.pose = {truth.x_m + 0.3, truth.y_m - 0.2, wrap(truth.theta_rad + 12 * kPi / 180)};
    options.height_m = 0.7;
    // Used only when the image cannot tell the sign (a pose near the field's long axis).
    options.bearing_sign_prior = scene.calibration.camera.bearing_sign;
    const core::MirrorCalibrator calibrator(scene.calibration.field, options);
    const cv::Mat image = renderBgr(scene);
    core::MirrorFit fit;
    ASSERT_NO_THROW(fit = calibrator.fit(image)) << scene.summary;
    // Measured where the image constrains the mapping: from 1 m (nearer, a line passing the robot
    // runs almost radially in the image and hardly fixes the radial scale; the fit extrapolates
    // there) out to the radius of the farthest line pixels (98th percentile).
    const core::OmniCameraModel true_camera(scene.calibration.camera);
    std::vector<double> radii;
    for (const cv::Point2f& p : fit.line_pixels) {
      radii.push_back(std::hypot(p.x - scene.calibration.camera.center_u, p.y - scene.calibration.camera.center_v));
    }
    const double r_max = percentile(radii, 0.98);
    const double r_min = true_camera.radiusAtElevation(-std::atan(scene.calibration.camera.height_m / 1.0));
    const MappingError e = compare(scene.calibration, truth, fit.calibration.camera, fit.pose, r_min, r_max);
    const MappingError all = compare(scene.calibration, truth, fit.calibration.camera, fit.pose);
    std::printf(
        "seed %u: %s profile, residual %.3f m, inliers %.2f, pose error %.3f m | radii %.0f-%.0f px: distance "
        "error median %.4f p95 %.4f, bearing p95 %.2f deg, %zu pixels | whole field: distance median %.4f p95 %.4f, "
        "bearing p95 %.2f deg, unmapped %zu of %zu\n  %s\n",
        seed, fit.profile.c_str(), fit.residual.median_m, fit.residual.inlier_fraction,
        std::hypot(fit.pose.x_m - truth.x_m, fit.pose.y_m - truth.y_m), r_min, r_max, e.distance_median, e.distance_p95,
        e.bearing_p95_deg, e.pixels, all.distance_median, all.distance_p95, all.bearing_p95_deg, all.unmapped,
        all.pixels, scene.summary.c_str());
    EXPECT_GT(e.pixels, 1000u);
    EXPECT_LT(e.distance_p95, 0.02) << seed;
    EXPECT_LT(e.bearing_p95_deg, 1.0) << seed;
    EXPECT_LT(all.distance_median, 0.02) << seed;
    EXPECT_LT(all.bearing_p95_deg, 1.0) << seed;
    EXPECT_LT(all.unmapped, all.pixels / 50) << seed;
    EXPECT_NO_THROW(core::validateCalibration(fit.calibration, "fit"));
    EXPECT_EQ(fit.calibration.camera.bearing_sign, scene.calibration.camera.bearing_sign) << seed;
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
