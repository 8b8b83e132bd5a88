#include "act_color/sim/flat_painter.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace act_color {
namespace sim {

LabeledFrame paintFlatFrame(const core::ExpectedClassModel& model, const core::Pose2D& pose, double brightness,
                            uint32_t seed) {
  static const double kColors[core::kNumClasses][3] = {{0, 0, 0},     {45, 140, 55}, {235, 235, 230}, {225, 200, 35},
                                                       {35, 70, 205}, {28, 28, 32},  {240, 110, 20}};
  // Clutter off the field: some of it close to class colors.
  static const double kClutter[6][3] = {{120, 110, 100}, {90, 150, 80}, {200, 180, 90},
                                        {70, 90, 160},   {160, 60, 50}, {60, 55, 50}};
  const core::OmniCameraModel& camera = model.camera();
  LabeledFrame frame;
  frame.rgb.create(camera.height(), camera.width(), CV_8UC3);
  frame.labels.create(camera.height(), camera.width(), CV_8UC1);
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 4.0);
  const core::PoseTransform transform(pose);
  for (int v = 0; v < camera.height(); ++v) {
    uint8_t* out = frame.rgb.ptr<uint8_t>(v);
    uint8_t* lab = frame.labels.ptr<uint8_t>(v);
    for (int u = 0; u < camera.width(); ++u) {
      const size_t index = static_cast<size_t>(v) * camera.width() + u;
      const uint8_t k = model.geometricClass(index, transform);
      lab[u] = k;
      double c[3] = {0, 0, 0};
      if (k == core::kUnknown) {
        // Clutter patches of 1 m (floor) or by bearing (walls).
        const core::PixelRay& ray = camera.ray(index);
        int cell;
        if (ray.region == core::PixelRegion::kFloor) {
          double fx, fy;
          transform.apply(ray.ground_x_m, ray.ground_y_m, &fx, &fy);
          cell = static_cast<int>(std::floor(fx)) * 7 + static_cast<int>(std::floor(fy)) * 13;
        } else {
          cell = static_cast<int>(std::floor((ray.bearing_rad + pose.theta_rad) * 6.0));
        }
        const double* clutter = kClutter[((cell % 6) + 6) % 6];
        std::copy(clutter, clutter + 3, c);
      } else if (k < core::kNumClasses) {
        std::copy(kColors[k], kColors[k] + 3, c);
      }
      for (int ch = 0; ch < 3; ++ch) {
        const double value = k == core::kNotImaged ? 0.0 : brightness * c[ch] + noise(rng);
        out[3 * u + ch] = static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
      }
    }
  }
  return frame;
}

}  // namespace sim
}  // namespace act_color
