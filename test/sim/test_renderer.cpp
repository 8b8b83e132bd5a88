#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <random>

#include "act_color/core/expected_class_model.hpp"
#include "act_color/sim/renderer.hpp"
#include "sim_test_util.hpp"

namespace act_color {
namespace {

using core::Pose2D;
using sim::LabeledFrame;
using sim::Renderer;
using sim::Scene;
using sim_test::fieldToBase;

struct Pixel {
  int u, v;
};

// Pixel that sees the field point (x, y, z) from the robot at `pose`; false when not imaged.
bool projectFieldPoint(const core::OmniCameraModel& camera, const Pose2D& pose, double x, double y, double z,
                       Pixel* px) {
  double bx, by;
  fieldToBase(pose, x, y, &bx, &by);
  double u, v;
  const bool ok = z == 0.0
                      ? camera.projectFloorPoint(bx, by, &u, &v)
                      : camera.projectDirection(std::atan2(by, bx),
                                                std::atan2(z - camera.viewpointHeight(), std::hypot(bx, by)), &u, &v);
  if (!ok) return false;
  px->u = static_cast<int>(std::lround(u));
  px->v = static_cast<int>(std::lround(v));
  return px->u >= 0 && px->v >= 0 && px->u < camera.width() && px->v < camera.height();
}

cv::Vec3b colorAt(const LabeledFrame& f, const Pixel& p) { return f.rgb.at<cv::Vec3b>(p.v, p.u); }
int labelAt(const LabeledFrame& f, const Pixel& p) { return f.labels.at<uint8_t>(p.v, p.u); }

class RendererTest : public ::testing::TestWithParam<int> {
 protected:
  core::Calibration calibration() const {
    return GetParam() == 0 ? sim_test::defaultCalibration() : sim_test::contractCalibration();
  }
};

// A floor point projects where the camera model says: at OmniCameraModel::projectFloorPoint of a
// point on a line the truth is white and the pixel bright; at a carpet point green and greenish.
TEST_P(RendererTest, FloorPointsAppearWhereTheCameraModelProjectsThem) {
  const Renderer renderer(calibration());
  const auto& camera = renderer.model().camera();
  const auto& field = renderer.model().field();
  Scene scene;
  scene.robot_pose = {-1.0, 0.5, 0.3};
  scene.lighting = sim_test::cleanLighting();
  const LabeledFrame frame = renderer.render(scene);

  Pixel line, carpet;
  ASSERT_TRUE(projectFieldPoint(camera, scene.robot_pose, 0.0, -1.0, 0.0, &line));  // halfway line
  ASSERT_TRUE(projectFieldPoint(camera, scene.robot_pose, -2.0, -1.5, 0.0, &carpet));
  EXPECT_EQ(labelAt(frame, line), core::kWhite);
  EXPECT_EQ(labelAt(frame, carpet), core::kGreen);
  const cv::Vec3b w = colorAt(frame, line), g = colorAt(frame, carpet);
  EXPECT_GT(w[0] + w[1] + w[2], 450);
  EXPECT_LT(w[0] + w[1] + w[2], 3 * 250) << "white lines are not pure white under normal light";
  EXPECT_GT(g[1], g[0] + 40);
  EXPECT_GT(g[1], g[2] + 40);

  // Many random floor points away from class boundaries: truth equals the field model's class.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ux(-field.halfLength() - 0.8, field.halfLength() + 0.8);
  std::uniform_real_distribution<double> uy(-field.halfWidth() - 0.8, field.halfWidth() + 0.8);
  int checked = 0, white = 0;
  for (int n = 0; n < 4000; ++n) {
    const double x = ux(rng), y = uy(rng);
    double bx, by;
    fieldToBase(scene.robot_pose, x, y, &bx, &by);
    if (std::hypot(bx, by) > 4.0 || std::abs(x) > field.halfLength() - 0.3) continue;  // near: footprint < 3 cm
    const uint8_t k = field.floorClass(x, y);
    bool uniform = true;
    for (double dx : {-0.05, 0.0, 0.05})
      for (double dy : {-0.05, 0.0, 0.05}) uniform = uniform && field.floorClass(x + dx, y + dy) == k;
    if (!uniform) continue;
    Pixel p;
    if (!projectFieldPoint(camera, scene.robot_pose, x, y, 0.0, &p)) continue;
    if (camera.ray(p.u, p.v).region != core::PixelRegion::kFloor) continue;
    EXPECT_EQ(labelAt(frame, p), k) << "field point (" << x << ", " << y << ")";
    ++checked;
    if (k == core::kWhite) ++white;
  }
  EXPECT_GT(checked, 300);
  EXPECT_GT(white, 3);
}

// With nothing on the field but the goals, every pixel's truth is the model's geometric class.
TEST_P(RendererTest, TruthEqualsTheGeometricClassOnAnEmptyField) {
  const Renderer renderer(calibration());
  const core::ExpectedClassModel& model = renderer.model();
  const double hl = model.field().halfLength();
  for (const Pose2D& pose : std::vector<Pose2D>{
           {0.0, 0.0, 0.0}, {-1.5, 1.0, 0.4}, {hl - 1.0, 0.3, 2.8}, {-hl + 0.6, -0.5, -1.2}, {3.0, -5.5, 1.0}}) {
    Scene scene;
    scene.robot_pose = pose;
    const LabeledFrame frame = renderer.render(scene);
    const core::PoseTransform transform(pose);
    size_t mismatches = 0, goal_pixels = 0;
    for (size_t i = 0; i < model.camera().rays().size(); ++i) {
      const uint8_t expected = model.geometricClass(i, transform);
      if (frame.labels.data[i] != expected) ++mismatches;
      if (expected == core::kYellow || expected == core::kBlue) ++goal_pixels;
    }
    EXPECT_EQ(mismatches, 0u) << "pose " << pose.x_m << ", " << pose.y_m << ", " << pose.theta_rad;
    EXPECT_GT(goal_pixels, 50u);
  }
}

// The goals: the centre of each goal's mouth is goal-colored and labelled where the model says.
TEST_P(RendererTest, GoalsAppearWhereTheModelSays) {
  const Renderer renderer(calibration());
  const auto& camera = renderer.model().camera();
  const auto& field = renderer.model().field();
  Scene scene;
  scene.robot_pose = {-2.0, 1.0, 2.0};
  scene.lighting = sim_test::cleanLighting();
  const LabeledFrame frame = renderer.render(scene);
  for (core::ColorClass goal : {core::kYellow, core::kBlue}) {
    Eigen::Vector3d lo, hi;
    field.goalBox(goal, &lo, &hi);
    // The face towards the field, a little inside the box so that the projection cannot miss it.
    const double x_face = std::abs(lo.x()) < std::abs(hi.x()) ? lo.x() : hi.x();
    Pixel p;
    ASSERT_TRUE(projectFieldPoint(camera, scene.robot_pose, x_face, 0.0, 0.45 * hi.z(), &p));
    EXPECT_EQ(labelAt(frame, p), goal);
    const cv::Vec3b c = colorAt(frame, p);
    if (goal == core::kYellow) {
      EXPECT_GT(c[0], 150);
      EXPECT_GT(c[1], 120);
      EXPECT_LT(c[2], 90);
    } else {
      EXPECT_GT(c[2], c[0] + 80);
      EXPECT_GT(c[2], c[1] + 50);
    }
  }
}

// Other robots are black (5), the ball orange (6); elsewhere truth stays the model's class.
TEST_P(RendererTest, RobotsAndBallAreLabelledWhereTheyStand) {
  const Renderer renderer(calibration());
  const auto& camera = renderer.model().camera();
  Scene scene;
  scene.robot_pose = {0.5, -0.5, 0.7};
  scene.lighting = sim_test::cleanLighting();
  scene.robots = {{2.0, 0.5, 0.25, 0.8}, {-1.5, -2.0, 0.25, 0.8}};
  scene.ball = sim::Ball{0.0, 1.0, 0.11};
  const LabeledFrame frame = renderer.render(scene);
  for (const auto& r : scene.robots) {
    Pixel p;
    ASSERT_TRUE(projectFieldPoint(camera, scene.robot_pose, r.x_m, r.y_m, 0.4, &p));
    EXPECT_EQ(labelAt(frame, p), core::kBlack);
    const cv::Vec3b c = colorAt(frame, p);
    EXPECT_LT(c[0] + c[1] + c[2], 3 * 80);
  }
  Pixel b;
  ASSERT_TRUE(projectFieldPoint(camera, scene.robot_pose, scene.ball->x_m, scene.ball->y_m, scene.ball->radius_m, &b));
  EXPECT_EQ(labelAt(frame, b), core::kOrange);
  const cv::Vec3b c = colorAt(frame, b);
  EXPECT_GT(c[0], c[1] + 50);
  EXPECT_GT(c[1], c[2] + 20);

  // Where no object is, truth equals the empty field's; objects cover a plausible area.
  Scene empty = scene;
  empty.robots.clear();
  empty.ball.reset();
  const LabeledFrame base = renderer.render(empty);
  const core::PoseTransform transform(scene.robot_pose);
  size_t black = 0, orange = 0, other = 0;
  for (size_t i = 0; i < camera.rays().size(); ++i) {
    const uint8_t k = frame.labels.data[i];
    if (k == base.labels.data[i]) continue;
    if (k == core::kBlack) {
      ++black;
    } else if (k == core::kOrange) {
      ++orange;
    } else {
      ++other;
    }
    EXPECT_EQ(base.labels.data[i], renderer.model().geometricClass(i, transform));
  }
  EXPECT_EQ(other, 0u);
  EXPECT_GT(black, 500u);
  EXPECT_GT(orange, 30u);
}

INSTANTIATE_TEST_SUITE_P(Calibrations, RendererTest, ::testing::Values(0, 1));

Scene busyScene() {
  Scene scene;
  scene.robot_pose = {1.0, 2.0, -0.6};
  scene.robots = {{3.0, 2.5, 0.25, 0.8}, {-1.0, 0.0, 0.25, 0.8}};
  scene.ball = sim::Ball{2.0, 1.0, 0.11};
  scene.lighting.spotlights = {{0.0, 0.0, 2.0, 1.0}};
  scene.lighting.shadows = {{-1.0, 1.0, 0.5, 4.0, 0.5}};
  scene.lighting.gradient_x_per_m = 0.03;
  scene.lighting.color_temperature_k = 4000;
  scene.noise_seed = 11;
  return scene;
}

TEST(Renderer, IsDeterministicAndNoiseFollowsTheSeed) {
  const core::Calibration cal = sim_test::defaultCalibration();
  const Renderer a(cal), b(cal);
  const Scene scene = busyScene();
  const LabeledFrame f1 = a.render(scene), f2 = a.render(scene), f3 = b.render(scene);
  EXPECT_EQ(cv::norm(f1.rgb, f2.rgb, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(f1.labels, f2.labels, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(f1.rgb, f3.rgb, cv::NORM_INF), 0.0);
  Scene other = scene;
  other.noise_seed = 12;
  const LabeledFrame f4 = a.render(other);
  EXPECT_GT(cv::norm(f1.rgb, f4.rgb, cv::NORM_L1), 1e5);
  EXPECT_EQ(cv::norm(f1.labels, f4.labels, cv::NORM_INF), 0.0);
  // Another hall: same field, different clutter.
  const LabeledFrame f5 = Renderer(cal, 8).render(scene);
  EXPECT_GT(cv::norm(f1.rgb, f5.rgb, cv::NORM_L1), 1e5);
}

double meanIntensity(const LabeledFrame& f) {
  double sum = 0.0;
  size_t n = 0;
  for (int v = 0; v < f.rgb.rows; ++v) {
    for (int u = 0; u < f.rgb.cols; ++u) {
      if (f.labels.at<uint8_t>(v, u) == core::kNotImaged) continue;
      const cv::Vec3b c = f.rgb.at<cv::Vec3b>(v, u);
      sum += c[0] + c[1] + c[2];
      ++n;
    }
  }
  return sum / (3.0 * n);
}

TEST(Renderer, DarkeningHalvesTheMeanIntensity) {
  const Renderer renderer(sim_test::defaultCalibration());
  Scene scene = busyScene();
  const double normal = meanIntensity(renderer.render(scene));
  scene.lighting.brightness_contrast = 0.5;
  const double dark = meanIntensity(renderer.render(scene));
  EXPECT_GT(normal, 60.0);
  EXPECT_NEAR(dark / normal, 0.5, 0.01);
}

TEST(Renderer, LightingChangesTheColorsNotTheTruth) {
  const Renderer renderer(sim_test::defaultCalibration());
  const auto& camera = renderer.model().camera();
  Scene scene;
  scene.robot_pose = {0.0, 0.0, 0.0};
  scene.lighting = sim_test::cleanLighting();
  const LabeledFrame normal = renderer.render(scene);

  Scene brighter = scene;
  brighter.lighting.level = 1.3;
  EXPECT_GT(meanIntensity(renderer.render(brighter)), meanIntensity(normal) + 10);

  // A hard shadow on the floor: darker inside, unchanged outside.
  Scene shadowed = scene;
  shadowed.lighting.shadows = {{1.0, -3.0, 2.0, 3.0, 0.4}};
  const LabeledFrame s = renderer.render(shadowed);
  Pixel in, out;
  ASSERT_TRUE(projectFieldPoint(camera, scene.robot_pose, 1.5, 0.7, 0.0, &in));
  ASSERT_TRUE(projectFieldPoint(camera, scene.robot_pose, 2.5, 0.7, 0.0, &out));
  EXPECT_LT(colorAt(s, in)[1], 0.8 * colorAt(normal, in)[1]);
  EXPECT_EQ(colorAt(s, out), colorAt(normal, out));
  // The floor's shadow leaves the goal behind it as it was; a zone of the hall's light (lamps over
  // one half off: floor_only false) darkens the goal too.
  const double goal_x = renderer.model().field().halfLength() + 0.1;
  Pixel goal;
  ASSERT_TRUE(projectFieldPoint(camera, scene.robot_pose, goal_x, 0.0, 0.3, &goal));
  ASSERT_EQ(labelAt(normal, goal), core::kYellow);
  Scene half = scene;
  half.lighting.shadows = {{1.0, -1e3, 1e3, 1e3, 0.4, false}};
  shadowed.lighting.shadows = {{1.0, -1e3, 1e3, 1e3, 0.4}};
  const LabeledFrame h = renderer.render(half), floor_only = renderer.render(shadowed);
  EXPECT_EQ(colorAt(floor_only, goal), colorAt(normal, goal));
  EXPECT_LT(colorAt(h, goal)[0], 0.8 * colorAt(normal, goal)[0]);
  EXPECT_LT(colorAt(h, in)[1], 0.8 * colorAt(normal, in)[1]);
  Pixel behind;  // the other half
  ASSERT_TRUE(projectFieldPoint(camera, scene.robot_pose, -1.5, 0.7, 0.0, &behind));
  EXPECT_EQ(colorAt(h, behind), colorAt(normal, behind));

  // Warm light: more red relative to blue on the white lines.
  Scene warm = scene;
  warm.lighting.color_temperature_k = 3200;
  const LabeledFrame w = renderer.render(warm);
  Pixel line;
  ASSERT_TRUE(projectFieldPoint(camera, scene.robot_pose, 0.0, 1.0, 0.0, &line));
  ASSERT_EQ(labelAt(normal, line), core::kWhite);
  const cv::Vec3b cn = colorAt(normal, line), cw = colorAt(w, line);
  EXPECT_GT(static_cast<double>(cw[0]) / cw[2], 1.2 * cn[0] / cn[2]);

  for (const LabeledFrame* f : {&s, &w}) EXPECT_EQ(cv::norm(f->labels, normal.labels, cv::NORM_INF), 0.0);
}

TEST(Renderer, ImageOutsideTheMirrorIsBlackAndChassisIsBlack) {
  const Renderer renderer(sim_test::defaultCalibration());
  const LabeledFrame f = renderer.render(busyScene());
  EXPECT_EQ(f.labels.at<uint8_t>(0, 0), core::kNotImaged);
  EXPECT_EQ(f.rgb.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
  const auto& cal = renderer.model().camera().calibration();
  const int cu = static_cast<int>(cal.center_u), cv_ = static_cast<int>(cal.center_v);
  EXPECT_EQ(f.labels.at<uint8_t>(cv_, cu + 5), core::kBlack);
  const cv::Vec3b c = f.rgb.at<cv::Vec3b>(cv_, cu + 5);
  EXPECT_LT(c[0] + c[1] + c[2], 3 * 70);
}

// A 580x580 frame well under 100 ms on one core (measured ~25 ms in Release on the dev machine).
TEST(Renderer, RendersAFrameWellUnder100Milliseconds) {
  const Renderer renderer(sim_test::defaultCalibration());
  Scene scene = busyScene();
  renderer.render(scene);  // warm-up
  const int frames = 10;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < frames; ++i) {
    scene.noise_seed = i;
    renderer.render(scene);
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / frames;
  std::printf("render time per 580x580 frame: %.1f ms\n", ms);
  RecordProperty("render_ms", std::to_string(ms));
  EXPECT_LT(ms, 100.0);
}

}  // namespace
}  // namespace act_color
