// Issue 15: light that comes and goes leaves the table as it was. A family scene with its light
// frozen, played with full and half brightness alternating, with one dark frame in ten, and with an
// exposure swinging to and fro: the table's fill stays within 1.5x of a steady run's (it went to 99%
// before the trainer kept the states of the lights it left) and the classes' precision on the frames
// at the steady light stays near the steady run's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "act_color/core/metrics.hpp"
#include "act_color/sim/flicker_evaluation.hpp"
#include "act_color/sim/scene_family.hpp"

namespace {

namespace core = act_color::core;
namespace sim = act_color::sim;

constexpr size_t kSettled = 20;  // frames before the measures start

struct Measured {
  double fill_mean = 0, fill_max = 0;
  core::ClassificationMetrics steady_light;  // frames with a gain within 0.05 of 1
};

Measured measure(const sim::FlickerRun& run, const std::vector<double>& gains) {
  Measured m;
  for (size_t i = kSettled; i < run.fill.size(); ++i) {
    m.fill_mean += run.fill[i];
    m.fill_max = std::max(m.fill_max, run.fill[i]);
    if (std::abs(gains[i] - 1.0) <= 0.05) m.steady_light.merge(run.per_frame[i]);
  }
  m.fill_mean /= static_cast<double>(run.fill.size() - kSettled);
  return m;
}

// A family scene's exposure swinging 1 +- 0.3 at `hz` over 120 frames, measured as act_flicker
// measures it: every frame from the 30th against the steady run nearest its light.
struct Swing {
  sim::FlickerRun run;
  sim::FlickerComparison compared;
};
Swing swingAgainstSteadyLight(uint32_t seed, double hz) {
  const sim::FamilyScene scene = sim::makeFamilyScene(seed, sim::ScenarioLength::kSmall, false);
  const sim::FlickerFrames frames = sim::steadyLightFrames(scene, 120);
  const std::vector<double> gains = sim::exposureSwing(frames.frames.size(), 10, 0.3, hz);
  const std::vector<sim::FlickerRun> references = sim::playSteadyReferences(scene, frames, core::ActParams(), &gains);
  Swing s;
  s.run = sim::playWithGains(scene, frames, gains);
  s.compared = sim::compareWithSteadyLight(s.run, gains, references, 30);
  return s;
}

class Flicker : public ::testing::Test {
 protected:
  void SetUp() override { frames = sim::steadyLightFrames(scene, 60); }
  const sim::FamilyScene scene = sim::makeFamilyScene(0, sim::ScenarioLength::kSmall, false);
  sim::FlickerFrames frames;
};

TEST_F(Flicker, LightThatComesAndGoesLeavesTheTableAsItWas) {
  const size_t n = frames.frames.size();
  const std::vector<double> steady_gains(n, 1.0);
  const Measured steady = measure(sim::playWithGains(scene, frames, steady_gains), steady_gains);
  for (const int period : {2, 10}) {
    const std::vector<double> gains = sim::everyNthFrame(n, period, 0.5);
    const sim::FlickerRun run = sim::playWithGains(scene, frames, gains);
    const Measured flicker = measure(run, gains);
    std::printf(
        "one frame in %d at half brightness: fill mean %.4f max %.4f (steady %.4f: x%.2f), %d changes of light, "
        "%d restores\n",
        period, flicker.fill_mean, flicker.fill_max, steady.fill_mean, flicker.fill_max / steady.fill_mean,
        run.light_changes, run.restores);
    // The first dark frame moves the table (a change of light), every later one restores a state.
    EXPECT_LE(run.light_changes, 2) << period;
    EXPECT_GE(run.restores, period == 2 ? 40 : 8) << period;
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

// An exposure controller hunting: 1 +- 0.3 at 2 Hz (30 frames per second), measured as act_flicker
// measures it (its run "seed 0, exposure 1 +- 0.3 at 2 Hz"): every frame from the 30th against the
// steady run at the nearest of 0.7, 0.725, ... 1.3, the compared frames pooled; every class's
// precision within 0.03 (issue 15, item 1) and the fill within 1.5x. Measured (d065414): yellow
// 0.025 below (0.888 against 0.913), fill x1.26; since a restored light's cycle samples densely
// (ActTrainer's kRestoredDensity, 2026-12-07): white 0.0297 below (0.834 against 0.864), yellow
// 0.018, fill x1.25 (a thin margin: that change was judged on act_flicker's 36 runs). Until
// 2026-12-07 this test compared the frames within 0.05 of exposure 1 (at 1.024 and 1.038) with the
// steady run at 1, allowing 0.05: yellow stood at 0.0498 below (0.850 against 0.900; bac65db: 0.027,
// white 0.048), so that a change of the trainer that left act_flicker's figures as they were moved
// it across. Before a moved table left the old light's cells behind and a change was taken at 0.4
// instead of 0.75 of green's sigma: fill x1.37, white precision 0.76 against 0.86.
TEST(FlickerHunting, AnExposureSwingingToAndFroLeavesTheTableAsItWas) {
  const Swing swing = swingAgainstSteadyLight(0, 2.0);
  const sim::FlickerComparison& c = swing.compared;
  std::printf("scene 0, exposure 1 +- 0.3 at 2 Hz: fill x%.2f, %d changes, %d restores\n", c.fill_max_ratio,
              swing.run.light_changes, swing.run.restores);
  EXPECT_LE(c.fill_max_ratio, 1.5);
  for (const int k : core::trainableClasses()) {
    std::printf("  %-6s precision %.3f (steady runs %.3f)\n", core::className(k), c.run.precision(k),
                c.reference.precision(k));
    EXPECT_GE(c.run.precision(k), c.reference.precision(k) - 0.03) << core::className(k);
  }
}

// A restored light serves a frame or two in turn with the others, and its table, moved there with a
// change's dense additions, is cleaned and confirmed only in those frames: a restored light's cycle
// samples its additions, learned_boundary and 2.4's removal 4 times as densely. Tuning scene 2 at
// 5 Hz (four lights in turn, one restored every frame) kept the carpet's colors in white: precision
// 0.084 below the light-matched steady runs, now within 0.03, every class's recall within 0.05 of
// theirs (measured: white precision 0.607 against 0.592, 0.508 at density 1; white recall 0.641
// against 0.676).
TEST(FlickerRestoredLight, ARestoredLightCatchesUpOnTheFramesItMissed) {
  const Swing swing = swingAgainstSteadyLight(2, 5.0);
  const sim::FlickerComparison& c = swing.compared;
  std::printf("scene 2, exposure 1 +- 0.3 at 5 Hz: fill x%.2f, %d changes, %d restores\n", c.fill_max_ratio,
              swing.run.light_changes, swing.run.restores);
  EXPECT_GE(swing.run.restores, 100);
  EXPECT_LE(c.fill_max_ratio, 1.5);
  for (const int k : core::trainableClasses()) {
    std::printf("  %-6s precision %.3f recall %.3f (steady runs %.3f, %.3f)\n", core::className(k), c.run.precision(k),
                c.run.recall(k), c.reference.precision(k), c.reference.recall(k));
    EXPECT_GE(c.run.precision(k), c.reference.precision(k) - 0.03) << core::className(k);
    EXPECT_GE(c.run.recall(k), c.reference.recall(k) - 0.05) << core::className(k);
  }
}

// A slow swing (1 Hz) passes more lights than a fast one before it turns: on tuning scene 5 it
// made 19 changes of light with 8 kept lights, each moving the last table on, and the table grew
// to 2.2x a light-matched steady run's (act_flicker); here 1.66x the largest steady run's. With the
// lights kept up to ActTrainer::kLightStatesBytes (16 at 6 bits per channel): 9 changes, 1.26x.
TEST(FlickerSlowSwing, AnExposureSwingingSlowlyIsServedByTheLightsItLeft) {
  const sim::FamilyScene scene = sim::makeFamilyScene(5, sim::ScenarioLength::kSmall, false);
  const sim::FlickerFrames frames = sim::steadyLightFrames(scene, 120);
  const size_t n = frames.frames.size();
  const std::vector<double> gains = sim::exposureSwing(n, 10, 0.3, 1.0);
  const sim::FlickerRun run = sim::playWithGains(scene, frames, gains);
  const Measured flicker = measure(run, gains);
  double largest_steady = 0;
  for (const double gain : {0.7, 1.0, 1.3}) {
    const std::vector<double> steady_gains(n, gain);
    largest_steady =
        std::max(largest_steady,
                 measure(sim::playWithGains(scene, frames, steady_gains), std::vector<double>(n, 1.0)).fill_mean);
  }
  std::printf(
      "scene 5, exposure 1 +- 0.3 at 1 Hz: fill max %.4f (largest steady mean %.4f: x%.2f), %d changes, %d "
      "restores\n",
      flicker.fill_max, largest_steady, flicker.fill_max / largest_steady, run.light_changes, run.restores);
  EXPECT_LE(run.light_changes, 12);
  EXPECT_LE(flicker.fill_max, 1.5 * largest_steady);
}

// An exposure alternating every frame between 1.144 and 0.856 (1 +- 0.3 at 15 Hz) on tuning scene 5,
// measured as act_flicker measures it (against the steady runs at the nearest of 0.7, 0.725, ... 1.3,
// the compared frames pooled): every class's precision within 0.03 (issue 15, item 1). The map of
// the first change went through the lines' quantiles as seen, which a view of other lines had
// moved, and white fell 0.071 below; fitted with a curve of light's form, 0.015 (0.012 against
// references every 0.025 of gain instead of 0.1).
TEST(FlickerFastSwing, AnExposureAlternatingEveryFrameKeepsThePrecision) {
  const sim::FlickerComparison c = swingAgainstSteadyLight(5, 15.0).compared;
  std::printf("scene 5, exposure 1 +- 0.3 at 15 Hz: worst precision drop %.3f (%s), fill x%.2f\n",
              c.worst_precision_drop, core::className(c.worst_class), c.fill_max_ratio);
  EXPECT_LE(c.worst_precision_drop, 0.03) << core::className(c.worst_class);
  EXPECT_LE(c.fill_max_ratio, 1.5);
}

// A frame is compared with the steady run nearest to its gain, at most 0.0125 away; gains outside
// [0.65, 1.35] (a flicker's dark frames) are not compared, and a comparison without the reference it
// needs is refused rather than made against nothing.
TEST(FlickerReferences, EachFrameMeetsTheSteadyRunNearestToItsLight) {
  const std::vector<double>& levels = sim::steadyReferenceGains();
  for (const double gain : {0.7, 0.856, 1.0, 1.144, 1.3, 0.66, 1.34}) {
    const int l = sim::steadyReferenceFor(gain);
    ASSERT_GE(l, 0) << gain;
    const double off = std::abs(levels[static_cast<size_t>(l)] - gain);
    EXPECT_LE(off, gain >= 0.7 && gain <= 1.3 ? 0.0125 + 1e-9 : 0.05) << gain;
  }
  EXPECT_EQ(sim::steadyReferenceFor(0.5), -1);
  EXPECT_EQ(sim::steadyReferenceFor(1.4), -1);
  EXPECT_EQ(sim::steadyReferenceFor(std::nan("")), -1);

  sim::FlickerRun run;
  run.fill = {0.01, 0.01};
  run.per_frame.resize(2);
  const std::vector<sim::FlickerRun> none(levels.size());
  EXPECT_THROW(sim::compareWithSteadyLight(run, {1.0, 1.0}, none, 0), std::invalid_argument);
  EXPECT_NO_THROW(sim::compareWithSteadyLight(run, {0.5, 0.5}, none, 0));  // nothing to compare
}

}  // namespace
