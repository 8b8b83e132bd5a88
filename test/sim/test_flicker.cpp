// Issue 15: light that comes and goes leaves the table as it was. A family scene with its light
// frozen, played with full and half brightness alternating, and with one dark frame in ten: the
// table's fill stays within 1.5x of the steady run's (it went to 99% before) and the classes'
// precision on the frames at the steady light stays near the steady run's.
#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "act_color/core/act_trainer.hpp"
#include "act_color/core/metrics.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scene_family.hpp"
#include "act_color/sim/tone_curve.hpp"

namespace {

namespace core = act_color::core;
namespace sim = act_color::sim;

struct FlickerRun {
  double fill_mean = 0, fill_max = 0;
  core::ClassificationMetrics steady_light;  // frames at the steady light
  int light_changes = 0, restores = 0;
};

// Frames `first` .. end of `frames`, every `period`-th of them at `gain` (period 0: none).
FlickerRun play(const sim::FamilyScene& scene, const std::vector<sim::LabeledFrame>& frames,
                const std::vector<core::Pose2D>& poses, int period, double gain) {
  core::ActTrainer trainer(scene.calibration);
  const core::Segmenter segmenter(scene.calibration.camera);
  const sim::ToneCurve dark = sim::ToneCurve::gain(Eigen::Vector3d::Constant(gain));
  FlickerRun run;
  int measured = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    cv::Mat rgb = frames[i].rgb.clone();
    const bool is_dark = period > 0 && static_cast<int>(i) % period == period - 1;
    if (is_dark) dark.apply(rgb);
    const core::ImageView view = core::ImageView::fromMat(rgb, core::PixelFormat::kRgb8);
    if (i == 0) {
      trainer.bootstrap(view, poses[i], core::kDefaultBootstrapCycles);
      continue;
    }
    const core::CycleStats stats = trainer.cycle(view, poses[i]);
    run.light_changes += stats.light_change;
    run.restores += stats.light_restored;
    if (i < 20) continue;  // settled
    const auto counts = trainer.lut().cellCounts();
    double filled = 0;
    for (int k = 1; k < core::kNumClasses; ++k) filled += counts[k];
    filled /= static_cast<double>(trainer.lut().size());
    run.fill_mean += filled;
    run.fill_max = std::max(run.fill_max, filled);
    ++measured;
    if (!is_dark) {
      cv::Mat labels;
      segmenter.classify(trainer.lut(), view, labels);
      run.steady_light.add(labels, frames[i].labels);
    }
  }
  run.fill_mean /= measured;
  return run;
}

TEST(Flicker, LightThatComesAndGoesLeavesTheTableAsItWas) {
  const sim::FamilyScene scene = sim::makeFamilyScene(0, sim::ScenarioLength::kSmall, false);
  const sim::Renderer renderer(scene.calibration, scene.renderer);
  // The scene's motion with its first frame's light throughout.
  std::vector<sim::LabeledFrame> frames;
  std::vector<core::Pose2D> poses;
  const sim::Lighting light = scene.scenario.frames[0].scene.lighting;
  for (size_t i = 0; i < 60; ++i) {
    sim::Scene s = scene.scenario.frames[std::min(i, scene.scenario.frames.size() - 1)].scene;
    s.lighting = light;
    s.noise_seed = static_cast<uint32_t>(i + 1);
    frames.push_back(renderer.render(s));
    poses.push_back(s.robot_pose);
  }
  const FlickerRun steady = play(scene, frames, poses, 0, 1.0);
  for (const int period : {2, 10}) {
    const FlickerRun flicker = play(scene, frames, poses, period, 0.5);
    std::printf(
        "one frame in %d at half brightness: fill mean %.4f max %.4f (steady %.4f: x%.2f), %d changes of light, "
        "%d restores\n",
        period, flicker.fill_mean, flicker.fill_max, steady.fill_mean, flicker.fill_max / steady.fill_mean,
        flicker.light_changes, flicker.restores);
    // The first dark frame moves the table (a change of light), every later one restores a state.
    EXPECT_LE(flicker.light_changes, 2) << period;
    EXPECT_GE(flicker.restores, period == 2 ? 40 : 8) << period;
    EXPECT_LE(flicker.fill_max, 1.5 * steady.fill_mean) << period;
    for (const int k : core::trainableClasses()) {
      std::printf("  %-6s precision at the steady light %.3f (steady run %.3f)\n", core::className(k),
                  flicker.steady_light.precision(k), steady.steady_light.precision(k));
      // Measured: within 0.04 (yellow, one dark frame in ten); the steady run with another random
      // seed differs by up to 0.03.
      EXPECT_GE(flicker.steady_light.precision(k), steady.steady_light.precision(k) - 0.05) << core::className(k);
    }
  }
}

}  // namespace
