#include "act_color/sim/scene_family.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <stdexcept>

namespace act_color {
namespace sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
// Closest distance of another robot's centre to the own robot's, and of the ball's.
constexpr double kMinRobotDistanceM = 0.9;
constexpr double kMinBallDistanceM = 0.5;
// Frames after which the evaluator measures (12 frames of adaptation plus settle cycles): the
// scene's first event and each following one leave at least this many frames.
constexpr int kSmallBefore = 14, kSmallAfter = 20;
constexpr int kFullBefore = 42, kFullAfter = 40;

using core::wrapAngle;

// The scene's random draws, all from one generator seeded with the scene's seed.
class Draw {
 public:
  explicit Draw(uint32_t seed) : rng(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  int integer(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); }
  bool chance(double p) { return uniform(0.0, 1.0) < p; }
  int sign() { return chance(0.5) ? 1 : -1; }
  // Index drawn with the given weights.
  size_t weighted(const std::vector<double>& weights) {
    return std::discrete_distribution<size_t>(weights.begin(), weights.end())(rng);
  }
  Eigen::Vector3d jitter(const Eigen::Vector3d& rgb, double amount) {
    Eigen::Vector3d out;
    for (int c = 0; c < 3; ++c) out[c] = std::clamp(rgb[c] + uniform(-amount, amount), 0.0, 255.0);
    return out;
  }
  Eigen::Vector3d grey(double lo, double hi, double tint) {
    const double g = uniform(lo, hi);
    return jitter(Eigen::Vector3d::Constant(g), tint);
  }
  std::mt19937 rng;
};

// ---------------------------------------------------------------------------------------------
// Camera

struct ImageSize {
  int width, height;
  double weight;  // large images are rarer: they take longer to render
};
const std::vector<ImageSize>& imageSizes() {
  static const std::vector<ImageSize> kSizes = {{480, 480, 3.0}, {580, 580, 3.0},  {640, 480, 3.0},  {752, 480, 2.0},
                                                {800, 600, 1.5}, {1024, 768, 1.2}, {1280, 1024, 0.6}};
  return kSizes;
}

// Elevation below the horizon as a function of r in [r_chassis, r_horizon), strictly increasing
// towards 0 at r_horizon.
using Profile = std::function<double(double r_px)>;

// Draws the mirror profile; `kind` receives its name.
Profile drawProfile(Draw& draw, double height_m, double r_chassis_px, double r_horizon_px, std::string* kind) {
  const size_t which = draw.weighted({1.0, 1.0, 0.8, 0.8});
  if (which == 0) {
    // Ground distance d = a tan(b r), as MSL teams fit their mirrors; b puts the horizon at r_h.
    *kind = "tan";
    const double a_m = draw.uniform(1.0, 2.6);
    const double b = kPi / (2.0 * r_horizon_px);
    return [=](double r) { return -std::atan(height_m / (a_m * std::tan(b * r))); };
  }
  if (which == 1) {
    // A single-viewpoint hyperbolic mirror (unified model): r = g sin(a) / (xi + cos(a)) for the
    // nadir angle a; xi = 1 is a parabolic mirror. g puts the horizon (a = pi/2) at r_h.
    *kind = "hyperbolic";
    const double xi = draw.uniform(0.5, 1.0);
    const double g = xi * r_horizon_px;
    return [=](double r) {
      double lo = 0.0, hi = kPi / 2;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (g * std::sin(mid) / (xi + std::cos(mid)) < r ? lo : hi) = mid;
      }
      return 0.5 * (lo + hi) - kPi / 2;
    };
  }
  if (which == 2) {
    // A polynomial profile in the normalised radius.
    *kind = "polynomial";
    const double c = draw.uniform(0.8, 0.97), p = draw.uniform(1.3, 2.5);
    return [=](double r) { return -(kPi / 2) * c * std::pow(1.0 - r / r_horizon_px, p); };
  }
  // Piecewise linear in r, with two knees (a mirror made of a near and a far part).
  *kind = "piecewise";
  const double s1 = draw.uniform(0.35, 0.5), s2 = draw.uniform(0.65, 0.8);
  const double e0 = draw.uniform(-1.35, -1.05);
  const double e1 = e0 * draw.uniform(0.4, 0.6), e2 = e1 * draw.uniform(0.25, 0.45);
  const double r0 = r_chassis_px, r1 = s1 * r_horizon_px, r2 = s2 * r_horizon_px, r3 = r_horizon_px;
  return [=](double r) {
    if (r <= r1) return e0 + (e1 - e0) * (r - r0) / (r1 - r0);
    if (r <= r2) return e1 + (e2 - e1) * (r - r1) / (r2 - r1);
    return e2 + (0.0 - e2) * (r - r2) / (r3 - r2);
  };
}

struct CameraDraw {
  std::string profile;
  int size_index = 0;
};

// Large images (over 800x600) in every seventh scene (seed % 7 == 3) and only there: any 14
// consecutive seeds hold two, and the mean render time does not depend on luck.
bool largeImageScene(uint32_t seed) { return seed % 7 == 3; }

core::CameraCalibration drawCamera(Draw& draw, bool large, CameraDraw* info) {
  core::CameraCalibration c;
  std::vector<double> weights;
  for (const ImageSize& s : imageSizes()) {
    const bool is_large = static_cast<double>(s.width) * s.height > 800.0 * 600.0;
    weights.push_back(is_large == large ? s.weight : 0.0);
  }
  info->size_index = static_cast<int>(draw.weighted(weights));
  const ImageSize& size = imageSizes()[info->size_index];
  c.width = size.width;
  c.height = size.height;
  c.center_u = 0.5 * c.width + draw.uniform(-0.08, 0.08) * c.width;
  c.center_v = 0.5 * c.height + draw.uniform(-0.08, 0.08) * c.height;
  const double fit_px = std::min({c.center_u, c.width - c.center_u, c.center_v, c.height - c.center_v});
  c.mirror_radius_px = std::floor((fit_px - draw.uniform(2.0, 8.0)) * draw.uniform(0.92, 1.0));
  c.chassis_radius_px = std::round(c.mirror_radius_px * draw.uniform(0.08, 0.18));
  c.bearing_sign = draw.sign();
  c.bearing_offset_rad = draw.uniform(-kPi, kPi);
  c.height_m = draw.uniform(0.5, 0.9);

  const double r_c = c.chassis_radius_px, r_m = c.mirror_radius_px;
  const double r_h = r_m * draw.uniform(0.86, 0.95);
  const Profile below = drawProfile(draw, c.height_m, r_c, r_h, &info->profile);
  // Dense samples, closer together towards the horizon where the distance grows fastest.
  const int n_below = draw.integer(21, 33);  // with the 3-6 above the horizon: 24-39 entries
  const double density = draw.uniform(1.3, 1.8);
  for (int i = 0; i < n_below - 1; ++i) {
    const double t = static_cast<double>(i) / (n_below - 1);
    const double r = r_c + (r_h - r_c) * (1.0 - std::pow(1.0 - t, density));
    c.elevation_map.emplace_back(r, below(r));
  }
  c.elevation_map.emplace_back(r_h, 0.0);
  // A short stretch above the horizon at the rim.
  const int n_above = draw.integer(3, 6);
  const double top = draw.uniform(0.06, 0.25), q = draw.uniform(0.8, 1.25);
  for (int i = 1; i <= n_above; ++i) {
    const double t = static_cast<double>(i) / n_above;
    c.elevation_map.emplace_back(r_h + (r_m - r_h) * t, top * std::pow(t, q));
  }
  return c;
}

std::vector<Strut> drawStruts(Draw& draw, const core::CameraCalibration& c) {
  std::vector<Strut> struts;
  if (!draw.chance(0.5)) return struts;
  const int n = 1 + static_cast<int>(draw.weighted({0.15, 0.15, 0.35, 0.35}));
  const double start = draw.uniform(-kPi, kPi);
  const double inner = draw.chance(0.6) ? c.chassis_radius_px : c.mirror_radius_px * draw.uniform(0.3, 0.7);
  const bool light_metal = draw.chance(0.2);
  const Eigen::Vector3d rgb = light_metal ? draw.grey(90, 150, 6) : draw.grey(22, 55, 4);
  for (int k = 0; k < n; ++k) {
    Strut s;
    s.bearing_rad = wrapAngle(start + 2 * kPi * k / n + draw.uniform(-0.08, 0.08));
    s.half_width_rad = 0.5 * draw.uniform(1.5, 4.0) * kDegToRad;
    s.inner_radius_px = inner;
    s.outer_radius_px = c.mirror_radius_px + 1.0;
    s.rgb = draw.jitter(rgb, 4);
    struts.push_back(s);
  }
  return struts;
}

// ---------------------------------------------------------------------------------------------
// Field, hall, materials

core::FieldCalibration drawField(Draw& draw) {
  core::FieldCalibration f;
  f.length_m = draw.uniform(6.0, 18.0);
  f.width_m = std::clamp(f.length_m / draw.uniform(1.4, 1.6), 4.0, 12.0);
  const double k = f.length_m / 18.0;  // the 2007 rules' sizes scaled to this field
  f.line_width_m = std::clamp(0.05 + 0.075 * (f.length_m - 6.0) / 12.0 + draw.uniform(-0.01, 0.01), 0.05, 0.125);
  f.margin_m = draw.uniform(0.3, 1.0);
  f.center_circle_radius_m = std::min(std::max(0.5, 2.0 * k * draw.uniform(0.9, 1.1)), 0.4 * f.width_m);
  f.corner_arc_radius_m = std::max(0.25, 0.75 * k);
  f.goal_area_depth_m = std::max(0.3, 0.75 * k * draw.uniform(0.9, 1.1));
  f.goal_area_width_m = std::min(3.5 * k * draw.uniform(0.9, 1.1) + 0.3, 0.6 * f.width_m);
  f.penalty_area_depth_m = std::max(f.goal_area_depth_m + 0.4, 2.25 * k * draw.uniform(0.9, 1.1));
  f.penalty_area_width_m = std::min(std::max(f.goal_area_width_m + 0.8, 6.5 * k), 0.85 * f.width_m);
  if (draw.chance(0.5)) f.penalty_mark_distance_m = std::max(1.0, 3.0 * k);
  f.goal_width_m = std::clamp(2.0 * k * draw.uniform(0.9, 1.1), 1.0, 2.2);
  f.goal_width_m = std::min(f.goal_width_m, f.goal_area_width_m - 0.2);
  f.goal_height_m = std::clamp(0.45 + 0.55 * k * draw.uniform(0.9, 1.1), 0.5, 1.0);
  f.goal_depth_m = std::clamp(0.5 * k * draw.uniform(0.9, 1.2), 0.25, 0.6);
  f.yellow_goal_x_sign = draw.sign();
  return f;
}

// The ball's look (issue 13): orange as in 2007, yellow, red, pink, or two colors; a robot team
// marker of the ball's color or of another; a hall poster of the ball's color. Drawn with their own
// generator so that the rest of a scene stays as it was before balls had looks. Returns a word.
std::string drawBallLooks(uint32_t seed, RendererOptions* o) {
  Draw draw(seed * 2654435761u + 0xba11u);
  std::string kind;
  switch (draw.weighted({0.35, 0.25, 0.15, 0.1, 0.15})) {
    case 0:
      kind = "orange";
      break;  // as drawLooks drew it
    case 1:
      kind = "yellow";
      o->ball.rgb = Eigen::Vector3d(draw.uniform(225, 250), draw.uniform(215, 245), draw.uniform(30, 110));
      break;
    case 2:
      kind = "red";
      o->ball.rgb = Eigen::Vector3d(draw.uniform(195, 235), draw.uniform(25, 60), draw.uniform(30, 70));
      break;
    case 3:
      kind = "pink";
      o->ball.rgb = Eigen::Vector3d(draw.uniform(225, 250), draw.uniform(90, 140), draw.uniform(160, 210));
      break;
    default:
      kind = "two-colour";
      o->ball_patches = SurfaceLook{draw.chance(0.5) ? Eigen::Vector3d(draw.uniform(190, 230), 40, 50)
                                                     : Eigen::Vector3d(40, 70, draw.uniform(170, 220)),
                                    0.06f};
      break;
  }
  // A hall poster or box of the ball's color: one of the random clutter colors takes it.
  if (draw.chance(0.35) && o->clutter_palette.size() > 7) {
    o->clutter_palette.back() = draw.jitter(o->ball.rgb, 12);
    kind += ", poster";
  }
  if (draw.chance(0.3)) {
    o->robot_marker = SurfaceLook{draw.jitter(o->ball.rgb, 15), 0.06f};
    kind += ", markers of its color";
  } else if (draw.chance(0.25)) {
    o->robot_marker =
        SurfaceLook{draw.chance(0.5) ? Eigen::Vector3d(235, 70, 190) : Eigen::Vector3d(60, 210, 225), 0.06f};
    kind += ", markers";
  }
  return kind;
}

// Materials, hall and the clutter palette. Returns a short description.
void drawLooks(Draw& draw, RendererOptions* o) {
  static const std::vector<Eigen::Vector3d> kCarpets = {
      {52, 138, 58},   // the renderer's default
      {38, 128, 112},  // teal, bluish green
      {96, 150, 48},   // yellowish green
      {34, 98, 44},    // dark
      {88, 172, 96},   // light
  };
  o->carpet.rgb = draw.jitter(kCarpets[draw.weighted({2.0, 1.0, 1.0, 1.0, 1.0})], 10);
  o->carpet.texture_amplitude = static_cast<float>(draw.uniform(0.12, 0.3));
  const double line = draw.uniform(205, 240);
  o->line.rgb = draw.jitter(Eigen::Vector3d(line, line + draw.uniform(-4, 6), line - draw.uniform(0, 10)), 4);
  o->line.texture_amplitude = static_cast<float>(draw.uniform(0.04, 0.1));
  o->yellow_goal.rgb = Eigen::Vector3d(draw.uniform(205, 240), draw.uniform(165, 210), draw.uniform(10, 70));
  o->blue_goal.rgb = Eigen::Vector3d(draw.uniform(15, 50), draw.uniform(50, 105), draw.uniform(150, 215));
  o->robot.rgb = draw.grey(18, 60, 4);
  o->robot.texture_amplitude = static_cast<float>(draw.uniform(0.2, 0.4));
  o->chassis.rgb = draw.grey(18, 55, 4);
  o->ball.rgb = Eigen::Vector3d(draw.uniform(220, 250), draw.uniform(80, 130), draw.uniform(10, 40));
  o->hall_floor.rgb = draw.jitter(Eigen::Vector3d::Constant(draw.uniform(90, 180)), 12);
  o->wall.rgb = draw.jitter(Eigen::Vector3d::Constant(draw.uniform(150, 220)), 10);
  o->ceiling.rgb = draw.grey(80, 140, 6);

  // Clutter near every class color (the hard part for any color classifier), plus random ones.
  std::vector<Eigen::Vector3d>& p = o->clutter_palette;
  p.clear();
  p.push_back(draw.grey(210, 240, 6));
  p.push_back(draw.grey(210, 240, 6));
  p.push_back(draw.jitter(o->yellow_goal.rgb, 18));
  p.push_back(draw.jitter(o->blue_goal.rgb, 18));
  p.push_back(draw.grey(20, 50, 5));
  p.push_back(draw.jitter(o->carpet.rgb, 18));
  if (draw.chance(0.5)) p.push_back(draw.jitter(o->ball.rgb, 20));
  const int random_colors = draw.integer(3, 8);
  for (int i = 0; i < random_colors; ++i) {
    p.push_back(Eigen::Vector3d(draw.uniform(20, 240), draw.uniform(20, 240), draw.uniform(20, 240)));
  }
  o->num_boxes = draw.integer(6, 20);
  o->num_wall_patches = draw.integer(4, 12);
  o->num_floor_mats = draw.integer(4, 14);
  o->hall_wall_distance_m = draw.uniform(1.5, 8.0);
  o->hall_height_m = draw.uniform(3.0, 8.0);
}

Lighting drawLighting(Draw& draw, const core::FieldCalibration& f) {
  Lighting l;
  const double hl = f.length_m / 2, hw = f.width_m / 2;
  l.level = draw.uniform(0.75, 1.25);
  l.color_temperature_k = draw.uniform(3800, 7500);
  l.white_balance = Eigen::Vector3d(draw.uniform(0.88, 1.12), 1.0, draw.uniform(0.88, 1.12));
  l.saturation = draw.uniform(0.7, 1.3);
  l.black_level = draw.uniform(0, 12);
  l.gamma = 1.0 / draw.uniform(1.8, 2.6);
  l.vignetting = draw.uniform(0.0, 0.5);
  l.noise_sigma = draw.uniform(1.0, 6.0);
  l.blur_sigma_px = draw.uniform(0.0, 1.2);
  // Light from one side (a window): up to 0.08/m, but no end of the field darker than 0.4.
  const double gradient = draw.chance(0.7) ? draw.uniform(0.0, 0.08) : draw.uniform(0.0, 0.02);
  const double direction = draw.uniform(-kPi, kPi);
  const double extent =
      std::abs(std::cos(direction)) * (hl + f.margin_m) + std::abs(std::sin(direction)) * (hw + f.margin_m);
  const double g = std::min(gradient, 0.6 / extent);
  l.gradient_x_per_m = g * std::cos(direction);
  l.gradient_y_per_m = g * std::sin(direction);
  const int spots = draw.integer(0, 4);
  for (int i = 0; i < spots; ++i) {
    l.spotlights.push_back(
        {draw.uniform(-hl - 1, hl + 1), draw.uniform(-hw - 1, hw + 1), draw.uniform(1.0, 3.0), draw.uniform(0.2, 0.9)});
  }
  if (draw.chance(0.3)) {
    const int shadows = draw.integer(1, 3);
    for (int i = 0; i < shadows; ++i) {
      Shadow s;
      if (draw.chance(0.5)) {  // a strip across the field (a beam, a balcony)
        const double x = draw.uniform(-hl, hl), w = draw.uniform(0.4, 1.5);
        s = {x, -hw - 2, x + w, hw + 2, draw.uniform(0.45, 0.8)};
      } else {
        const double x = draw.uniform(-hl, hl), y = draw.uniform(-hw, hw);
        s = {x, y, x + draw.uniform(1, 3), y + draw.uniform(1, 3), draw.uniform(0.45, 0.8)};
      }
      l.shadows.push_back(s);
    }
  }
  return l;
}

// ---------------------------------------------------------------------------------------------
// Motion and objects

// A smooth path across the field (a Lissajous figure), kept 0.6 m inside the outer lines.
struct Path {
  double cx, cy, ax, ay, omega, phase_x, phase_y, ratio, wobble;
  core::Pose2D at(double t_s) const {
    const double x = cx + ax * std::sin(omega * t_s + phase_x);
    const double y = cy + ay * std::sin(ratio * omega * t_s + phase_y);
    const double vx = ax * omega * std::cos(omega * t_s + phase_x);
    const double vy = ay * ratio * omega * std::cos(ratio * omega * t_s + phase_y);
    return {x, y, wrapAngle(std::atan2(vy, vx) + wobble * std::sin(0.7 * t_s))};
  }
};

Path drawPath(Draw& draw, const core::FieldCalibration& f) {
  const double hl = f.length_m / 2 - 0.6, hw = f.width_m / 2 - 0.6;
  Path p;
  p.cx = draw.uniform(-0.2, 0.2) * hl;
  p.cy = draw.uniform(-0.2, 0.2) * hw;
  p.ax = std::min(draw.uniform(0.3, 0.8) * hl, hl - std::abs(p.cx));
  p.ay = std::min(draw.uniform(0.3, 0.8) * hw, hw - std::abs(p.cy));
  p.ratio = draw.chance(0.5) ? 1.0 : 2.0;
  const double speed = draw.uniform(0.6, 1.6);  // m/s, about
  p.omega = speed / (0.8 * std::hypot(p.ax, p.ratio * p.ay));
  p.phase_x = draw.uniform(-kPi, kPi);
  p.phase_y = draw.uniform(-kPi, kPi);
  p.wobble = draw.uniform(0.0, 0.5);
  return p;
}

std::vector<Person> drawPeople(Draw& draw, const core::FieldCalibration& f, const RendererOptions& o,
                               std::vector<double>* walk_speed) {
  static const std::vector<Eigen::Vector3d> kSkin = {{224, 180, 150}, {196, 150, 112}, {150, 104, 72}, {96, 66, 46}};
  const double carpet_x = f.length_m / 2 + f.margin_m, carpet_y = f.width_m / 2 + f.margin_m;
  const double band = o.hall_wall_distance_m;
  std::vector<Person> people;
  const int n = draw.integer(0, 6);
  for (int i = 0; i < n; ++i) {
    Person p;
    p.radius_m = draw.uniform(0.17, 0.24);
    p.height_m = draw.uniform(1.5, 1.9);
    // Right at the carpet's edge or further out in the band before the wall.
    const double out = draw.chance(0.5) ? draw.uniform(0.02, 0.1) : draw.uniform(0.3, std::max(0.31, band - 0.6));
    double speed = 0.0;
    if (draw.chance(0.6)) {  // beside a side line: may walk along it
      p.y_m = draw.sign() * (carpet_y + p.radius_m + out);
      p.x_m = draw.uniform(-carpet_x, carpet_x);
      if (draw.chance(0.3)) speed = draw.sign() * draw.uniform(0.3, 0.8);
    } else {
      // Behind a goal line: behind the goal's back too, so that nobody stands in front of a goal.
      const double behind = f.length_m / 2 + std::max(f.margin_m, f.goal_depth_m + 0.05);
      p.x_m = draw.sign() * (behind + p.radius_m + out);
      p.y_m = draw.uniform(-carpet_y, carpet_y);
    }
    p.shirt_rgb = draw.chance(0.5)
                      ? o.clutter_palette[draw.integer(0, static_cast<int>(o.clutter_palette.size()) - 1)]
                      : Eigen::Vector3d(draw.uniform(20, 240), draw.uniform(20, 240), draw.uniform(20, 240));
    p.trousers_rgb = draw.chance(0.5)
                         ? draw.grey(25, 80, 6)
                         : Eigen::Vector3d(draw.uniform(30, 70), draw.uniform(40, 80), draw.uniform(70, 130));
    p.skin_rgb = draw.jitter(kSkin[draw.integer(0, static_cast<int>(kSkin.size()) - 1)], 8);
    people.push_back(p);
    walk_speed->push_back(speed);
  }
  return people;
}

double distanceToPoses(double x, double y, const std::vector<core::Pose2D>& poses) {
  double d = 1e9;
  for (const core::Pose2D& p : poses) d = std::min(d, std::hypot(x - p.x_m, y - p.y_m));
  return d;
}

// ---------------------------------------------------------------------------------------------
// Events

enum class Kind { kDarken, kGain, kGamma, kWarm, kBrighten, kTone, kSlow, kAutoExposure, kWrongPose, kDrive, kLocal };

struct Event {
  Kind kind;
  int frame;
  std::string name;
  ToneCurve curve;             // sudden changes
  double factor = 1.0;         // slow change: level multiplier at the ramp's end
  int duration = 0;            // frames of a ramp, a swing, a wrong pose
  double period_frames = 8.0;  // auto exposure
  double settle = 1.0;         // auto exposure's final value
  Shadow zone;                 // a local change: the light of this zone from the event's frame on
};

// Per-frame light level and exposure multipliers and the tone curve of the events so far.
struct Photometry {
  double level = 1.0;
  double exposure = 1.0;
  ToneCurve transfer;
  std::vector<Shadow> zones;  // local changes
};

Photometry photometryAt(const std::vector<Event>& events, int frame) {
  Photometry p;
  for (const Event& e : events) {
    if (frame < e.frame) continue;
    const int t = frame - e.frame;
    switch (e.kind) {
      case Kind::kDarken:
      case Kind::kGain:
      case Kind::kGamma:
      case Kind::kWarm:
      case Kind::kBrighten:
      case Kind::kTone:
        p.transfer = p.transfer.then(e.curve);
        break;
      case Kind::kSlow: {
        double s = std::min(1.0, static_cast<double>(t) / e.duration);
        s = s * s * (3 - 2 * s);  // smoothstep: no kink at the ends of the ramp
        p.level *= 1.0 + (e.factor - 1.0) * s;
        break;
      }
      case Kind::kAutoExposure: {
        // The exposure controller overshoots: 0.7 .. 1.3, decaying towards where it settles.
        if (t < e.duration) {
          const double decay = 1.0 - static_cast<double>(t) / e.duration;
          const double mean = 1.0 + (e.settle - 1.0) * (1.0 - decay);
          p.exposure *= mean + 0.3 * decay * std::sin(2 * kPi * t / e.period_frames + 0.5 * kPi);
        } else {
          p.exposure *= e.settle;
        }
        break;
      }
      case Kind::kLocal:
        p.zones.push_back(e.zone);
        break;
      case Kind::kWrongPose:
      case Kind::kDrive:
        break;
    }
  }
  return p;
}

// `named_kind` in [0, 5): that named sudden change; -1: one of the other kinds.
Event drawEvent(Draw& draw, int frame, int named_kind, bool can_drive, bool can_wrong_pose, ScenarioLength length) {
  Event e;
  e.frame = frame;
  const bool small = length == ScenarioLength::kSmall;
  if (named_kind >= 0) {
    e.kind = static_cast<Kind>(named_kind);
  } else {
    const size_t k = draw.weighted({1.0, 1.0, 1.0, can_wrong_pose ? 0.8 : 0.0, can_drive ? 0.6 : 0.0});
    e.kind = std::vector<Kind>{Kind::kTone, Kind::kSlow, Kind::kAutoExposure, Kind::kWrongPose, Kind::kDrive}[k];
  }
  switch (e.kind) {
    case Kind::kDarken:
      e.name = "darken";  // the paper's brightness and contrast to 50% (3.2)
      e.curve = ToneCurve::brightnessContrast(0.5, 0.5);
      break;
    case Kind::kGain:
      e.name = "gain_0.5";
      e.curve = ToneCurve::gain(Eigen::Vector3d::Constant(0.5));
      break;
    case Kind::kGamma:
      e.name = "gamma_1.6";
      e.curve = ToneCurve::gamma(1.6);
      break;
    case Kind::kWarm:
      e.name = "warm_white_balance";
      e.curve = ToneCurve::whiteBalance(-2000.0);
      break;
    case Kind::kBrighten: {
      e.name = "brighten";
      const double g = draw.uniform(1.5, 1.6);
      e.curve = ToneCurve::gain(Eigen::Vector3d::Constant(g));
      break;
    }
    case Kind::kTone: {
      std::string description;
      e.curve = ToneCurve::random(draw.rng, draw.uniform(0.4, 1.0), &description);
      e.name = "tone:" + description;
      break;
    }
    case Kind::kSlow:
      e.name = "slow_change";
      e.factor = draw.chance(0.5) ? draw.uniform(0.45, 0.7) : draw.uniform(1.35, 1.6);
      e.duration = small ? 30 : 90;
      break;
    case Kind::kAutoExposure:
      e.name = "auto_exposure";
      e.duration = small ? draw.integer(12, 16) : draw.integer(36, 48);
      e.period_frames = draw.uniform(6.0, 10.0);
      e.settle = draw.uniform(0.85, 1.15);
      break;
    case Kind::kWrongPose:
      e.name = "wrong_pose";
      e.duration = small ? draw.integer(8, 14) : draw.integer(24, 40);
      break;
    case Kind::kDrive:
      e.name = "drive";
      break;
    case Kind::kLocal:  // made from a sudden change by localChange
      break;
  }
  return e;
}

// A sudden change made local (LightEvents::kLocal): the light beyond a line across the field, on
// everything there, multiplied by 0.25-0.6 (lamps over one part off, a window's sun gone) or by
// 1.4-1.8 (the sun out), from the event's frame on. The line lies within the middle 60% of the
// field along x or y; the zone reaches beyond the hall on its side.
Event localChange(Draw& draw, const Event& sudden, const core::FieldCalibration& f) {
  Event e = sudden;
  e.kind = Kind::kLocal;
  const bool along_x = draw.chance(0.5);
  const int side = draw.sign();
  const double half = (along_x ? f.length_m : f.width_m) / 2;
  const double line = draw.uniform(-0.3, 0.3) * 2 * half;
  const double factor = draw.chance(0.6) ? draw.uniform(0.25, 0.6) : draw.uniform(1.4, 1.8);
  constexpr double kFar = 1e3;
  e.zone = Shadow{-kFar, -kFar, kFar, kFar, factor, /*floor_only=*/false};
  // The line is the zone's one near edge.
  (along_x ? (side > 0 ? e.zone.x_min_m : e.zone.x_max_m) : (side > 0 ? e.zone.y_min_m : e.zone.y_max_m)) = line;
  char text[64];
  std::snprintf(text, sizeof(text), "local:%c%c%.1f*%.2f", along_x ? 'x' : 'y', side > 0 ? '>' : '<', line,
                e.zone.factor);
  e.name = text;
  return e;
}

// A pose 2.5 m from `truth` rotated by 165 degrees (paper, 3.3), in a direction that keeps it on
// the carpet for all poses of the window.
double wrongPoseDirection(Draw& draw, const std::vector<core::Pose2D>& truths, const core::FieldCalibration& f) {
  const double lx = f.length_m / 2 + f.margin_m - 0.2, ly = f.width_m / 2 + f.margin_m - 0.2;
  const double start = draw.uniform(-kPi, kPi);
  double best = start, best_excess = 1e9;
  for (int k = 0; k < 24; ++k) {
    const double a = start + 2 * kPi * k / 24;
    double excess = 0.0;
    for (const core::Pose2D& p : truths) {
      const double x = p.x_m + kWrongPoseDistanceM * std::cos(a), y = p.y_m + kWrongPoseDistanceM * std::sin(a);
      excess = std::max({excess, std::abs(x) - lx, std::abs(y) - ly});
    }
    if (excess <= 0.0) return a;
    if (excess < best_excess) {
      best_excess = excess;
      best = a;
    }
  }
  return best;
}

}  // namespace

const std::vector<std::string>& familyEventKinds() {
  static const std::vector<std::string> kKinds = {"darken",     "gain_0.5", "gamma_1.6",   "warm_white_balance",
                                                  "brighten",   "tone",     "slow_change", "auto_exposure",
                                                  "wrong_pose", "drive",    "local"};
  return kKinds;
}

std::string familyEventKind(const std::string& event) { return event.substr(0, event.find(':')); }

bool isNamedToneChange(const std::string& event) {
  const std::string kind = familyEventKind(event);
  const auto& kinds = familyEventKinds();
  return std::find(kinds.begin(), kinds.begin() + 5, kind) != kinds.begin() + 5;
}

bool isSuddenChange(const std::string& event) {
  const std::string kind = familyEventKind(event);
  return isNamedToneChange(event) || kind == "tone" || kind == "local";
}

FamilyScene makeFamilyScene(uint32_t seed, ScenarioLength length, bool ball_looks, LightEvents light_events) {
  Draw draw(seed);
  FamilyScene out;
  out.seed = seed;
  const bool small = length == ScenarioLength::kSmall;

  // Camera, field, hall and materials.
  CameraDraw camera_info;
  out.calibration.camera = drawCamera(draw, largeImageScene(seed), &camera_info);
  out.calibration.field = drawField(draw);
  core::validateCalibration(out.calibration, "family scene " + std::to_string(seed));
  const core::FieldCalibration& field = out.calibration.field;
  RendererOptions& options = out.renderer;
  options.hall_seed = seed * 2654435761u + 17u;
  drawLooks(draw, &options);
  const std::string ball_kind = ball_looks ? drawBallLooks(seed, &options) : "orange";
  options.struts = drawStruts(draw, out.calibration.camera);
  const Lighting base_light = drawLighting(draw, field);

  // Frames and events: the first event after the adaptation span, each event followed by one.
  const int before_min = small ? kSmallBefore : kFullBefore, after_min = small ? kSmallAfter : kFullAfter;
  const int n_events = 1 + static_cast<int>(draw.weighted(small ? std::vector<double>{0.55, 0.45}
                                                                : std::vector<double>{0.35, 0.35, 0.3}));
  const int lo = small ? 40 : 120, hi = small ? 60 : 180;
  const int total = draw.integer(std::max(lo, before_min + after_min * n_events), hi);
  std::vector<int> event_frames;
  {
    // Spread the slack over the span before the first event and after each.
    const int slack = total - before_min - after_min * n_events;
    std::vector<double> share(n_events + 1);
    double sum = 0.0;
    for (double& s : share) sum += (s = draw.uniform(0.1, 1.0));
    int frame = 0;
    for (int i = 0; i < n_events; ++i) {
      frame += (i == 0 ? before_min : after_min) + static_cast<int>(std::floor(slack * share[i] / sum));
      event_frames.push_back(frame);
    }
  }

  // Motion: static, driving all along, or static until a "drive" event.
  const bool driving_from_start = draw.chance(0.3);
  const Path path = drawPath(draw, field);
  const double static_heading = draw.uniform(-kPi, kPi);

  std::vector<Event> events;
  bool has_drive = driving_from_start, has_wrong_pose = false;
  // Every even seed has one named sudden change, the kinds in turn (seed / 2 % 5): half the scenes,
  // each kind in any ten consecutive seeds. Odd seeds and the other events draw from the rest.
  const int named_slot = seed % 2 == 0 ? draw.integer(0, n_events - 1) : -1;
  for (int i = 0; i < n_events; ++i) {
    const bool named = i == named_slot;
    Event e = drawEvent(draw, event_frames[i], named ? static_cast<int>(seed / 2 % 5) : -1, !has_drive, !has_wrong_pose,
                        length);
    has_drive |= e.kind == Kind::kDrive;
    has_wrong_pose |= e.kind == Kind::kWrongPose;
    events.push_back(e);
    // Sometimes the robot starts driving at the same moment (1-3 events per scene).
    if (!has_drive && e.kind != Kind::kWrongPose && draw.chance(0.2)) {
      Event d;
      d.kind = Kind::kDrive;
      d.frame = e.frame;
      d.name = "drive";
      events.push_back(d);
      has_drive = true;
    }
  }
  if (light_events == LightEvents::kLocal) {
    // From a generator of its own: the scene is otherwise the global one's.
    Draw local(seed * 2246822519u + 0x10ca1u);
    for (Event& e : events) {
      if (e.kind <= Kind::kTone) e = localChange(local, e, field);  // the five named changes and tone curves
    }
  }
  int drive_start = driving_from_start ? 0 : total;
  for (const Event& e : events) {
    if (e.kind == Kind::kDrive) drive_start = e.frame;
  }

  // True poses.
  constexpr double kFrameRateHz = 30.0;
  std::vector<core::Pose2D> truth(total);
  for (int i = 0; i < total; ++i) {
    const double t = std::max(0, i - drive_start) / kFrameRateHz;
    truth[i] = path.at(t);
    if (i < drive_start && !driving_from_start) truth[i].theta_rad = static_heading;
  }
  // Told poses: exact while static, a few cm of localization noise while driving, and wrong in
  // the wrong-pose window.
  std::vector<core::Pose2D> told = truth;
  std::normal_distribution<double> position_noise(0.0, 0.03), angle_noise(0.0, 0.01);
  for (int i = 0; i < total; ++i) {
    if (i < drive_start) continue;
    told[i].x_m += position_noise(draw.rng);
    told[i].y_m += position_noise(draw.rng);
    told[i].theta_rad = wrapAngle(told[i].theta_rad + angle_noise(draw.rng));
  }
  for (const Event& e : events) {
    if (e.kind != Kind::kWrongPose) continue;
    const int end = std::min(total, e.frame + e.duration);
    const std::vector<core::Pose2D> window(truth.begin() + e.frame, truth.begin() + end);
    const double a = wrongPoseDirection(draw, window, field);
    for (int i = e.frame; i < end; ++i) {
      told[i] = wrongPose(truth[i], a);
    }
  }

  // Other robots, clear of every own pose and of each other.
  const double hl = field.length_m / 2, hw = field.width_m / 2;
  std::vector<RobotObstacle> robots;
  const int n_robots = draw.integer(2, 6);
  for (int attempt = 0; attempt < 200 && static_cast<int>(robots.size()) < n_robots; ++attempt) {
    RobotObstacle r;
    r.radius_m = draw.uniform(0.2, 0.28);
    r.height_m = draw.uniform(0.5, 0.85);
    r.x_m = draw.uniform(-hl + 0.3, hl - 0.3);
    r.y_m = draw.uniform(-hw + 0.3, hw - 0.3);
    if (distanceToPoses(r.x_m, r.y_m, truth) < kMinRobotDistanceM) continue;
    bool clear = true;
    for (const RobotObstacle& o : robots) clear = clear && std::hypot(r.x_m - o.x_m, r.y_m - o.y_m) > 0.7;
    if (clear) robots.push_back(r);
  }
  // The ball, lying or rolling slowly.
  std::optional<Ball> ball;
  double ball_vx = 0.0, ball_vy = 0.0;
  if (draw.chance(0.55)) {
    const bool rolling = draw.chance(0.4);
    auto clear = [&](const Ball& b, double vx, double vy) {
      bool ok = true;
      for (int i = 0; i < total && ok; ++i) {
        const double x = b.x_m + vx * i / kFrameRateHz, y = b.y_m + vy * i / kFrameRateHz;
        ok = std::hypot(x - truth[i].x_m, y - truth[i].y_m) >= kMinBallDistanceM && std::abs(x) < hl + 0.2 &&
             std::abs(y) < hw + 0.2;
        for (const RobotObstacle& r : robots) ok = ok && std::hypot(x - r.x_m, y - r.y_m) > r.radius_m + 0.15;
      }
      return ok;
    };
    for (int attempt = 0; attempt < 100 && !ball; ++attempt) {
      Ball b{draw.uniform(-hl + 0.3, hl - 0.3), draw.uniform(-hw + 0.3, hw - 0.3), draw.uniform(0.1, 0.12)};
      const double vx = rolling ? draw.uniform(-0.4, 0.4) : 0.0, vy = rolling ? draw.uniform(-0.4, 0.4) : 0.0;
      if (clear(b, vx, vy)) {
        ball = b;
        ball_vx = vx;
        ball_vy = vy;
      }
    }
    // Partly hidden (with the ball looks): in a quarter of the scenes the ball lies just behind a
    // robot as seen from the first pose (its own generator: the rest of the scene stays as it was).
    Draw hide(seed * 2246822519u + 0x41deu);
    if (ball_looks && ball && !robots.empty() && hide.chance(0.25)) {
      const RobotObstacle& r = robots[static_cast<size_t>(hide.integer(0, static_cast<int>(robots.size()) - 1))];
      const double dx = r.x_m - truth[0].x_m, dy = r.y_m - truth[0].y_m, d = std::hypot(dx, dy);
      const double behind = r.radius_m + hide.uniform(0.17, 0.3);
      const double side = hide.sign() * r.radius_m * hide.uniform(0.6, 1.0);  // the ball shows beside it
      Ball b{r.x_m + (dx * behind - dy * side) / d, r.y_m + (dy * behind + dx * side) / d, ball->radius_m};
      if (d > 0 && clear(b, 0.0, 0.0)) {
        ball = b;
        ball_vx = ball_vy = 0.0;
      }
    }
  }
  std::vector<double> walk_speed;
  const std::vector<Person> people = drawPeople(draw, field, options, &walk_speed);
  const double walk_limit = hl + field.margin_m + options.hall_wall_distance_m - 0.5;

  // The frames.
  Scenario& s = out.scenario;
  s.name = "family_" + std::to_string(seed);
  s.frame_rate_hz = kFrameRateHz;
  std::string event_text;
  for (int i = 0; i < total; ++i) {
    ScenarioFrame f;
    f.scene.robot_pose = truth[i];
    f.told_pose = told[i];
    f.scene.robots = robots;
    if (ball) {
      Ball b = *ball;
      b.x_m += ball_vx * i / kFrameRateHz;
      b.y_m += ball_vy * i / kFrameRateHz;
      f.scene.ball = b;
    }
    f.scene.people = people;
    for (size_t k = 0; k < people.size(); ++k) {
      if (walk_speed[k] == 0.0) continue;
      // Back and forth along the side line (a triangle wave in x).
      const double span = 2 * walk_limit;
      double x = std::fmod(people[k].x_m + walk_limit + walk_speed[k] * i / kFrameRateHz, 2 * span);
      if (x < 0) x += 2 * span;
      f.scene.people[k].x_m = (x < span ? x : 2 * span - x) - walk_limit;
    }
    const Photometry p = photometryAt(events, i);
    f.scene.lighting = base_light;
    f.scene.lighting.level *= p.level;
    f.scene.lighting.exposure *= p.exposure;
    f.scene.lighting.transfer = p.transfer;
    f.scene.lighting.shadows.insert(f.scene.lighting.shadows.end(), p.zones.begin(), p.zones.end());
    f.scene.noise_seed = seed * 100003u + static_cast<uint32_t>(i) * 7919u + 1u;
    for (const Event& e : events) {
      if (e.frame == i) {
        f.events.push_back(e.name);
        event_text += " " + e.name + "@" + std::to_string(i);
      }
    }
    s.frames.push_back(f);
  }

  const core::CameraCalibration& c = out.calibration.camera;
  char text[512];
  std::snprintf(
      text, sizeof(text),
      "family %u: %dx%d %s mirror r=%.0f px h=%.2f m, field %.1fx%.1f m, hall %.1f m, %zu struts, %zu people, "
      "%zu robots%s, noise %.1f, %s, %d frames, events:%s",
      seed, c.width, c.height, camera_info.profile.c_str(), c.mirror_radius_px, c.height_m, field.length_m,
      field.width_m, options.hall_wall_distance_m, options.struts.size(), people.size(), robots.size(),
      ball ? (", " + ball_kind + " ball").c_str() : "", base_light.noise_sigma,
      driving_from_start ? "driving" : (drive_start < total ? "static then driving" : "static"), total,
      event_text.c_str());
  out.summary = text;
  s.description = out.summary;
  return out;
}

}  // namespace sim
}  // namespace act_color
