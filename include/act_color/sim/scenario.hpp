#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "act_color/core/types.hpp"
#include "act_color/sim/renderer.hpp"

namespace act_color {
namespace sim {

// One frame of a scenario: what the camera sees (the scene, with the true pose) and what ACT is
// told (the pose from self-localization), plus markers of events starting at this frame.
struct ScenarioFrame {
  Scene scene;                      // scene.robot_pose is the true pose
  core::Pose2D told_pose;           // the pose published on /localization/pose
  std::vector<std::string> events;  // e.g. "darken", "brighten", "wrong_pose"
};

enum class ScenarioLength {
  kSmall,  // a few dozen frames, for tests
  kFull,   // hundreds of frames, for benchmarks
};

struct Scenario {
  std::string name;
  std::string description;
  double frame_rate_hz = 30.0;
  std::vector<ScenarioFrame> frames;
};

// Names accepted by makeScenario, in a fixed order:
//   static_darkening    static robot, normal light, then brightness and contrast to 50% (paper, 3.2)
//   wrong_pose          frames cycle over two known poses and a third whose true pose is 2.5 m away
//                       and rotated by 165 degrees while ACT is told the last known one (paper, 3.3)
//   driving             robot driving across the field among other robots and the ball, light level
//                       and color temperature varying slowly
//   spotlights          strong spotlights and hard shadows, robot moving through them
//   sudden_brightening  static robot, light level jumps from 0.6 to 1.3
const std::vector<std::string>& scenarioNames();

// Builds a named scenario; deterministic in (name, length, seed). Throws std::invalid_argument for
// an unknown name. The calibration's field is used to keep poses and objects on the field.
Scenario makeScenario(const std::string& name, ScenarioLength length, const core::Calibration& calibration,
                      uint32_t seed = 1);

// Parses "small" or "full"; false otherwise.
bool parseScenarioLength(const std::string& text, ScenarioLength* length);

// Parameters of the wrong-pose case (paper, 3.3).
constexpr double kWrongPoseDistanceM = 2.5;
constexpr double kWrongPoseRotationRad = 165.0 * 3.14159265358979323846 / 180.0;
// The pose kWrongPoseDistanceM from `from` towards `direction_rad` (field frame), rotated by
// kWrongPoseRotationRad.
core::Pose2D wrongPose(const core::Pose2D& from, double direction_rad);

}  // namespace sim
}  // namespace act_color
