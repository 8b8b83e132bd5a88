#pragma once

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/image_view.hpp"
#include "act_color/core/omni_camera_model.hpp"
#include "act_color/core/types.hpp"

namespace act_color {
namespace core {

enum class FeatureType : uint8_t { kLinePoint = 0, kYellowGoal = 1, kBlueGoal = 2, kBall = 3, kObstacle = 4 };

struct Feature {
  FeatureType type = FeatureType::kLinePoint;
  float u = 0.f, v = 0.f;                    // pixel of the floor point
  float centroid_u = 0.f, centroid_v = 0.f;  // centre of the run or blob
  float base_x_m = 0.f, base_y_m = 0.f;      // floor point in base_link
  float field_x_m = 0.f, field_y_m = 0.f;    // floor point in field (toField)
  uint32_t size = 0;
};

struct FeatureParams {
  int scan_lines = 180;      // radial scan lines over 360 degrees
  int max_line_run_px = 12;  // longer white runs are not lines
  int min_goal_run_px = 3;   // goal and obstacle runs shorter than this are noise
  int min_obstacle_run_px = 4;
  int min_ball_pixels = 6;        // orange blobs smaller than this are noise
  double obstacle_merge_m = 0.5;  // neighbouring scan lines' obstacle feet closer than this merge

  // Throws std::invalid_argument naming the first parameter out of its range and its value.
  void validate() const;
};

// Features of a label image (class ids, the camera's size) by radial scan lines from the chassis
// to the mirror's rim: the robot's other modules use them (self-localization, ball, obstacles).
// Only pixels whose ray meets the floor give features. Throws std::invalid_argument when the
// label image does not fit the camera.
std::vector<Feature> extractFeatures(const cv::Mat& labels, const OmniCameraModel& camera,
                                     const FeatureParams& params = FeatureParams());

// Drops the features whose field point lies beyond the carpet (the outer lines plus the field's
// margin, or the goals' depth where that is larger): hall clutter, people and the robots' own
// reflections off the field are no obstacles or goals the robot can meet. Needs toField first.
void removeOffField(const FieldCalibration& field, std::vector<Feature>* features);

// Fills field_x_m / field_y_m from base_x_m / base_y_m for the pose of base_link in field.
void toField(const Pose2D& pose, std::vector<Feature>* features);

}  // namespace core
}  // namespace act_color
