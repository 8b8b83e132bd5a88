#include "act_color/core/feature_extractor.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "act_color/core/expected_class_model.hpp"

namespace act_color {
namespace core {

LutViewSegmenter::LutViewSegmenter(const CameraCalibration& camera) : width_(camera.width), height_(camera.height) {
  // Inside the mirror: r <= mirror radius and the elevation table's end, as Segmenter.
  const double r_max = std::min(camera.mirror_radius_px, camera.elevation_map.back().first);
  spans_.resize(height_);
  for (int v = 0; v < height_; ++v) {
    const double dv = v - camera.center_v;
    const double half_sq = r_max * r_max - dv * dv;
    if (half_sq < 0) {
      spans_[v] = {0, 0};
      continue;
    }
    const double half = std::sqrt(half_sq);
    const int u0 = std::max(0, static_cast<int>(std::ceil(camera.center_u - half)));
    const int u1 = std::min(width_, static_cast<int>(std::floor(camera.center_u + half)) + 1);
    spans_[v] = {u0, std::max(u0, u1)};
  }
}

void LutViewSegmenter::classify(const LutView& lut, const ImageView& image, cv::Mat& labels) const {
  if (lut.table == nullptr || lut.bits < 1 || lut.bits > 8 || lut.size != (size_t{1} << (3 * lut.bits))) {
    throw std::invalid_argument("the color table is inconsistent (" + std::to_string(lut.size) + " cells for " +
                                std::to_string(lut.bits) + " bits per channel)");
  }
  if (lut.space != nativeColorSpace(image.format)) {
    throw std::invalid_argument(std::string("the table's color space does not fit ") + encodingName(image.format) +
                                " images");
  }
  if (image.width != width_ || image.height != height_) {
    throw std::invalid_argument("image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                                " px, the calibration is for " + std::to_string(width_) + "x" +
                                std::to_string(height_));
  }
  labels.create(image.height, image.width, CV_8UC1);
  const int shift = 8 - lut.bits;
  const int s0 = 2 * lut.bits;
  const int s1 = lut.bits;
  const uint8_t* table = lut.table;
  for (int v = 0; v < image.height; ++v) {
    const uint8_t* in = image.data + static_cast<size_t>(v) * image.step;
    uint8_t* out = labels.ptr<uint8_t>(v);
    const int u0 = spans_[v].first, u1 = spans_[v].second;
    std::fill(out, out + u0, static_cast<uint8_t>(kUnknown));
    std::fill(out + u1, out + image.width, static_cast<uint8_t>(kUnknown));
    switch (image.format) {
      case PixelFormat::kRgb8:
      case PixelFormat::kBgr8: {
        const int i0 = image.format == PixelFormat::kBgr8 ? 2 : 0;
        const int i2 = 2 - i0;
        for (int u = u0; u < u1; ++u) {
          const uint8_t* p = in + 3 * u;
          out[u] = table[(static_cast<uint32_t>(p[i0] >> shift) << s0) | (static_cast<uint32_t>(p[1] >> shift) << s1) |
                         static_cast<uint32_t>(p[i2] >> shift)];
        }
        break;
      }
      case PixelFormat::kUyvy:
        for (int u = u0; u < u1; ++u) {
          const uint8_t* p = in + 4 * (u >> 1);
          const uint8_t y = p[(u & 1) ? 3 : 1];
          out[u] = table[(static_cast<uint32_t>(y >> shift) << s0) | (static_cast<uint32_t>(p[0] >> shift) << s1) |
                         static_cast<uint32_t>(p[2] >> shift)];
        }
        break;
    }
  }
}

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
