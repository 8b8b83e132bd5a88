#include "act_color/core/expected_class_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace act_color {
namespace core {

ExpectedClassModel::ExpectedClassModel(const Calibration& calibration)
    : field_(calibration.field), camera_(calibration.camera) {
  ground_range_m_.resize(camera_.rays().size());
  removal_range_m_.resize(camera_.rays().size());
  const double step = 2.0 * M_PI / kRemovalSectors;
  for (size_t i = 0; i < ground_range_m_.size(); ++i) {
    const PixelRay& ray = camera_.ray(i);
    ground_range_m_[i] = ray.region == PixelRegion::kFloor ? std::hypot(ray.ground_x_m, ray.ground_y_m)
                                                           : std::numeric_limits<float>::infinity();
    const bool never_unknown = ray.region == PixelRegion::kNotImaged || ray.region == PixelRegion::kChassis ||
                               ray.region == PixelRegion::kSelf;
    removal_range_m_[i] = never_unknown ? -std::numeric_limits<float>::infinity() : ground_range_m_[i];
    // How far the bearings of the floor points and above-horizon rays (which a tilt turns) reach
    // beyond the sectors removalSector puts them in.
    if (ray.region != PixelRegion::kFloor && ray.region != PixelRegion::kAboveHorizon) continue;
    const double bearing = ray.region == PixelRegion::kFloor ? std::atan2(ray.ground_y_m, ray.ground_x_m)
                                                             : std::atan2(ray.dir_y, ray.dir_x);
    const double d = std::abs(std::remainder(bearing - (removalSector(i) + 0.5) * step, 2.0 * M_PI));
    sector_bearing_reach_ = std::max(sector_bearing_reach_, d - 0.5 * step);
  }
}

template <bool kTellLines>
uint8_t ExpectedClassModel::classOfRay(const PixelRay& ray, const PoseTransform& pose) const {
  // The ray in the field frame, computed only when a goal may be hit: up to the floor point or,
  // above the horizon, without end.
  auto goalHit = [&](bool to_floor) {
    const Eigen::Vector3d origin(pose.x_m, pose.y_m, camera_.viewpointHeight());
    const Eigen::Vector3d dir(pose.cos_theta * ray.dir_x - pose.sin_theta * ray.dir_y,
                              pose.sin_theta * ray.dir_x + pose.cos_theta * ray.dir_y, ray.dir_z);
    const double t_max = to_floor ? camera_.viewpointHeight() / -dir.z() : std::numeric_limits<double>::infinity();
    return field_.goalHit(origin, dir, t_max);
  };
  if (ray.region == PixelRegion::kAboveHorizon) return goalHit(false);
  double fx, fy;
  pose.apply(ray.ground_x_m, ray.ground_y_m, &fx, &fy);
  // A ray can only pass through a goal box if it reaches beyond a goal line.
  if (std::abs(fx) >= field_.halfLength() || std::abs(pose.x_m) >= field_.halfLength()) {
    const ColorClass goal = goalHit(true);
    if (goal != kUnknown) return goal;
  }
  if (kTellLines) return field_.floorClass(fx, fy);
  return field_.onCarpet(fx, fy) ? kGreen : kUnknown;
}

bool ExpectedClassModel::offField(size_t pixel_index, const PoseTransform& pose) const {
  const PixelRay& ray = camera_.ray(pixel_index);
  if (ray.region != PixelRegion::kFloor && ray.region != PixelRegion::kAboveHorizon) return false;
  return classOfRay<false>(ray, pose) == kUnknown;
}

uint8_t ExpectedClassModel::geometricClass(size_t pixel_index, const PoseTransform& pose) const {
  const PixelRay& ray = camera_.ray(pixel_index);
  switch (ray.region) {
    case PixelRegion::kNotImaged:
    case PixelRegion::kSelf:
      return kNotImaged;
    case PixelRegion::kChassis:
      return kBlack;
    case PixelRegion::kFloor:
    case PixelRegion::kAboveHorizon:
      break;
  }
  return classOfRay<true>(ray, pose);
}

double ExpectedClassModel::safeCarpetRange(const Pose2D& pose) const {
  const FieldCalibration& f = field_.calibration();
  const double ax = std::abs(pose.x_m);
  const double ay = std::abs(pose.y_m);
  double range = std::min(field_.halfLength() + f.margin_m - ax, field_.halfWidth() + f.margin_m - ay);
  // Distance to the goal boxes' footprints (both lie at |x| >= half length, |y| <= width / 2).
  const double dx = std::max(0.0, field_.halfLength() - ax);
  const double dy = std::max(0.0, ay - f.goal_width_m / 2);
  range = std::min(range, std::hypot(dx, dy));
  return std::max(0.0, range);
}

int ExpectedClassModel::removalSector(size_t pixel_index) const {
  constexpr double kTwoPi = 2.0 * M_PI;
  double bearing = std::fmod(static_cast<double>(camera_.ray(pixel_index).bearing_rad), kTwoPi);
  if (bearing < 0) bearing += kTwoPi;
  const int sector = static_cast<int>(bearing / kTwoPi * kRemovalSectors);
  return std::clamp(sector, 0, kRemovalSectors - 1);
}

void ExpectedClassModel::sectorSafeRanges(const Pose2D& pose, std::array<double, kRemovalSectors>& out) const {
  // Off the carpet or in a goal region means |x| >= half length (the goal lines; goals lie behind
  // them, and a ray to a floor point in front of them cannot pass through a goal) or |y| >= half
  // width + margin. Along a ray at angle a the wall with inner normal angle n and distance d is
  // reached after d / cos(a - n); over a sector the smallest is at the bearing nearest to n.
  const double x_wall = field_.halfLength();
  const double y_wall = field_.halfWidth() + field_.calibration().margin_m;
  if (!(std::abs(pose.x_m) < x_wall && std::abs(pose.y_m) < y_wall)) {
    out.fill(0.0);
    return;
  }
  // Inner normals along +x, -x, +y, -y, and the distances to the walls.
  const double distance[4] = {x_wall - pose.x_m, x_wall + pose.x_m, y_wall - pose.y_m, y_wall + pose.y_m};
  const double half = M_PI / kRemovalSectors;  // half a sector
  const double cos_half = std::cos(half), sin_half = std::sin(half);
  // cos and sin of the sector centres, by rotating from the first one.
  double c = std::cos(pose.theta_rad + half), sn = std::sin(pose.theta_rad + half);
  const double cos_step = std::cos(2.0 * half), sin_step = std::sin(2.0 * half);
  for (int s = 0; s < kRemovalSectors; ++s) {
    // cos and |sin| of the angle between each normal and the sector centre.
    const double cos_delta[4] = {c, -c, sn, -sn};
    const double sin_delta[4] = {std::abs(sn), std::abs(sn), std::abs(c), std::abs(c)};
    double safe = std::numeric_limits<double>::infinity();
    for (int w = 0; w < 4; ++w) {
      // cos of the angle to the sector's nearest bearing: 1 when the normal lies in the sector.
      const double cos_nearest = cos_delta[w] >= cos_half ? 1.0 : cos_delta[w] * cos_half + sin_delta[w] * sin_half;
      if (cos_nearest <= 1e-9) continue;  // the sector's rays never reach this wall
      safe = std::min(safe, distance[w] / cos_nearest);
    }
    // A little less, for the float ranges and the rounding of the bearings.
    out[static_cast<size_t>(s)] = std::max(0.0, safe * (1.0 - 1e-6) - 1e-6);
    const double next_c = c * cos_step - sn * sin_step;
    sn = sn * cos_step + c * sin_step;
    c = next_c;
  }
}

void ExpectedClassModel::sectorOffRanges(const Pose2D& pose, std::array<double, kRemovalSectors>& out) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr double kTwoPi = 2.0 * M_PI;
  constexpr double kStep = kTwoPi / kRemovalSectors;
  constexpr double kMargin = 1e-3;  // rad: rounding of the bearings
  out.fill(kInf);
  const double half_length = field_.carpetHalfLength(), half_width = field_.carpetHalfWidth();
  const double x = pose.x_m, y = pose.y_m;
  // Off the carpet, or bearings a tilt turns by more than a sector: no shortcut.
  if (!(std::abs(x) < half_length && std::abs(y) < half_width) || !(sector_bearing_reach_ < kStep)) return;
  // Sector s holds the bearings (field frame, relative to theta) [s step - reach, (s + 1) step +
  // reach], reach the pixels' largest bearing beyond their nominal sector plus a margin.
  const double reach = sector_bearing_reach_ + kMargin;
  // Marks the sectors whose bearings meet [a - half, a + half] (a relative to theta).
  auto sectorsMeeting = [&](double a, double half, auto&& mark) {
    a = std::fmod(a, kTwoPi);
    if (a < 0) a += kTwoPi;
    const int first = static_cast<int>(std::floor((a - half - reach) / kStep));
    const int last = static_cast<int>(std::floor((a + half + reach) / kStep));
    for (int k = first; k <= std::min(last, first + kRemovalSectors - 1); ++k) {
      mark(static_cast<size_t>(((k % kRemovalSectors) + kRemovalSectors) % kRemovalSectors));
    }
  };
  // A ray meets a goal box only if its bearing points into the goal's footprint.
  std::array<bool, kRemovalSectors> goal{};
  for (int i = 0; i < 2; ++i) {
    Eigen::Vector3d lo, hi;
    field_.goalBox(i == 0 ? kYellow : kBlue, &lo, &hi);
    if (x >= lo.x() - 1e-6 && x <= hi.x() + 1e-6 && y >= lo.y() - 1e-6 && y <= hi.y() + 1e-6) return;
    const double centre = std::atan2(0.5 * (lo.y() + hi.y()) - y, 0.5 * (lo.x() + hi.x()) - x);
    double half = 0.0;
    for (const double cx : {lo.x(), hi.x()}) {
      for (const double cy : {lo.y(), hi.y()}) {
        half = std::max(half, std::abs(std::remainder(std::atan2(cy - y, cx - x) - centre, kTwoPi)));
      }
    }
    sectorsMeeting(centre - pose.theta_rad, half, [&](size_t s) { goal[s] = true; });
  }
  // Leaving a convex carpet, the farthest exit over a sector's bearings is at one of their ends or
  // at a corner of the carpet between them. Ends: each sector boundary +- reach.
  auto exitRange = [&](double c, double s) {
    const double tx = c > 0 ? (half_length - x) / c : c < 0 ? (-half_length - x) / c : kInf;
    const double ty = s > 0 ? (half_width - y) / s : s < 0 ? (-half_width - y) / s : kInf;
    return std::min(tx, ty);
  };
  std::array<double, kRemovalSectors> boundary{};
  const double cos_step = std::cos(kStep), sin_step = std::sin(kStep);
  for (const double offset : {-reach, reach}) {
    double c = std::cos(pose.theta_rad + offset), sn = std::sin(pose.theta_rad + offset);
    for (int k = 0; k < kRemovalSectors; ++k) {
      boundary[static_cast<size_t>(k)] = std::max(boundary[static_cast<size_t>(k)], exitRange(c, sn));
      const double next_c = c * cos_step - sn * sin_step;
      sn = sn * cos_step + c * sin_step;
      c = next_c;
    }
  }
  std::array<double, kRemovalSectors> far{};
  for (int k = 0; k < kRemovalSectors; ++k) {
    far[static_cast<size_t>(k)] =
        std::max(boundary[static_cast<size_t>(k)], boundary[static_cast<size_t>((k + 1) % kRemovalSectors)]);
  }
  for (const double cx : {-half_length, half_length}) {
    for (const double cy : {-half_width, half_width}) {
      const double distance = std::hypot(cx - x, cy - y);
      sectorsMeeting(std::atan2(cy - y, cx - x) - pose.theta_rad, 0.0,
                     [&](size_t s) { far[s] = std::max(far[s], distance); });
    }
  }
  for (size_t s = 0; s < out.size(); ++s) {
    if (!goal[s]) out[s] = far[s] * (1.0 + 1e-6) + 1e-6;
  }
}

bool ExpectedClassModel::brighterThanNeighbourhood(const ImageView& image, int u, int v) {
  if (u < 2 || v < 2 || u >= image.width - 2 || v >= image.height - 2) return false;
  int sum = 0;
  for (int j = v - 2; j <= v + 2; ++j) {
    for (int i = u - 2; i <= u + 2; ++i) sum += image.intensity(i, j);
  }
  return 25 * image.intensity(u, v) > sum;  // eq. 1, without the division
}

cv::Mat ExpectedClassModel::expectedLabels(const ImageView& image, const Pose2D& pose) const {
  cv::Mat labels(camera_.height(), camera_.width(), CV_8UC1);
  const PoseTransform transform(pose);
  for (int v = 0; v < camera_.height(); ++v) {
    uint8_t* row = labels.ptr<uint8_t>(v);
    for (int u = 0; u < camera_.width(); ++u) {
      uint8_t c = geometricClass(static_cast<size_t>(v) * camera_.width() + u, transform);
      if (c == kWhite && !brighterThanNeighbourhood(image, u, v)) c = kRejectedWhite;
      row[u] = c;
    }
  }
  return labels;
}

}  // namespace core
}  // namespace act_color
