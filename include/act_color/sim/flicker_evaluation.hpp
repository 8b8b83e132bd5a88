#pragma once

#include <vector>

#include "act_color/core/act_trainer.hpp"
#include "act_color/core/metrics.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scene_family.hpp"

namespace act_color {
namespace sim {

// Light that comes and goes (issue 15): a family scene's motion with its first frame's light frozen,
// each frame then scaled by a gain of its own (flicker, one dark frame in N, an exposure controller
// hunting), and ACT (defaults unless told otherwise) played on it from a start-up on the first frame.
struct FlickerFrames {
  std::vector<LabeledFrame> frames;
  std::vector<core::Pose2D> poses;
};
// noise_offset: another realisation of the sensor noise (the same motion and light), for a control
// run that shows how far two steady runs differ by chance.
FlickerFrames steadyLightFrames(const FamilyScene& scene, size_t count, uint32_t noise_offset = 0);

struct FlickerRun {
  std::vector<double> fill;                            // mapped table cells / all cells, per frame
  std::vector<core::ClassificationMetrics> per_frame;  // classified with the table after the frame's cycle
  int light_changes = 0, restores = 0;
};
FlickerRun playWithGains(const FamilyScene& scene, const FlickerFrames& frames, const std::vector<double>& gains,
                         const core::ActParams& params = core::ActParams());

// Gain sequences: every period-th frame at `gain` (period 0: none); 1 + amplitude sin(2 pi hz t + 0.5)
// at 30 frames per second from frame `first` on (the phase keeps 15 Hz from sampling only zeros).
std::vector<double> everyNthFrame(size_t count, int period, double gain);
std::vector<double> exposureSwing(size_t count, size_t first, double amplitude, double hz);

// A run against light-matched references: for each frame from `first` on whose gain is within
// [0.65, 1.35], the steady run at the nearest of the gains 0.7, 0.725, ..., 1.3 (trained from the start
// at that light; frames at other gains, the dark frames of a flicker, are not compared).
struct FlickerComparison {
  double fill_max_ratio = 0;                   // largest fill / the reference's fill on the same frame
  double fill_mean_ratio = 0;                  // mean over the frames of that ratio
  core::ClassificationMetrics run, reference;  // the compared frames' counts
  int worst_class = 0;                         // largest precision drop (reference - run)
  double worst_precision_drop = 0;
};
FlickerComparison compareWithSteadyLight(const FlickerRun& run, const std::vector<double>& gains,
                                         const std::vector<FlickerRun>& references, size_t first);
// The gains of the references compareWithSteadyLight expects, in its order.
const std::vector<double>& steadyReferenceGains();
// The index in steadyReferenceGains() of the reference a frame at `gain` is compared with; -1 for a
// gain outside [0.65, 1.35] (not compared).
int steadyReferenceFor(double gain);
// Those references: the frames played at each of those gains throughout. Only the references that
// frames at `compared_gains` are compared with when given (the others stay empty).
std::vector<FlickerRun> playSteadyReferences(const FamilyScene& scene, const FlickerFrames& frames,
                                             const core::ActParams& params = core::ActParams(),
                                             const std::vector<double>* compared_gains = nullptr);

}  // namespace sim
}  // namespace act_color
