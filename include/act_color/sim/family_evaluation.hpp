#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "act_color/core/act_trainer.hpp"
#include "act_color/core/metrics.hpp"
#include "act_color/core/run_evaluation.hpp"
#include "act_color/core/table_ceiling.hpp"
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

// Where a scene's self mask comes from: none; its mirror struts (Renderer::strutMask: every pixel a
// strut covers, the best a team's calibration can hold); or learned as a team does it, by
// learnSelfMaskOnDrive before the scene's frames.
enum class SelfMaskSource { kNone, kStruts, kLearnedOnDrive };

// What a team does with `act_replay --learn-self-mask` on a drive over its field: the scene's first
// frame's hall, robots, ball and light seen from `poses` random poses on the field (told exactly),
// a default ActTrainer without a mask trained along (bootstrapped at the first pose, then
// kDriveCyclesPerPose cycles at each) and core::SelfMaskLearner fed the table after each pose's
// cycles. Deterministic in the scene's seed. `turning` false: every pose faces +x (a drive that
// never turns).
constexpr int kDrivePoses = 24;
constexpr int kDriveCyclesPerPose = 5;
std::vector<uint8_t> learnSelfMaskOnDrive(const FamilyScene& scene, int poses, bool turning = true);
// The drive's poses: `poses` random poses within 0.45 of the field's length and width, off the
// first frame's robots and ball (fewer when the field is crowded). The frame at pose k is rendered
// with noise seed kDriveNoiseSeed + k.
std::vector<core::Pose2D> drivePoses(const FamilyScene& scene, int poses, bool turning = true);
constexpr uint32_t kDriveNoiseSeed = 5000;

struct EvalOptions {
  size_t adapt_frames = 12;    // frames of each segment before "after adaptation"
  int bootstrap_cycles = 100;  // start-up training on the first frame, as act_replay
  std::string png_dir;         // when set: input | modes | truth of each segment's last frame
  bool false_pixels = false;   // SceneResult::false_pixels (a pass over every pixel per mode)
  // The self mask each scene's calibration carries (CameraCalibration::self_mask); every mode
  // trains and classifies with it.
  SelfMaskSource self_mask = SelfMaskSource::kNone;
};

// Issue 13's figures of the ball in one scene and mode. In scenes with a ball: pixels pooled over
// the frames from kBallFramesInView frames after the ball first came into view (at least
// kMinBallTruthPixels of it imaged); the ball's reported position (CycleStats::ball) against the
// truth in those frames. In scenes without one: the frames with any pixel classified as the ball.
constexpr size_t kBallFramesInView = 30;
constexpr uint64_t kMinBallTruthPixels = 10;
struct BallFigures {
  bool ball_in_scene = false;
  size_t frames = 0;                            // counted frames (with a ball: after kBallFramesInView in view)
  uint64_t truth = 0, predicted = 0, hits = 0;  // ball pixels in the truth, classified, both
  size_t frames_in_view = 0;                    // of the counted frames, with the ball in view
  size_t sightings = 0;                         // of those, with a position reported
  size_t position_ok = 0;                       // of the sightings, within 0.15 m + 5% of the distance
  std::vector<double> position_errors_m;
  size_t frames_with_ball_pixels = 0;  // without a ball: frames with any pixel classified as the ball
  double recall() const { return truth ? static_cast<double>(hits) / truth : std::nan(""); }
  double precision() const { return predicted ? static_cast<double>(hits) / predicted : std::nan(""); }
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
  double act_seconds = 0.0;       // training and classification, all modes
  std::vector<BallFigures> ball;  // [mode]
  // With EvalOptions::false_pixels: [mode][segment], after adaptation, against the ceiling's table.
  std::vector<std::vector<std::array<core::FalsePixels, core::kNumClasses>>> false_pixels;
  // The self mask against the struts (imaged pixels): its size, the struts' and both.
  size_t self_mask_pixels = 0, strut_pixels = 0, self_mask_on_struts = 0;
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
  // [mode][class]: cycles after those events until recall first comes within 0.02 of its final
  // level (core::SegmentSummary::reach_cycles; never = segment length). Far below settle when
  // recall gets there at once and later leaves it again (the table's cells come and go).
  std::vector<std::array<Distribution, core::kNumClasses>> reach;
  // [mode][class]: units whose F1 is below the paper's F1 - 0.02, and the worst difference.
  std::vector<std::array<size_t, core::kNumClasses>> f1_below_paper;
  std::vector<std::array<double, core::kNumClasses>> f1_worst_vs_paper;
  // Seeds of the units behind each worst case [mode][class], for looking at them.
  std::vector<std::array<uint32_t, core::kNumClasses>> worst_recall_seed, worst_precision_seed;
  // [mode]: the ball (BallFigures) over scenes with a ball in view long enough: recall, precision
  // and the fraction of sightings within the position tolerance; the fraction of frames seen;
  // over scenes without a ball, the fraction of frames with ball pixels.
  std::vector<Distribution> ball_recall, ball_precision, ball_position_ok, ball_seen, no_ball_false_frames;
  std::vector<size_t> no_ball_scenes_over_1pct;
  // [mode][class], with EvalOptions::false_pixels (else empty): shares of the class's classified
  // pixels that are false (1 - precision, taken apart by core::FalsePixelSources) in cells the
  // ceiling gives the class too, in the hall's cells, in other classes' cells; and those of them
  // in a cell at the top of a channel. 90th percentile in p10.
  std::vector<std::array<Distribution, core::kNumClasses>> false_shared, false_hall, false_other, false_top;
};

FamilyReport summarize(const std::vector<SceneResult>& results);
// The report as text: per class median / p10 / worst for each mode and the ceiling, the gaps,
// settle cycles and the comparison with the paper.
std::string formatReport(const FamilyReport& report);
// One line per scene: seed, then per class F1 of each mode and of the ceiling.
std::string formatScene(const SceneResult& result);

}  // namespace sim
}  // namespace act_color
