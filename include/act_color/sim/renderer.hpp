#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/expected_class_model.hpp"
#include "act_color/core/types.hpp"
#include "act_color/sim/flat_painter.hpp"
#include "act_color/sim/tone_curve.hpp"

namespace act_color {
namespace sim {

// Another robot: a black cylinder standing on the floor.
struct RobotObstacle {
  double x_m = 0.0;
  double y_m = 0.0;
  double radius_m = 0.25;
  double height_m = 0.8;
};

// The ball: a sphere lying on the floor (RendererOptions::ball, ball_patches: its look).
struct Ball {
  double x_m = 0.0;
  double y_m = 0.0;
  double radius_m = 0.11;
};

// A person standing in the hall: a vertical cylinder, trousers below, shirt above, the head on top.
// Not a class: truth core::kUnknown. Place people off the carpet (the renderer does not check).
struct Person {
  double x_m = 0.0;
  double y_m = 0.0;
  double radius_m = 0.2;
  double height_m = 1.75;
  Eigen::Vector3d shirt_rgb{180.0, 60.0, 50.0};  // 8-bit sRGB-like, as the materials
  Eigen::Vector3d trousers_rgb{50.0, 55.0, 80.0};
  Eigen::Vector3d skin_rgb{200.0, 160.0, 130.0};  // head and hair, the top 13% of the height
};

// A pool of light on the floor and objects: gain * exp(-d^2 / (2 radius^2)) added to the level.
struct Spotlight {
  double x_m = 0.0;
  double y_m = 0.0;
  double radius_m = 2.0;
  double gain = 0.8;
};

// A hard shadow: light multiplied by `factor` inside an axis-aligned rectangle of the floor. With
// `floor_only` false, a zone of the hall's lighting: the light on everything inside the rectangle
// (floor, robots, people, hall objects; the walls by where they stand) is multiplied, as when the
// lamps over one half go off or a window's sun goes behind a cloud (`factor` may exceed 1).
struct Shadow {
  double x_min_m = 0.0, y_min_m = 0.0, x_max_m = 0.0, y_max_m = 0.0;
  double factor = 0.5;
  bool floor_only = true;
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
  // Camera white balance: per-channel (r, g, b) gains on the linear signal, before gamma.
  Eigen::Vector3d white_balance{1.0, 1.0, 1.0};
  // Color saturation of the camera's 8-bit output about its grey (luma) value: 1 leaves it alone.
  double saturation = 1.0;
  // Sensor black level in 8-bit units (DN), added with the noise before clipping.
  double black_level = 0.0;
  // A global per-channel change applied last (after noise and brightness_contrast): a sudden
  // change of light or of a camera setting. Identity by default.
  ToneCurve transfer;
};

struct Scene {
  core::Pose2D robot_pose;  // true pose of base_link in the field frame
  std::vector<RobotObstacle> robots;
  std::optional<Ball> ball;
  std::vector<Person> people;  // in the hall, off the carpet
  Lighting lighting;
  uint32_t noise_seed = 1;  // sensor noise of this frame
};

// A surface's look: the 8-bit sRGB-like color it shows under light 1 with the default photometry
// and how strongly the value-noise texture modulates it (relative albedo variation).
struct SurfaceLook {
  Eigen::Vector3d rgb{128.0, 128.0, 128.0};
  float texture_amplitude = 0.1f;
};

// A part of the own robot in front of the mirror (a strut holding the mirror, a cable): an annular
// sector of the image, centred on the image-plane bearing atan2(dv, du) (not base_link's bearing:
// struts are fixed in the image whatever bearing_sign and bearing_offset say). Truth core::kBlack
// (the contract's black: robots, including the own one), lit by the light at the robot.
struct Strut {
  double bearing_rad = 0.0;      // atan2(v - cv, u - cu) of the strut's axis
  double half_width_rad = 0.03;  // angular half-width about that axis
  double inner_radius_px = 0.0;  // from this radius ...
  double outer_radius_px = 1e9;  // ... to this one (clipped to the mirror)
  Eigen::Vector3d rgb{40.0, 40.0, 44.0};
};

// The clutter colors of the default hall (several of them close to class colors).
const std::vector<Eigen::Vector3d>& defaultClutterPalette();

// What the renderer draws besides the scene: the hall, the materials and the own robot's parts.
// The defaults are the renderer's original look (Renderer(calibration, hall_seed) uses them).
struct RendererOptions {
  uint32_t hall_seed = 7;  // layout of the hall's clutter and the texture

  SurfaceLook carpet{{52.0, 138.0, 58.0}, 0.22f};
  SurfaceLook line{{224.0, 228.0, 218.0}, 0.08f};
  SurfaceLook yellow_goal{{228.0, 196.0, 28.0}, 0.08f};
  SurfaceLook blue_goal{{28.0, 72.0, 192.0}, 0.08f};
  SurfaceLook robot{{34.0, 34.0, 38.0}, 0.35f};
  SurfaceLook ball{{240.0, 108.0, 22.0}, 0.06f};
  // A ball of two colors: patches of this one (about a third of the surface) on `ball`.
  std::optional<SurfaceLook> ball_patches;
  // A band of this color around every other robot (a team marker; truth black, it is the robot).
  std::optional<SurfaceLook> robot_marker;
  SurfaceLook chassis{{30.0, 30.0, 33.0}, 0.3f};
  SurfaceLook hall_floor{{150.0, 142.0, 128.0}, 0.3f};
  SurfaceLook wall{{196.0, 190.0, 176.0}, 0.15f};
  SurfaceLook ceiling{{110.0, 110.0, 116.0}, 0.15f};

  // Colors of boxes, posters and mats (8-bit sRGB-like), drawn uniformly per item.
  std::vector<Eigen::Vector3d> clutter_palette = defaultClutterPalette();
  int num_boxes = 14;                 // standing between the carpet and the walls
  int num_wall_patches = 9;           // per wall (posters, doors; the first one is a bright window)
  int num_floor_mats = 10;            // on the hall floor
  double hall_wall_distance_m = 4.0;  // walls this far beyond the carpet's edge
  double hall_height_m = 4.0;         // the ceiling

  std::vector<Strut> struts;  // the own robot's parts in front of the mirror
};

// Ray-casts the contract's omnidirectional camera on a 2007-rules MSL field: carpet and lines,
// 3-D goals (solid colored boxes as in FieldModel), other robots, the ball, and a hall beyond the
// margin (floor and walls with colored clutter, some of it close to the class colors).
// Deterministic: the same calibration, options and scene give the same bytes.
// The hall (defaults): walls 4 m beyond the carpet and 4 m high, a ceiling with lamps, boxes and mats on the
// hall floor and posters/windows on the walls, laid out from `hall_seed`. Truth is the class of the
// first surface a pixel's ray meets; on the static world it equals
// ExpectedClassModel::geometricClass exactly (same rays, same floor points, FieldModel::goalHit).
// Struts, robots, the ball and people (off the carpet: they cover only off-carpet floor, walls and
// clutter, unless placed elsewhere) are the exceptions.
class Renderer {
 public:
  // The default look with the hall laid out from `hall_seed`.
  explicit Renderer(const core::Calibration& calibration, uint32_t hall_seed = 7);
  Renderer(const core::Calibration& calibration, const RendererOptions& options);

  // rgb8 image and truth labels (class ids, core::kNotImaged outside the mirror).
  LabeledFrame render(const Scene& scene) const;

  const core::ExpectedClassModel& model() const;

  // The pixels the own robot's mirror struts cover (row-major, 1 = strut): the self mask a team
  // learns with `act_replay --learn-self-mask`; empty without struts.
  std::vector<uint8_t> strutMask() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace sim
}  // namespace act_color
