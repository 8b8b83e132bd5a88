#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "act_color/core/calibration.hpp"

namespace act_color {
namespace core {

// What a pixel of the omnidirectional camera looks at.
enum class PixelRegion : uint8_t {
  kNotImaged = 0,     // outside the mirror
  kChassis = 1,       // the own robot
  kFloor = 2,         // ray below the horizon: meets the floor
  kAboveHorizon = 3,  // ray at or above the horizon
  kSelf = 4,          // the own robot in front of the mirror (the self mask and its 8-neighbours): no class
};

// Precomputed view ray of one pixel in base_link, from the viewpoint (0, 0, height_m).
struct PixelRay {
  PixelRegion region = PixelRegion::kNotImaged;
  float bearing_rad = 0.f;
  float elevation_rad = 0.f;
  // Floor point in base_link (valid for kFloor).
  float ground_x_m = 0.f;
  float ground_y_m = 0.f;
  // Unit direction in base_link (valid for kFloor and kAboveHorizon).
  float dir_x = 0.f;
  float dir_y = 0.f;
  float dir_z = 0.f;
};

// camera.tilt's rotation of view directions (camera frame -> base_link) for a rotation vector
// (tilt_x_rad, tilt_y_rad, 0); the identity for none.
Eigen::Matrix3d tiltRotation(double tilt_x_rad, double tilt_y_rad);
// The unit view direction of a bearing (counter-clockwise from x) and an elevation (up from the
// horizon).
Eigen::Vector3d viewDirection(double bearing_rad, double elevation_rad);

// The contract's camera model: pixel -> bearing/elevation -> floor point, precomputed for every
// pixel of the calibrated image size.
class OmniCameraModel {
 public:
  explicit OmniCameraModel(const CameraCalibration& camera);

  const CameraCalibration& calibration() const { return camera_; }
  int width() const { return camera_.width; }
  int height() const { return camera_.height; }
  double viewpointHeight() const { return camera_.height_m; }

  const PixelRay& ray(int u, int v) const { return rays_[static_cast<size_t>(v) * camera_.width + u]; }
  const PixelRay& ray(size_t index) const { return rays_[index]; }
  const std::vector<PixelRay>& rays() const { return rays_; }

  // Elevation for a radius in pixels by linear interpolation; NaN beyond the table's ends.
  double elevationAtRadius(double r_px) const;
  // Inverse of elevationAtRadius; NaN when the elevation is outside the table.
  double radiusAtElevation(double elevation_rad) const;
  // Computes the ray of an arbitrary (sub)pixel position (not only pixel centres).
  PixelRay computeRay(double u, double v) const;
  // Pixel that sees the base_link direction (bearing, elevation); false when not imaged.
  bool projectDirection(double bearing_rad, double elevation_rad, double* u, double* v) const;
  // Pixel that sees the floor point (x, y) in base_link; false when not imaged.
  bool projectFloorPoint(double x_m, double y_m, double* u, double* v) const;

 private:
  CameraCalibration camera_;
  bool tilted_;           // camera.tilt is not zero
  Eigen::Matrix3d tilt_;  // camera.tilt: camera frame -> base_link
  std::vector<PixelRay> rays_;
};

}  // namespace core
}  // namespace act_color
