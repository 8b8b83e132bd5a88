#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/expected_class_model.hpp"
#include "act_color/core/types.hpp"
#include "act_color/sim/flat_painter.hpp"

namespace act_color {
namespace sim {

// Another robot: a black cylinder standing on the floor.
struct RobotObstacle {
  double x_m = 0.0;
  double y_m = 0.0;
  double radius_m = 0.25;
  double height_m = 0.8;
};

// The ball: an orange sphere lying on the floor.
struct Ball {
  double x_m = 0.0;
  double y_m = 0.0;
  double radius_m = 0.11;
};

// A pool of light on the floor and objects: gain * exp(-d^2 / (2 radius^2)) added to the level.
struct Spotlight {
  double x_m = 0.0;
  double y_m = 0.0;
  double radius_m = 2.0;
  double gain = 0.8;
};

// A hard shadow: light multiplied by `factor` inside an axis-aligned rectangle of the floor.
struct Shadow {
  double x_min_m = 0.0, y_min_m = 0.0, x_max_m = 0.0, y_max_m = 0.0;
  double factor = 0.5;
};

// Illumination and camera photometry.
struct Lighting {
  double level = 1.0;                   // global light level
  double color_temperature_k = 5500.0;  // 5500: neutral; lower is redder, higher bluer
  double gradient_x_per_m = 0.0;        // relative change of light per metre along field x
  double gradient_y_per_m = 0.0;
  std::vector<Spotlight> spotlights;
  std::vector<Shadow> shadows;
  double exposure = 1.0;
  double gamma = 1.0 / 2.2;  // output = (exposure * linear) ^ gamma
  double vignetting = 0.25;  // relative light loss at the mirror's rim
  double blur_sigma_px = 0.7;
  double noise_sigma = 2.5;  // sensor noise, 8-bit units
  // The paper's darkening (section 3.2): brightness and contrast of the final image to this
  // fraction; 1.0 leaves the image alone, 0.5 is the paper's 50% darkening.
  double brightness_contrast = 1.0;
};

struct Scene {
  core::Pose2D robot_pose;  // true pose of base_link in the field frame
  std::vector<RobotObstacle> robots;
  std::optional<Ball> ball;
  Lighting lighting;
  uint32_t noise_seed = 1;  // sensor noise of this frame
};

// Ray-casts the contract's omnidirectional camera on a 2007-rules MSL field: carpet and lines,
// 3-D goals (solid colored boxes as in FieldModel), other robots, the ball, and a hall beyond the
// margin (floor and walls with colored clutter, some of it close to the class colors).
// Deterministic: the same calibration, hall seed and scene give the same bytes.
// The hall: walls 4 m beyond the carpet and 4 m high, a ceiling with lamps, boxes and mats on the
// hall floor and posters/windows on the walls, laid out from `hall_seed`. Truth is the class of the
// first surface a pixel's ray meets; on the static world it equals
// ExpectedClassModel::geometricClass exactly (same rays, same floor points, FieldModel::goalHit).
class Renderer {
 public:
  explicit Renderer(const core::Calibration& calibration, uint32_t hall_seed = 7);

  // rgb8 image and truth labels (class ids, core::kNotImaged outside the mirror).
  LabeledFrame render(const Scene& scene) const;

  const core::ExpectedClassModel& model() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace sim
}  // namespace act_color
