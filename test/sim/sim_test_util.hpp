#pragma once

#include <cmath>
#include <string>

#include "act_color/core/calibration.hpp"
#include "act_color/core/types.hpp"
#include "act_color/sim/renderer.hpp"

namespace act_color {
namespace sim_test {

inline std::string sourcePath(const std::string& relative) { return std::string(ACT_SOURCE_DIR) + "/" + relative; }

// The package's simulated camera (piecewise elevation map) and the contract's example (two points).
inline core::Calibration defaultCalibration() {
  return core::loadCalibration(sourcePath("config/calibration/msl_2007_580.yaml"));
}
// A second camera (640x480, off-centre mirror, mirrored bearings), for checks that nothing is tuned
// to the first.
inline core::Calibration secondCalibration() {
  return core::loadCalibration(sourcePath("config/calibration/msl_2007_640x480.yaml"));
}
inline core::Calibration contractCalibration() {
  return core::loadCalibration(sourcePath("test/data/contract_example.yaml"));
}

// A field point in base_link of `pose`.
inline void fieldToBase(const core::Pose2D& pose, double fx, double fy, double* bx, double* by) {
  const double dx = fx - pose.x_m, dy = fy - pose.y_m;
  const double c = std::cos(pose.theta_rad), s = std::sin(pose.theta_rad);
  *bx = c * dx + s * dy;
  *by = -s * dx + c * dy;
}

// Lighting without noise or blur: pixel colors follow the surfaces exactly.
inline sim::Lighting cleanLighting() {
  sim::Lighting l;
  l.noise_sigma = 0.0;
  l.blur_sigma_px = 0.0;
  return l;
}

}  // namespace sim_test
}  // namespace act_color
