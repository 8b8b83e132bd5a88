#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "act_color/core/act_trainer.hpp"
#include "act_color/core/metrics.hpp"
#include "act_color/core/run_evaluation.hpp"
#include "act_color/sim/scene_family.hpp"

namespace act_color {
namespace sim {

// One way of running ACT over a scene: the defaults, the paper's algorithm, an ablation.
struct EvalMode {
  std::string name;
  core::ActParams params;
};

// The defaults, the paper's algorithm (ActParams::paper()) and, with `ablations`, the defaults with
// each extension off in turn (named "no_<parameter>").
std::vector<EvalMode> evalModes(bool ablations);

struct EvalOptions {
  size_t adapt_frames = 12;    // frames of each segment before "after adaptation"
  int bootstrap_cycles = 100;  // start-up training on the first frame, as act_replay
  std::string png_dir;         // when set: input | modes | truth of each segment's last frame
};

// One scene run with every mode on the same rendered frames, and the fixed-table ceiling of each
// segment (TableCeiling over the segment's frames after adaptation).
struct SceneResult {
  uint32_t seed = 0;
  std::string summary;
  std::vector<std::string> mode_names;
  std::vector<std::vector<core::SegmentSummary>> segments;  // [mode][segment]
  std::vector<core::ClassificationMetrics> ceiling;         // [segment]
  size_t frames = 0;
  size_t adapt_frames = 12;
  double render_seconds = 0.0;
  double act_seconds = 0.0;  // training and classification, all modes
};

SceneResult evaluateScene(const FamilyScene& scene, const std::vector<EvalMode>& modes, const EvalOptions& options);

// A (scene, segment, class) with enough truth pixels after adaptation to be scored.
constexpr double kMinTruthPixelsPerFrame = 30.0;

// Distribution of one figure over the (scene, segment) units of a class.
struct Distribution {
  size_t count = 0;
  double median = 0, p10 = 0, worst = 0;  // p10: the 10% worst (for gaps and cycles: the 90th percentile)
};

// Statistics of a set of scene results, per class and mode (issue 11's report).
struct FamilyReport {
  std::vector<std::string> mode_names;
  // [mode][class]: recall and precision after adaptation; ceiling as an extra last "mode".
  std::vector<std::array<Distribution, core::kNumClasses>> recall, precision;
  // [mode][class]: ceiling minus the mode (positive: below the ceiling); 90th percentile in p10.
  std::vector<std::array<Distribution, core::kNumClasses>> recall_gap, precision_gap;
  // [mode][class]: settle cycles after events (never settled counts as the segment's length).
  std::vector<std::array<Distribution, core::kNumClasses>> settle;
  // [mode][class]: units whose F1 is below the paper's F1 - 0.02, and the worst difference.
  std::vector<std::array<size_t, core::kNumClasses>> f1_below_paper;
  std::vector<std::array<double, core::kNumClasses>> f1_worst_vs_paper;
  // Seeds of the units behind each worst case [mode][class], for looking at them.
  std::vector<std::array<uint32_t, core::kNumClasses>> worst_recall_seed, worst_precision_seed;
};

FamilyReport summarize(const std::vector<SceneResult>& results);
// The report as text: per class median / p10 / worst for each mode and the ceiling, the gaps,
// settle cycles and the comparison with the paper.
std::string formatReport(const FamilyReport& report);
// One line per scene: seed, then per class F1 of each mode and of the ceiling.
std::string formatScene(const SceneResult& result);

}  // namespace sim
}  // namespace act_color
