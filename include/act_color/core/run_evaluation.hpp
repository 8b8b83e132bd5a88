#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "act_color/core/metrics.hpp"

namespace act_color {
namespace core {

// Accuracy of one part of a run: from an event (e.g. a sudden darkening) to the next.
struct SegmentSummary {
  std::string event;       // what started the segment ("start" for the first)
  size_t first_frame = 0;  // index in the run
  size_t frames = 0;
  ClassificationMetrics all;      // every frame of the segment
  ClassificationMetrics adapted;  // frames after the first `adapt_frames` of the segment
  // Mean per-frame recall over the last quarter of the segment: what ACT converged to.
  std::array<double, kNumClasses> final_recall{};
  // Training cycles after the event until the class's per-frame recall stays within the tolerance
  // of final_recall (1: the first frame after the event, trained once, is already there); -1 when
  // the class is absent or never settles.
  std::array<int, kNumClasses> settle_cycles{};
  // Training cycles after the event until the class's per-frame recall first comes within the
  // tolerance of final_recall (it may leave it again later: settle_cycles counts the last
  // return); -1 when the class is absent or never comes there.
  std::array<int, kNumClasses> reach_cycles{};
};

// Collects per-frame accuracy of a run and splits it into segments at events.
class RunEvaluation {
 public:
  explicit RunEvaluation(size_t adapt_frames = 12, double settle_tolerance = 0.02)
      : adapt_frames_(adapt_frames), settle_tolerance_(settle_tolerance) {}

  // The next frame starts a new segment named `event`.
  void markEvent(const std::string& event);
  void addFrame(const cv::Mat& labels, const cv::Mat& truth);

  size_t frames() const { return frame_metrics_.size(); }
  const ClassificationMetrics& frame(size_t i) const { return frame_metrics_[i]; }
  ClassificationMetrics overall() const;
  std::vector<SegmentSummary> segments() const;

  // Frames after the first `adapt_frames` of every segment, pooled.
  ClassificationMetrics adapted() const;

  // Human-readable report of all segments and the whole run.
  std::string report() const;
  // A few lines: the whole run's recall/precision per trainable class (all frames and adapted
  // frames) and, for each event, the cycles each class needed to settle.
  std::string brief() const;
  // One CSV row per frame: frame, segment, then recall and precision of each class.
  std::string csv() const;

 private:
  size_t adapt_frames_;
  double settle_tolerance_;
  std::vector<ClassificationMetrics> frame_metrics_;
  std::vector<std::pair<size_t, std::string>> events_;  // (first frame, name)
};

}  // namespace core
}  // namespace act_color
