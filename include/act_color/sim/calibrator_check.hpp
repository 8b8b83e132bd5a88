#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/types.hpp"

namespace act_color {
namespace sim {

// A fitted pixel-to-floor mapping against the true one (issue 12: ground points within 2% of their
// distance, bearing within 1 degree): ground distance from the robot and the field-frame bearing
// (heading + bearing: one image sees only their sum) of every 3rd pixel whose true floor point lies
// within the field, at radii in [r_min, r_max] from the true mirror centre.
struct MappingError {
  size_t pixels = 0;                             // floor pixels of the truth within the field and the radii
  size_t unmapped = 0;                           // of them, not floor under the fit
  double distance_median = 0, distance_p95 = 0;  // relative ground-distance error
  double bearing_p95_deg = 0;
};
MappingError compareMappings(const core::Calibration& truth, const core::Pose2D& true_pose,
                             const core::CameraCalibration& fit, const core::Pose2D& fit_pose, double r_min = 0.0,
                             double r_max = 1e9);

// core::MirrorCalibrator on the first image of a scene of the randomized family, told a pose 0.36 m
// and 12 degrees off and a height of 0.7 m (ground distances depend on height and elevation only
// jointly), the bearing sign as prior only.
struct CalibratorCheck {
  uint32_t seed = 0;
  std::string summary;  // the scene
  bool fitted = false;  // a fit was made (else `refusal` says why: too few line pixels)
  std::string refusal;  // why the calibrator would refuse it ("" when it would write the file)
  std::string profile;
  double pose_error_m = 0;
  // What the calibrator itself sees of its fit (the refusal is decided on them): median distance of
  // the line pixels to the model's lines, the fraction of those on the carpet within 0.08 m, and
  // the fraction of carpet pixels the model puts on a painted line.
  double residual_median_m = 0, carpet_inlier_fraction = 0, carpet_on_lines = 0;
  // From 1 m out to the farthest line pixels (98th percentile): where the image constrains the
  // mapping; nearer, a line passing the robot runs almost radially and the profile extrapolates.
  MappingError lines;
  MappingError whole;  // the whole field
  bool sign_right = false;
  double tilt_x_rad = 0, tilt_y_rad = 0;  // the fit's camera.tilt
  double seconds = 0;                     // the fit's run time
  // Within the targets: p95 of `lines` < 2%, median of `whole` < 2%, bearing p95 < 1 degree on
  // both, the sign right, under 2% of the field unmapped, and not refused.
  bool passed() const;
};
// `tilt_x_rad`, `tilt_y_rad`: the scene's camera tilted so (camera.tilt; the family's are upright);
// a tilted camera's calibrator is told the true height (a tilt moves ground points by an amount
// that depends on it).
CalibratorCheck checkCalibrator(uint32_t seed, double tilt_x_rad = 0.0, double tilt_y_rad = 0.0);
std::string formatCalibratorChecks(const std::vector<CalibratorCheck>& checks);

}  // namespace sim
}  // namespace act_color
