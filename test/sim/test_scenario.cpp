#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "act_color/sim/scenario.hpp"
#include "sim_test_util.hpp"

namespace act_color {
namespace {

using sim::makeScenario;
using sim::Scenario;
using sim::ScenarioLength;

double angleDifference(double a, double b) { return std::abs(std::atan2(std::sin(a - b), std::cos(a - b))); }

int countEvent(const Scenario& s, const std::string& event) {
  int n = 0;
  for (const auto& f : s.frames) n += static_cast<int>(std::count(f.events.begin(), f.events.end(), event));
  return n;
}

TEST(Scenario, AllNamedScenariosExistInBothLengthsAndAreDeterministic) {
  const core::Calibration cal = sim_test::defaultCalibration();
  ASSERT_GE(sim::scenarioNames().size(), 5u);
  for (const std::string& name : sim::scenarioNames()) {
    const Scenario small = makeScenario(name, ScenarioLength::kSmall, cal, 1);
    const Scenario full = makeScenario(name, ScenarioLength::kFull, cal, 1);
    EXPECT_EQ(small.name, name);
    EXPECT_GE(small.frames.size(), 24u) << name;
    EXPECT_LE(small.frames.size(), 60u) << name;
    EXPECT_GE(full.frames.size(), 200u) << name;
    const Scenario again = makeScenario(name, ScenarioLength::kSmall, cal, 1);
    ASSERT_EQ(again.frames.size(), small.frames.size());
    for (size_t i = 0; i < small.frames.size(); ++i) {
      const auto& a = small.frames[i];
      const auto& b = again.frames[i];
      EXPECT_EQ(a.told_pose.x_m, b.told_pose.x_m);
      EXPECT_EQ(a.told_pose.theta_rad, b.told_pose.theta_rad);
      EXPECT_EQ(a.scene.robot_pose.y_m, b.scene.robot_pose.y_m);
      EXPECT_EQ(a.scene.noise_seed, b.scene.noise_seed);
      EXPECT_EQ(a.events, b.events);
    }
    // Every true pose on the field, no other robot or the ball inside the own robot.
    for (const auto& f : full.frames) {
      EXPECT_LT(std::abs(f.scene.robot_pose.x_m), cal.field.length_m / 2) << name;
      EXPECT_LT(std::abs(f.scene.robot_pose.y_m), cal.field.width_m / 2) << name;
      for (const auto& r : f.scene.robots) {
        EXPECT_GE(std::hypot(r.x_m - f.scene.robot_pose.x_m, r.y_m - f.scene.robot_pose.y_m), 0.85) << name;
      }
      if (f.scene.ball) {
        EXPECT_GE(std::hypot(f.scene.ball->x_m - f.scene.robot_pose.x_m, f.scene.ball->y_m - f.scene.robot_pose.y_m),
                  0.45);
      }
    }
  }
  EXPECT_THROW(makeScenario("no_such_scenario", ScenarioLength::kSmall, cal), std::invalid_argument);
  ScenarioLength length;
  EXPECT_TRUE(sim::parseScenarioLength("full", &length));
  EXPECT_EQ(length, ScenarioLength::kFull);
  EXPECT_FALSE(sim::parseScenarioLength("medium", &length));
}

// Paper, 3.3: the true pose of the wrong frames is 2.5 m from the told one and rotated by 165°.
TEST(Scenario, WrongPoseTellsAKnownPoseWhileTheRobotStandsElsewhere) {
  const Scenario s = makeScenario("wrong_pose", ScenarioLength::kSmall, sim_test::defaultCalibration());
  int wrong = 0;
  for (const auto& f : s.frames) {
    const auto& truth = f.scene.robot_pose;
    const auto& told = f.told_pose;
    const bool marked = std::find(f.events.begin(), f.events.end(), "wrong_pose") != f.events.end();
    if (marked) {
      EXPECT_EQ(wrong, 0) << "the event marks the first wrong frame only";
    }
    if (truth.x_m != told.x_m || truth.y_m != told.y_m || truth.theta_rad != told.theta_rad) {
      if (wrong == 0) {
        EXPECT_TRUE(marked);
      }
      ++wrong;
      EXPECT_NEAR(std::hypot(truth.x_m - told.x_m, truth.y_m - told.y_m), 2.5, 1e-9);
      EXPECT_NEAR(angleDifference(truth.theta_rad, told.theta_rad), 165.0 * M_PI / 180.0, 1e-9);
    } else {
      EXPECT_EQ(truth.x_m, told.x_m);
      EXPECT_EQ(truth.y_m, told.y_m);
      EXPECT_EQ(truth.theta_rad, told.theta_rad);
    }
  }
  EXPECT_EQ(wrong, static_cast<int>(s.frames.size()) / 3);
  // The told poses are the known ones only: at most two distinct.
  EXPECT_NE(s.frames[0].told_pose.x_m, s.frames[1].told_pose.x_m);
  EXPECT_EQ(s.frames[2].told_pose.x_m, s.frames[1].told_pose.x_m);
}

TEST(Scenario, StaticDarkeningAndSuddenBrighteningChangeTheLightOnce) {
  const core::Calibration cal = sim_test::defaultCalibration();
  for (const bool brighten : {false, true}) {
    const Scenario s = makeScenario(brighten ? "sudden_brightening" : "static_darkening", ScenarioLength::kSmall, cal);
    const std::string event = brighten ? "brighten" : "darken";
    ASSERT_EQ(countEvent(s, event), 1);
    size_t at = 0;
    while (s.frames[at].events.empty()) ++at;
    EXPECT_GE(at, 3u);
    for (size_t i = 0; i < s.frames.size(); ++i) {
      const auto& f = s.frames[i];
      EXPECT_EQ(f.scene.robot_pose.x_m, s.frames[0].scene.robot_pose.x_m);
      EXPECT_EQ(f.told_pose.theta_rad, f.scene.robot_pose.theta_rad);
      if (brighten) {
        EXPECT_DOUBLE_EQ(f.scene.lighting.level, i < at ? 0.6 : 1.3);
      } else {
        EXPECT_DOUBLE_EQ(f.scene.lighting.brightness_contrast, i < at ? 1.0 : 0.5);
      }
    }
  }
}

TEST(Scenario, DrivingAndSpotlightsMoveTheRobotWithACloseToldPose) {
  const core::Calibration cal = sim_test::defaultCalibration();
  for (const char* name : {"driving", "spotlights"}) {
    const Scenario s = makeScenario(name, ScenarioLength::kFull, cal);
    double path = 0.0, max_error = 0.0, min_level = 1e9, max_level = 0.0;
    for (size_t i = 0; i < s.frames.size(); ++i) {
      const auto& p = s.frames[i].scene.robot_pose;
      const auto& t = s.frames[i].told_pose;
      max_error = std::max(max_error, std::hypot(p.x_m - t.x_m, p.y_m - t.y_m));
      if (i > 0) {
        const auto& q = s.frames[i - 1].scene.robot_pose;
        path += std::hypot(p.x_m - q.x_m, p.y_m - q.y_m);
        EXPECT_LT(std::hypot(p.x_m - q.x_m, p.y_m - q.y_m), 0.1) << "at most 3 m/s at 30 Hz";
      }
      min_level = std::min(min_level, s.frames[i].scene.lighting.level);
      max_level = std::max(max_level, s.frames[i].scene.lighting.level);
    }
    EXPECT_GT(path, 10.0) << name;
    EXPECT_GT(max_error, 0.0) << name;
    EXPECT_LT(max_error, 0.2) << name;
    if (std::string(name) == "driving") {
      EXPECT_GT(max_level - min_level, 0.3);
      EXPECT_FALSE(s.frames[0].scene.robots.empty());
      EXPECT_TRUE(s.frames[0].scene.ball.has_value());
    } else {
      const auto& l = s.frames[0].scene.lighting;
      EXPECT_GE(l.spotlights.size(), 3u);
      EXPECT_GE(l.shadows.size(), 2u);
      EXPECT_GE(std::max_element(l.spotlights.begin(), l.spotlights.end(),
                                 [](const auto& a, const auto& b) { return a.gain < b.gain; })
                    ->gain,
                1.0);
    }
  }
}

}  // namespace
}  // namespace act_color
