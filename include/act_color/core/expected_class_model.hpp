#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>

#include "act_color/core/calibration.hpp"
#include "act_color/core/field_model.hpp"
#include "act_color/core/image_view.hpp"
#include "act_color/core/omni_camera_model.hpp"
#include "act_color/core/types.hpp"

namespace act_color {
namespace core {

// Expected-label value of a pixel the field model puts on a line but that fails eq. 1.
constexpr uint8_t kRejectedWhite = 254;

// A pose ready for transforming many points: base_link -> field.
struct PoseTransform {
  explicit PoseTransform(const Pose2D& pose)
      : x_m(pose.x_m), y_m(pose.y_m), cos_theta(std::cos(pose.theta_rad)), sin_theta(std::sin(pose.theta_rad)) {}
  double x_m, y_m, cos_theta, sin_theta;
  void apply(double bx, double by, double* fx, double* fy) const {
    *fx = x_m + cos_theta * bx - sin_theta * by;
    *fy = y_m + sin_theta * bx + cos_theta * by;
  }
};

// The expected class of a pixel given the robot's pose (paper, section 2.1).
class ExpectedClassModel {
 public:
  explicit ExpectedClassModel(const Calibration& calibration);

  const FieldModel& field() const { return field_; }
  const OmniCameraModel& camera() const { return camera_; }

  // Class from geometry alone: kNotImaged outside the mirror, kBlack on the own chassis, kYellow
  // or kBlue where the ray meets a goal, kWhite or kGreen where it meets the carpet (white before
  // eq. 1), kUnknown elsewhere (off the carpet, above the horizon).
  uint8_t geometricClass(size_t pixel_index, const PoseTransform& pose) const;

  // True when the floor point of pixel `pixel_index` is surely on the carpet and not in a goal
  // region: used to skip pixels that cannot be unknown. `safe_range_m` from safeCarpetRange().
  bool surelyOnCarpet(size_t pixel_index, double safe_range_m) const {
    return ground_range_m_[pixel_index] < safe_range_m;
  }
  // Distance from the robot to the nearest carpet edge or goal box (0 when outside the carpet).
  double safeCarpetRange(const Pose2D& pose) const;

  // The removal step's sectors: bearings (base_link) split into kRemovalSectors equal sectors.
  static constexpr int kRemovalSectors = 64;
  // Sector of a floor or above-horizon pixel (by its bearing in base_link).
  int removalSector(size_t pixel_index) const;
  // Per sector, a ground range below which a floor point seen in that sector is surely on the
  // carpet and not in a goal region at this pose (the distance along the sector's rays to the side
  // lines plus margin and to the goal lines; 0 everywhere when the robot is beyond them). At least
  // safeCarpetRange in directions away from the goals, and larger in most.
  void sectorSafeRanges(const Pose2D& pose, std::array<double, kRemovalSectors>& out) const;
  // Per sector, a ground range beyond which offField is true at this pose without a ray cast:
  // every floor point the sector's pixels see beyond it is off the carpet, and none of the sector's
  // rays can meet a goal (the goals' footprints lie in other bearings). +inf for sectors that may
  // see a goal, and everywhere when the robot is off the carpet; above-horizon pixels have the
  // range +inf, so that they pass in the other sectors.
  void sectorOffRanges(const Pose2D& pose, std::array<double, kRemovalSectors>& out) const;

  // For the removal step (2.4): one float per pixel, -inf for pixels that are never kUnknown (not
  // imaged, chassis), else the floor range. mayBeOffField is false when geometricClass cannot be
  // kUnknown for a pixel whose safe range (safeCarpetRange, or its sector's from sectorSafeRanges)
  // is safe_range_m.
  float removalRange(size_t pixel_index) const { return removal_range_m_[pixel_index]; }
  static bool mayBeOffField(float removal_range_m, double safe_range_m) { return !(removal_range_m < safe_range_m); }
  size_t pixels() const { return removal_range_m_.size(); }
  // Hints the cache about the ray of a pixel (< pixels()) that will be looked at soon.
  void prefetchRay(size_t pixel_index) const { __builtin_prefetch(&camera_.ray(pixel_index)); }
  // geometricClass(pixel_index, pose) == kUnknown, computed the same way but without telling lines
  // from carpet.
  bool offField(size_t pixel_index, const PoseTransform& pose) const;

 private:
  // Goal or floor class of a floor or above-horizon ray; carpet as kGreen unless kTellLines.
  template <bool kTellLines>
  uint8_t classOfRay(const PixelRay& ray, const PoseTransform& pose) const;

 public:
  // eq. 1: the pixel is brighter than the mean of its 5x5 neighbourhood. False within 2 px of
  // the image border.
  static bool brighterThanNeighbourhood(const ImageView& image, int u, int v);

  // Expected class of every pixel with eq. 1 applied to white (pixels failing it become
  // kRejectedWhite: they train nothing); kNotImaged outside the mirror. For inspection and tests.
  cv::Mat expectedLabels(const ImageView& image, const Pose2D& pose) const;

 private:
  FieldModel field_;
  OmniCameraModel camera_;
  // Ground distance of each floor pixel's floor point; +inf for others.
  std::vector<float> ground_range_m_;
  // How far (rad) the bearings of floor points and above-horizon rays reach beyond their removal
  // sector (a tilted mirror turns them; 0 when none does).
  double sector_bearing_reach_ = 0.0;
  // ground_range_m_, but -inf for pixels that are never kUnknown (not imaged, chassis): the
  // removal step skips most pixels with this one compact array instead of the 32-byte rays.
  std::vector<float> removal_range_m_;
};

}  // namespace core
}  // namespace act_color
