#include "act_color/sim/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace act_color {
namespace sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Closest distance of another robot's or the ball's centre to the own robot's centre.
constexpr double kMinRobotDistanceM = 0.9;
constexpr double kMinBallDistanceM = 0.5;

using core::wrapAngle;

// Frame counts per length: (frames before the event, total).
struct Counts {
  int before;
  int total;
};
Counts counts(ScenarioLength length, Counts small, Counts full) {
  return length == ScenarioLength::kSmall ? small : full;
}

// Pushes (x, y) out of the disk of radius `min_distance` around (cx, cy).
void keepAway(double cx, double cy, double min_distance, double* x, double* y) {
  const double dx = *x - cx, dy = *y - cy;
  const double d = std::hypot(dx, dy);
  if (d >= min_distance) return;
  const double ux = d > 1e-9 ? dx / d : 1.0, uy = d > 1e-9 ? dy / d : 0.0;
  *x = cx + ux * min_distance;
  *y = cy + uy * min_distance;
}

// Other robots and the ball, kept clear of the own robot.
void placeObjects(Scene* scene, const std::vector<RobotObstacle>& robots, const Ball* ball) {
  scene->robots = robots;
  for (RobotObstacle& r : scene->robots) {
    keepAway(scene->robot_pose.x_m, scene->robot_pose.y_m, kMinRobotDistanceM, &r.x_m, &r.y_m);
  }
  if (ball) {
    Ball b = *ball;
    keepAway(scene->robot_pose.x_m, scene->robot_pose.y_m, kMinBallDistanceM, &b.x_m, &b.y_m);
    scene->ball = b;
  }
}

uint32_t noiseSeed(uint32_t seed, int frame) { return seed * 100003u + static_cast<uint32_t>(frame) * 7919u + 1u; }

std::vector<RobotObstacle> staticRobots() {
  return {{1.6, 2.1, 0.25, 0.8}, {-4.2, -2.4, 0.25, 0.8}, {3.4, -1.8, 0.25, 0.8}, {-1.0, 3.6, 0.25, 0.8}};
}

Scenario staticChange(const std::string& name, ScenarioLength length, uint32_t seed, bool brighten) {
  Scenario s;
  s.name = name;
  const Counts c = counts(length, {8, 32}, {90, 300});
  s.description = brighten ? "static robot; the light level jumps from 0.6 to 1.3"
                           : "static robot; brightness and contrast drop to 50% (paper, 3.2)";
  const core::Pose2D pose{-1.5, 1.0, 0.4};
  for (int i = 0; i < c.total; ++i) {
    ScenarioFrame f;
    f.scene.robot_pose = pose;
    f.told_pose = pose;
    // The ball rolls slowly so that frames are not identical but for noise.
    const double t = i / s.frame_rate_hz;
    const Ball ball{0.6 + 0.25 * t, -0.4 + 0.1 * t, 0.11};
    placeObjects(&f.scene, staticRobots(), &ball);
    f.scene.noise_seed = noiseSeed(seed, i);
    const bool after = i >= c.before;
    if (brighten) {
      f.scene.lighting.level = after ? 1.3 : 0.6;
      if (i == c.before) f.events.push_back("brighten");
    } else {
      f.scene.lighting.brightness_contrast = after ? 0.5 : 1.0;
      if (i == c.before) f.events.push_back("darken");
    }
    s.frames.push_back(f);
  }
  return s;
}

Scenario wrongPose(ScenarioLength length, uint32_t seed) {
  Scenario s;
  s.name = "wrong_pose";
  s.description =
      "frames cycle over known poses A, B and a pose 2.5 m from B rotated by 165 degrees, while ACT is told B "
      "(paper, 3.3)";
  const int total = length == ScenarioLength::kSmall ? 30 : 300;
  const core::Pose2D a{-2.0, 0.5, 0.0};
  const core::Pose2D b{1.0, -1.5, 1.2};
  const double direction = 2.1;  // where the true pose lies, seen from B
  const core::Pose2D c = sim::wrongPose(b, direction);
  const Ball ball{-0.5, -0.9, 0.11};
  for (int i = 0; i < total; ++i) {
    ScenarioFrame f;
    const int phase = i % 3;
    f.scene.robot_pose = phase == 0 ? a : phase == 1 ? b : c;
    f.told_pose = phase == 0 ? a : b;
    // One event where the wrong poses begin: a change of condition, not of light, so the run is
    // one segment from there on (act_replay's adapted figures need segments of some length).
    if (i == 2) f.events.push_back("wrong_pose");
    placeObjects(&f.scene, staticRobots(), &ball);
    f.scene.noise_seed = noiseSeed(seed, i);
    s.frames.push_back(f);
  }
  return s;
}

// Self-localization is never exact: a few centimetres and a fraction of a degree.
core::Pose2D localizationNoise(const core::Pose2D& truth, std::mt19937& rng) {
  std::normal_distribution<double> position(0.0, 0.03), angle(0.0, 0.01);
  return {truth.x_m + position(rng), truth.y_m + position(rng), wrapAngle(truth.theta_rad + angle(rng))};
}

Scenario driving(ScenarioLength length, const core::Calibration& cal, uint32_t seed) {
  Scenario s;
  s.name = "driving";
  s.description =
      "robot drives a figure-eight across the field among moving robots and the ball; light level and "
      "color temperature vary slowly";
  const int total = length == ScenarioLength::kSmall ? 48 : 450;
  const double hl = cal.field.length_m / 2, hw = cal.field.width_m / 2;
  std::mt19937 rng(seed);
  const double omega = 0.25;  // rad/s along the figure-eight: about 1.5 m/s
  // Other robots circle slowly around their home positions.
  struct Mover {
    double x, y, radius, omega, phase;
  };
  const std::vector<Mover> movers = {{2.5, 2.0, 1.2, 0.35, 0.0},
                                     {-3.0, -2.0, 1.5, -0.3, 1.0},
                                     {5.0, -3.0, 1.0, 0.4, 2.0},
                                     {-5.5, 2.5, 1.3, 0.25, 3.0},
                                     {6.5, 1.0, 0.8, -0.45, 4.0}};
  double ball_x = 1.0, ball_y = -1.0, ball_vx = 0.9, ball_vy = 0.6;
  for (int i = 0; i < total; ++i) {
    const double t = i / s.frame_rate_hz;
    ScenarioFrame f;
    const double x = 0.62 * hl * std::sin(omega * t), y = 0.5 * hw * std::sin(2 * omega * t);
    const double vx = 0.62 * hl * omega * std::cos(omega * t), vy = 0.5 * hw * 2 * omega * std::cos(2 * omega * t);
    f.scene.robot_pose = {x, y, wrapAngle(std::atan2(vy, vx) + 0.4 * std::sin(0.5 * t))};
    f.told_pose = localizationNoise(f.scene.robot_pose, rng);
    std::vector<RobotObstacle> robots;
    for (const Mover& m : movers) {
      robots.push_back({m.x + m.radius * std::cos(m.omega * t + m.phase),
                        m.y + m.radius * std::sin(m.omega * t + m.phase), 0.25, 0.8});
    }
    // The ball rolls and bounces off the outer lines.
    ball_x += ball_vx / s.frame_rate_hz;
    ball_y += ball_vy / s.frame_rate_hz;
    if (std::abs(ball_x) > hl - 0.5) ball_vx = -ball_vx;
    if (std::abs(ball_y) > hw - 0.5) ball_vy = -ball_vy;
    const Ball ball{ball_x, ball_y, 0.11};
    placeObjects(&f.scene, robots, &ball);
    Lighting& l = f.scene.lighting;
    l.level = 1.0 + 0.25 * std::sin(2 * kPi * t / 12.0);
    l.color_temperature_k = 5500.0 + 1200.0 * std::sin(2 * kPi * t / 17.0 + 1.0);
    l.gradient_x_per_m = 0.02;
    l.gradient_y_per_m = -0.01;
    f.scene.noise_seed = noiseSeed(seed, i);
    s.frames.push_back(f);
  }
  return s;
}

Scenario spotlights(ScenarioLength length, const core::Calibration& cal, uint32_t seed) {
  Scenario s;
  s.name = "spotlights";
  s.description = "strong spotlights and hard shadows on a dim field; the robot drives through them";
  const int total = length == ScenarioLength::kSmall ? 40 : 360;
  const double hl = cal.field.length_m / 2, hw = cal.field.width_m / 2;
  std::mt19937 rng(seed + 17);
  Lighting base;
  base.level = 0.55;
  base.gradient_x_per_m = 0.03;
  base.spotlights = {{-4.0, -1.0, 1.6, 1.4}, {-0.5, 0.8, 2.0, 1.1}, {3.0, -0.5, 1.3, 1.6}, {5.5, 2.5, 2.2, 1.0}};
  base.shadows = {
      {-2.5, -hw - 1.0, -1.6, hw + 1.0, 0.45}, {1.2, -hw - 1.0, 1.9, hw + 1.0, 0.5}, {-6.0, 1.5, -3.0, 3.0, 0.4}};
  const double speed = 1.2;  // m/s along the back-and-forth path
  const double ax = -0.7 * hl, ay = -0.25 * hw, bx = 0.7 * hl, by = 0.25 * hw;
  const double path = std::hypot(bx - ax, by - ay);
  for (int i = 0; i < total; ++i) {
    const double t = i / s.frame_rate_hz;
    double d = std::fmod(speed * t, 2 * path);
    const bool back = d > path;
    if (back) d = 2 * path - d;
    const double x = ax + (bx - ax) * d / path, y = ay + (by - ay) * d / path;
    ScenarioFrame f;
    f.scene.robot_pose = {x, y, wrapAngle(0.3 * t + (back ? kPi : 0.0))};
    f.told_pose = localizationNoise(f.scene.robot_pose, rng);
    const Ball ball{x + 1.5, y + 0.4, 0.11};
    placeObjects(&f.scene, staticRobots(), &ball);
    f.scene.lighting = base;
    f.scene.noise_seed = noiseSeed(seed, i);
    s.frames.push_back(f);
  }
  return s;
}

}  // namespace

core::Pose2D wrongPose(const core::Pose2D& from, double direction_rad) {
  return {from.x_m + kWrongPoseDistanceM * std::cos(direction_rad),
          from.y_m + kWrongPoseDistanceM * std::sin(direction_rad),
          core::wrapAngle(from.theta_rad + kWrongPoseRotationRad)};
}

const std::vector<std::string>& scenarioNames() {
  static const std::vector<std::string> kNames = {"static_darkening", "wrong_pose", "driving", "spotlights",
                                                  "sudden_brightening"};
  return kNames;
}

bool parseScenarioLength(const std::string& text, ScenarioLength* length) {
  if (text == "small") {
    *length = ScenarioLength::kSmall;
    return true;
  }
  if (text == "full") {
    *length = ScenarioLength::kFull;
    return true;
  }
  return false;
}

Scenario makeScenario(const std::string& name, ScenarioLength length, const core::Calibration& calibration,
                      uint32_t seed) {
  if (name == "static_darkening") return staticChange(name, length, seed, false);
  if (name == "sudden_brightening") return staticChange(name, length, seed, true);
  if (name == "wrong_pose") return wrongPose(length, seed);
  if (name == "driving") return driving(length, calibration, seed);
  if (name == "spotlights") return spotlights(length, calibration, seed);
  std::string known;
  for (const std::string& n : scenarioNames()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown scenario '" + name + "' (known: " + known + ")");
}

}  // namespace sim
}  // namespace act_color
