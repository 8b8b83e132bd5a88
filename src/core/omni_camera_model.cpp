#include "act_color/core/omni_camera_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace act_color {
namespace core {

Eigen::Matrix3d tiltRotation(double tilt_x_rad, double tilt_y_rad) {
  const Eigen::Vector3d w(tilt_x_rad, tilt_y_rad, 0.0);
  if (!(w.norm() > 0)) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
}

Eigen::Vector3d viewDirection(double bearing_rad, double elevation_rad) {
  return {std::cos(elevation_rad) * std::cos(bearing_rad), std::cos(elevation_rad) * std::sin(bearing_rad),
          std::sin(elevation_rad)};
}

namespace {

// A view direction's bearing and elevation after the rotation `turn`.
void turnView(const Eigen::Matrix3d& turn, double* bearing_rad, double* elevation_rad) {
  const Eigen::Vector3d dir = turn * viewDirection(*bearing_rad, *elevation_rad);
  *bearing_rad = std::atan2(dir.y(), dir.x());
  *elevation_rad = std::asin(std::clamp(dir.z(), -1.0, 1.0));
}

}  // namespace

OmniCameraModel::OmniCameraModel(const CameraCalibration& camera)
    : camera_(camera), tilted_(camera.tiltRad() > 0), tilt_(tiltRotation(camera.tilt_x_rad, camera.tilt_y_rad)) {
  rays_.resize(static_cast<size_t>(camera_.width) * camera_.height);
  for (int v = 0; v < camera_.height; ++v) {
    for (int u = 0; u < camera_.width; ++u) rays_[static_cast<size_t>(v) * camera_.width + u] = computeRay(u, v);
  }
  // Pixels of the self mask show the own robot (struts, cables): their view rays are kept, their
  // region says they show no class. So do the pixels right next to them (8-neighbours): a part's
  // blurred edge is neither the part nor what lies behind it.
  if (camera_.self_mask.size() == rays_.size()) {
    const int w = camera_.width, h = camera_.height;
    for (int v = 0; v < h; ++v) {
      for (int u = 0; u < w; ++u) {
        if (!camera_.self_mask[static_cast<size_t>(v) * w + u]) continue;
        for (int nv = std::max(0, v - 1); nv <= std::min(h - 1, v + 1); ++nv) {
          for (int nu = std::max(0, u - 1); nu <= std::min(w - 1, u + 1); ++nu) {
            PixelRay& ray = rays_[static_cast<size_t>(nv) * w + nu];
            if (ray.region != PixelRegion::kNotImaged) ray.region = PixelRegion::kSelf;
          }
        }
      }
    }
  }
}

double OmniCameraModel::elevationAtRadius(double r_px) const {
  const auto& map = camera_.elevation_map;
  if (r_px < map.front().first || r_px > map.back().first) return std::numeric_limits<double>::quiet_NaN();
  for (size_t i = 1; i < map.size(); ++i) {
    if (r_px <= map[i].first) {
      const double f = (r_px - map[i - 1].first) / (map[i].first - map[i - 1].first);
      return map[i - 1].second + f * (map[i].second - map[i - 1].second);
    }
  }
  return map.back().second;
}

double OmniCameraModel::radiusAtElevation(double elevation_rad) const {
  const auto& map = camera_.elevation_map;
  if (elevation_rad < map.front().second || elevation_rad > map.back().second)
    return std::numeric_limits<double>::quiet_NaN();
  for (size_t i = 1; i < map.size(); ++i) {
    if (elevation_rad <= map[i].second) {
      const double f = (elevation_rad - map[i - 1].second) / (map[i].second - map[i - 1].second);
      return map[i - 1].first + f * (map[i].first - map[i - 1].first);
    }
  }
  return map.back().first;
}

PixelRay OmniCameraModel::computeRay(double u, double v) const {
  PixelRay ray;
  const double du = u - camera_.center_u;
  const double dv = v - camera_.center_v;
  const double r = std::hypot(du, dv);
  if (r > camera_.mirror_radius_px || r > camera_.elevation_map.back().first) return ray;  // not imaged
  if (r < camera_.chassis_radius_px || r < camera_.elevation_map.front().first) {
    ray.region = PixelRegion::kChassis;
    return ray;
  }
  double elevation = elevationAtRadius(r);
  double bearing = camera_.bearing_sign * std::atan2(dv, du) + camera_.bearing_offset_rad;
  if (tilted_) turnView(tilt_, &bearing, &elevation);
  ray.bearing_rad = static_cast<float>(bearing);
  ray.elevation_rad = static_cast<float>(elevation);
  const Eigen::Vector3d dir = viewDirection(bearing, elevation);
  ray.dir_x = static_cast<float>(dir.x());
  ray.dir_y = static_cast<float>(dir.y());
  ray.dir_z = static_cast<float>(dir.z());
  if (elevation < 0) {
    ray.region = PixelRegion::kFloor;
    const double ground = camera_.height_m / std::tan(-elevation);
    ray.ground_x_m = static_cast<float>(ground * std::cos(bearing));
    ray.ground_y_m = static_cast<float>(ground * std::sin(bearing));
  } else {
    ray.region = PixelRegion::kAboveHorizon;
  }
  return ray;
}

bool OmniCameraModel::projectDirection(double bearing_rad, double elevation_rad, double* u, double* v) const {
  if (tilted_) turnView(tilt_.transpose(), &bearing_rad, &elevation_rad);  // into the camera's frame
  const double r = radiusAtElevation(elevation_rad);
  if (!std::isfinite(r) || r < camera_.chassis_radius_px || r > camera_.mirror_radius_px) return false;
  // bearing = sign * phi + offset, sign = +-1.
  const double phi = camera_.bearing_sign * (bearing_rad - camera_.bearing_offset_rad);
  *u = camera_.center_u + r * std::cos(phi);
  *v = camera_.center_v + r * std::sin(phi);
  return true;
}

bool OmniCameraModel::projectFloorPoint(double x_m, double y_m, double* u, double* v) const {
  const double ground = std::hypot(x_m, y_m);
  if (ground <= 0) return false;
  return projectDirection(std::atan2(y_m, x_m), -std::atan(camera_.height_m / ground), u, v);
}

}  // namespace core
}  // namespace act_color
