#include "act_color/sim/calibrator_check.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "act_color/core/mirror_calibrator.hpp"
#include "act_color/core/omni_camera_model.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scene_family.hpp"

namespace act_color {
namespace sim {
namespace {

constexpr double kPi = 3.14159265358979323846;

double wrap(double a) { return std::atan2(std::sin(a), std::cos(a)); }

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::numeric_limits<double>::infinity();
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(q * static_cast<double>(v.size() - 1))];
}

}  // namespace

MappingError compareMappings(const core::Calibration& truth, const core::Pose2D& true_pose,
                             const core::CameraCalibration& fit, const core::Pose2D& fit_pose, double r_min,
                             double r_max) {
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

bool CalibratorCheck::passed() const {
  return fitted && refusal.empty() && lines.pixels > 1000 && lines.distance_p95 < 0.02 && lines.bearing_p95_deg < 1.0 &&
         whole.distance_median < 0.02 && whole.bearing_p95_deg < 1.0 && whole.unmapped < whole.pixels / 50 &&
         sign_right;
}

CalibratorCheck checkCalibrator(uint32_t seed, double tilt_x_rad, double tilt_y_rad) {
  FamilyScene scene = makeFamilyScene(seed, ScenarioLength::kSmall, /*ball_looks=*/false);
  scene.calibration.camera.tilt_x_rad = tilt_x_rad;
  scene.calibration.camera.tilt_y_rad = tilt_y_rad;
  CalibratorCheck check;
  check.seed = seed;
  check.summary = scene.summary;
  const core::Pose2D truth = scene.scenario.frames.front().scene.robot_pose;
  core::MirrorCalibratorOptions options;
  options.pose = {truth.x_m + 0.3, truth.y_m - 0.2, wrap(truth.theta_rad + 12 * kPi / 180)};
  // Upright, ground distances depend on the height and the elevations only jointly; tilted, the
  // tilt's effect on them depends on the height, which a team measures: then it is told.
  options.height_m = tilt_x_rad != 0 || tilt_y_rad != 0 ? scene.calibration.camera.height_m : 0.7;
  // Used only when the image cannot tell the sign (a pose near the field's long axis).
  options.bearing_sign_prior = scene.calibration.camera.bearing_sign;
  const core::MirrorCalibrator calibrator(scene.calibration.field, options);
  const Renderer renderer(scene.calibration, scene.renderer);
  cv::Mat bgr;
  cv::cvtColor(renderer.render(scene.scenario.frames.front().scene).rgb, bgr, cv::COLOR_RGB2BGR);
  const auto start = std::chrono::steady_clock::now();
  core::MirrorFit fit;
  try {
    fit = calibrator.fitUnchecked(bgr);
  } catch (const std::exception& e) {
    check.refusal = e.what();
    return check;
  }
  check.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  check.fitted = true;
  check.refusal = calibrator.rejection(fit);
  check.profile = fit.profile;
  check.pose_error_m = std::hypot(fit.pose.x_m - truth.x_m, fit.pose.y_m - truth.y_m);
  check.residual_median_m = fit.residual.median_m;
  check.carpet_inlier_fraction = fit.residual.carpet_inlier_fraction;
  check.carpet_on_lines = fit.carpet_on_lines;
  const core::CameraCalibration& true_camera = scene.calibration.camera;
  std::vector<double> radii;
  for (const cv::Point2f& p : fit.line_pixels) {
    radii.push_back(std::hypot(p.x - true_camera.center_u, p.y - true_camera.center_v));
  }
  const double r_min = core::OmniCameraModel(true_camera).radiusAtElevation(-std::atan(true_camera.height_m / 1.0));
  check.lines =
      compareMappings(scene.calibration, truth, fit.calibration.camera, fit.pose, r_min, percentile(radii, 0.98));
  check.whole = compareMappings(scene.calibration, truth, fit.calibration.camera, fit.pose);
  check.sign_right = fit.calibration.camera.bearing_sign == true_camera.bearing_sign;
  check.tilt_x_rad = fit.calibration.camera.tilt_x_rad;
  check.tilt_y_rad = fit.calibration.camera.tilt_y_rad;
  return check;
}

std::string formatCalibratorChecks(const std::vector<CalibratorCheck>& checks) {
  std::ostringstream out;
  out << "| seed | result | profile | distance error from 1 m: median / p95 | whole field: median / p95 | bearing "
         "p95 (deg) | pose error | residual: median, inliers, carpet on lines | fit time | scene "
         "|\n|---|---|---|---|---|---|---|---|---|---|\n";
  size_t passed = 0, refused = 0, written_wrong = 0;
  char line[640];
  for (const CalibratorCheck& c : checks) {
    const bool refuses = !c.refusal.empty();
    passed += c.passed();
    refused += refuses;
    written_wrong += !refuses && !c.passed();
    std::string profile = c.profile;
    if (c.tilt_x_rad != 0 || c.tilt_y_rad != 0) {
      std::snprintf(line, sizeof(line), ", tilted %.2f deg", std::hypot(c.tilt_x_rad, c.tilt_y_rad) * 180 / kPi);
      profile += line;
    }
    if (!c.fitted) {
      out << "| " << c.seed << " | refused: " << c.refusal << " | | | | | | | | ";
    } else {
      std::snprintf(
          line, sizeof(line),
          "| %u | %s | %s | %.2f%% / %.2f%% | %.2f%% / %.2f%% | %.2f | %.3f m | %.3f m, %.2f, %.1f%% | %.1f s | ",
          c.seed, c.passed() ? "within the targets" : (refuses ? "refused" : "written, off target"), profile.c_str(),
          100 * c.lines.distance_median, 100 * c.lines.distance_p95, 100 * c.whole.distance_median,
          100 * c.whole.distance_p95, std::max(c.lines.bearing_p95_deg, c.whole.bearing_p95_deg), c.pose_error_m,
          c.residual_median_m, c.carpet_inlier_fraction, 100 * c.carpet_on_lines, c.seconds);
      out << line;
    }
    out << c.summary << " |\n";
  }
  std::snprintf(line, sizeof(line),
                "\n%zu of %zu cameras within the targets (ground distance 2%%, bearing 1 degree); %zu refused; %zu "
                "written off target\n",
                passed, checks.size(), refused, written_wrong);
  out << line;
  return out.str();
}

}  // namespace sim
}  // namespace act_color
