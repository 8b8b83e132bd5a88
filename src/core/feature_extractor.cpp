#include "act_color/core/feature_extractor.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <string>

#include "act_color/core/expected_class_model.hpp"

namespace act_color {
namespace core {

namespace {

struct ScanPixel {
  int u, v;
  uint8_t label;
  bool floor;
};

Feature makeFeature(FeatureType type, const ScanPixel& foot, double cu, double cv, const OmniCameraModel& camera,
                    uint32_t size) {
  Feature f;
  f.type = type;
  f.u = static_cast<float>(foot.u);
  f.v = static_cast<float>(foot.v);
  f.centroid_u = static_cast<float>(cu);
  f.centroid_v = static_cast<float>(cv);
  const PixelRay& ray = camera.ray(foot.u, foot.v);
  f.base_x_m = ray.ground_x_m;
  f.base_y_m = ray.ground_y_m;
  f.size = size;
  return f;
}

}  // namespace

std::vector<Feature> extractFeatures(const cv::Mat& labels, const OmniCameraModel& camera,
                                     const FeatureParams& params) {
  if (labels.type() != CV_8UC1 || labels.cols != camera.width() || labels.rows != camera.height()) {
    throw std::invalid_argument("label image does not fit the camera (" + std::to_string(camera.width()) + "x" +
                                std::to_string(camera.height()) + " mono8 expected)");
  }
  const CameraCalibration& cal = camera.calibration();
  const double r0 = cal.chassis_radius_px + 1.0;
  const double r1 = std::min(cal.mirror_radius_px, cal.elevation_map.back().first) - 1.0;
  std::vector<Feature> features;
  std::vector<ScanPixel> line;
  // Obstacle feet of consecutive scan lines, merged into one obstacle.
  std::vector<Feature> obstacle_group;
  std::vector<Feature> obstacles;
  auto flushObstacles = [&]() {
    if (obstacle_group.empty()) return;
    // The foot on the group's middle scan line: the obstacle's centre bearing.
    Feature f = obstacle_group[obstacle_group.size() / 2];
    double cu = 0, cv = 0;
    for (const Feature& g : obstacle_group) {
      cu += g.centroid_u;
      cv += g.centroid_v;
    }
    f.centroid_u = static_cast<float>(cu / obstacle_group.size());
    f.centroid_v = static_cast<float>(cv / obstacle_group.size());
    f.size = static_cast<uint32_t>(obstacle_group.size());
    obstacles.push_back(f);
    obstacle_group.clear();
  };

  for (int s = 0; s < params.scan_lines; ++s) {
    const double a = 2.0 * M_PI * s / params.scan_lines;
    const double ca = std::cos(a), sa = std::sin(a);
    line.clear();
    int last_u = -1, last_v = -1;
    for (double r = r0; r <= r1; r += 1.0) {
      const int u = static_cast<int>(std::lround(cal.center_u + r * ca));
      const int v = static_cast<int>(std::lround(cal.center_v + r * sa));
      if (u < 0 || v < 0 || u >= labels.cols || v >= labels.rows || (u == last_u && v == last_v)) continue;
      last_u = u;
      last_v = v;
      line.push_back({u, v, labels.at<uint8_t>(v, u), camera.ray(u, v).region == PixelRegion::kFloor});
    }
    bool yellow_done = false, blue_done = false, obstacle_found = false;
    uint8_t before = kUnknown;  // class of the run before the current one
    size_t i = 0;
    while (i < line.size()) {
      size_t j = i;
      while (j < line.size() && line[j].label == line[i].label) ++j;
      const uint8_t k = line[i].label;
      const int run = static_cast<int>(j - i);
      const ScanPixel& foot = line[i];
      const ScanPixel& mid = line[(i + j - 1) / 2];
      if (foot.floor) {
        if (k == kWhite && run <= params.max_line_run_px && before == kGreen && j < line.size() &&
            line[j].label == kGreen && mid.floor) {
          features.push_back(makeFeature(FeatureType::kLinePoint, mid, mid.u, mid.v, camera, run));
        } else if ((k == kYellow && !yellow_done) || (k == kBlue && !blue_done)) {
          if (run >= params.min_goal_run_px) {
            features.push_back(makeFeature(k == kYellow ? FeatureType::kYellowGoal : FeatureType::kBlueGoal, foot,
                                           mid.u, mid.v, camera, run));
            (k == kYellow ? yellow_done : blue_done) = true;
          }
        } else if (k == kBlack && !obstacle_found && run >= params.min_obstacle_run_px) {
          Feature f = makeFeature(FeatureType::kObstacle, foot, mid.u, mid.v, camera, run);
          if (!obstacle_group.empty()) {
            const Feature& prev = obstacle_group.back();
            if (std::hypot(prev.base_x_m - f.base_x_m, prev.base_y_m - f.base_y_m) > params.obstacle_merge_m)
              flushObstacles();
          }
          obstacle_group.push_back(f);
          obstacle_found = true;
        }
      }
      before = k;
      i = j;
    }
    if (!obstacle_found) flushObstacles();
  }
  // (An obstacle across scan line 0 is reported as two neighbouring candidates.)
  flushObstacles();
  features.insert(features.end(), obstacles.begin(), obstacles.end());

  // Ball: orange blobs; the innermost pixel is where the ball touches the floor.
  cv::Mat orange = labels == kOrange;
  cv::Mat components, stats, centroids;
  const int n = cv::connectedComponentsWithStats(orange, components, stats, centroids, 8, CV_32S);
  std::vector<ScanPixel> innermost(n, ScanPixel{-1, -1, kOrange, false});
  std::vector<double> best_r(n, 1e9);
  for (int v = 0; v < components.rows; ++v) {
    const int* row = components.ptr<int>(v);
    for (int u = 0; u < components.cols; ++u) {
      const int c = row[u];
      if (c == 0 || stats.at<int>(c, cv::CC_STAT_AREA) < params.min_ball_pixels) continue;
      if (camera.ray(u, v).region != PixelRegion::kFloor) continue;
      const double r = std::hypot(u - cal.center_u, v - cal.center_v);
      if (r < best_r[c]) {
        best_r[c] = r;
        innermost[c] = {u, v, kOrange, true};
      }
    }
  }
  for (int c = 1; c < n; ++c) {
    if (innermost[c].u < 0) continue;
    features.push_back(makeFeature(FeatureType::kBall, innermost[c], centroids.at<double>(c, 0),
                                   centroids.at<double>(c, 1), camera,
                                   static_cast<uint32_t>(stats.at<int>(c, cv::CC_STAT_AREA))));
  }
  return features;
}

void FeatureParams::validate() const {
  auto require = [](const char* name, double value, double lo, double hi) {
    requireParameterRange(name, value, lo, hi);
  };
  require("scan_lines", scan_lines, 4, 3600);
  require("max_line_run_px", max_line_run_px, 1, 1000);
  require("min_goal_run_px", min_goal_run_px, 1, 1000);
  require("min_obstacle_run_px", min_obstacle_run_px, 1, 1000);
  require("min_ball_pixels", min_ball_pixels, 1, 100000);
  require("obstacle_merge_m", obstacle_merge_m, 0.0, 10.0);
}

void removeOffField(const FieldCalibration& field, std::vector<Feature>* features) {
  const double beyond_x = std::max(field.margin_m, field.goal_setback_m + field.goal_depth_m);
  const double half_x = 0.5 * field.length_m + beyond_x;
  const double half_y = 0.5 * field.width_m + field.margin_m;
  features->erase(std::remove_if(features->begin(), features->end(),
                                 [&](const Feature& f) {
                                   return !(std::abs(f.field_x_m) <= half_x && std::abs(f.field_y_m) <= half_y);
                                 }),
                  features->end());
}

void toField(const Pose2D& pose, std::vector<Feature>* features) {
  const PoseTransform transform(pose);
  for (Feature& f : *features) {
    double x, y;
    transform.apply(f.base_x_m, f.base_y_m, &x, &y);
    f.field_x_m = static_cast<float>(x);
    f.field_y_m = static_cast<float>(y);
  }
}

}  // namespace core
}  // namespace act_color
