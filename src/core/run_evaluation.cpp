#include "act_color/core/run_evaluation.hpp"

#include <cmath>
#include <cstdio>

namespace act_color {
namespace core {

void RunEvaluation::markEvent(const std::string& event) {
  if (!events_.empty() && events_.back().first == frame_metrics_.size()) {
    events_.back().second += "+" + event;  // two events before the same frame
  } else {
    events_.emplace_back(frame_metrics_.size(), event);
  }
}

void RunEvaluation::addFrame(const cv::Mat& labels, const cv::Mat& truth) {
  ClassificationMetrics m;
  m.add(labels, truth);
  frame_metrics_.push_back(m);
}

ClassificationMetrics RunEvaluation::overall() const {
  ClassificationMetrics all;
  for (const auto& m : frame_metrics_) all.merge(m);
  return all;
}

ClassificationMetrics RunEvaluation::adapted() const {
  ClassificationMetrics all;
  for (const SegmentSummary& seg : segments()) all.merge(seg.adapted);
  return all;
}

std::vector<SegmentSummary> RunEvaluation::segments() const {
  std::vector<std::pair<size_t, std::string>> starts;
  if (events_.empty() || events_.front().first != 0) starts.emplace_back(0, "start");
  for (const auto& e : events_) {
    if (e.first < frame_metrics_.size()) starts.push_back(e);
  }
  std::vector<SegmentSummary> out;
  for (size_t s = 0; s < starts.size(); ++s) {
    SegmentSummary seg;
    seg.event = starts[s].second;
    seg.first_frame = starts[s].first;
    const size_t end = s + 1 < starts.size() ? starts[s + 1].first : frame_metrics_.size();
    seg.frames = end - seg.first_frame;
    for (size_t f = seg.first_frame; f < end; ++f) {
      seg.all.merge(frame_metrics_[f]);
      if (f - seg.first_frame >= adapt_frames_) seg.adapted.merge(frame_metrics_[f]);
    }
    const size_t tail = std::max<size_t>(1, seg.frames / 4);
    for (int k = 0; k < kNumClasses; ++k) {
      double sum = 0;
      int n = 0;
      for (size_t f = end - tail; f < end; ++f) {
        const double r = frame_metrics_[f].recall(k);
        if (!std::isnan(r)) {
          sum += r;
          ++n;
        }
      }
      seg.final_recall[k] = n ? sum / n : std::nan("");
      seg.settle_cycles[k] = -1;
      seg.reach_cycles[k] = -1;
      if (!n) continue;
      // The first frame at or above final - tolerance, and the last frame before which recall was
      // below it.
      size_t settle = seg.first_frame;
      for (size_t f = seg.first_frame; f < end; ++f) {
        const double r = frame_metrics_[f].recall(k);
        if (std::isnan(r)) continue;
        if (r < seg.final_recall[k] - settle_tolerance_) {
          settle = f + 1;
        } else if (seg.reach_cycles[k] < 0) {
          seg.reach_cycles[k] = static_cast<int>(f - seg.first_frame) + 1;
        }
      }
      if (settle < end) seg.settle_cycles[k] = static_cast<int>(settle - seg.first_frame) + 1;
    }
    out.push_back(seg);
  }
  return out;
}

std::string RunEvaluation::report() const {
  std::string out;
  char line[256];
  auto classTable = [&](const SegmentSummary* seg, const ClassificationMetrics& all,
                        const ClassificationMetrics* adapted) {
    std::snprintf(line, sizeof(line), "  %-8s %7s %9s %9s %11s %7s %8s\n", "class", "recall", "precision", "recall_ad",
                  "precision_ad", "final", "settle");
    out += line;
    for (int k = 0; k < kNumClasses; ++k) {
      if (all.truthCount(k) == 0 && all.predictedCount(k) == 0) continue;
      std::snprintf(line, sizeof(line), "  %-8s %7.4f %9.4f %9.4f %11.4f %7.4f %8d\n", className(k), all.recall(k),
                    all.precision(k), adapted ? adapted->recall(k) : std::nan(""),
                    adapted ? adapted->precision(k) : std::nan(""), seg ? seg->final_recall[k] : std::nan(""),
                    seg ? seg->settle_cycles[k] : -1);
      out += line;
    }
    std::snprintf(line, sizeof(line), "  fitness (eq. 6, trainable classes, lower is better): %.4f\n",
                  all.fitness(trainableClasses()));
    out += line;
  };
  for (const SegmentSummary& seg : segments()) {
    std::snprintf(line, sizeof(line), "segment '%s': frames %zu-%zu (%zu); *_ad: after its first %zu frames\n",
                  seg.event.c_str(), seg.first_frame, seg.first_frame + seg.frames - 1, seg.frames, adapt_frames_);
    out += line;
    classTable(&seg, seg.all, &seg.adapted);
  }
  std::snprintf(line, sizeof(line), "whole run: %zu frames\n", frame_metrics_.size());
  out += line;
  const ClassificationMetrics whole = overall();
  const ClassificationMetrics whole_adapted = adapted();
  classTable(nullptr, whole, &whole_adapted);
  out += "confusion of the whole run, pixels (rows: truth, columns: classified as)\n         ";
  for (int p = 0; p < kNumClasses; ++p) {
    std::snprintf(line, sizeof(line), " %9s", className(p));
    out += line;
  }
  out += "\n";
  for (int t = 0; t < kNumClasses; ++t) {
    if (whole.truthCount(t) == 0) continue;
    std::snprintf(line, sizeof(line), "  %-7s", className(t));
    out += line;
    for (int p = 0; p < kNumClasses; ++p) {
      std::snprintf(line, sizeof(line), " %9llu", static_cast<unsigned long long>(whole.confusion()[t][p]));
      out += line;
    }
    out += "\n";
  }
  return out;
}

std::string RunEvaluation::brief() const {
  std::string out;
  char line[256];
  const ClassificationMetrics all = overall();
  const ClassificationMetrics ad = adapted();
  std::snprintf(line, sizeof(line), "  %-7s %13s %13s   (adapted: from frame %zu after the start and each event)\n", "",
                "recall", "precision", adapt_frames_);
  out += line;
  std::snprintf(line, sizeof(line), "  %-7s %6s %6s %6s %6s\n", "class", "all", "adapt", "all", "adapt");
  out += line;
  for (int k : trainableClasses()) {
    if (all.truthCount(k) == 0) continue;
    std::snprintf(line, sizeof(line), "  %-7s %6.3f %6.3f %6.3f %6.3f\n", className(k), all.recall(k), ad.recall(k),
                  all.precision(k), ad.precision(k));
    out += line;
  }
  for (const SegmentSummary& seg : segments()) {
    if (seg.first_frame == 0) continue;
    std::snprintf(line, sizeof(line),
                  "  after '%s' at frame %zu, cycles to settle (within %.2f of final recall):", seg.event.c_str(),
                  seg.first_frame, settle_tolerance_);
    out += line;
    for (int k : trainableClasses()) {
      if (seg.settle_cycles[k] < 0) continue;
      std::snprintf(line, sizeof(line), " %s %d", className(k), seg.settle_cycles[k]);
      out += line;
    }
    out += "\n";
  }
  return out;
}

std::string RunEvaluation::csv() const {
  std::string out = "frame,segment";
  for (int k = 0; k < kNumClasses; ++k) out += std::string(",recall_") + className(k) + ",precision_" + className(k);
  out += "\n";
  size_t segment = 0;
  size_t next_event = 0;
  char cell[64];
  for (size_t f = 0; f < frame_metrics_.size(); ++f) {
    while (next_event < events_.size() && events_[next_event].first <= f) {
      if (events_[next_event].first > 0 || next_event > 0) ++segment;
      ++next_event;
    }
    out += std::to_string(f) + "," + std::to_string(segment);
    for (int k = 0; k < kNumClasses; ++k) {
      std::snprintf(cell, sizeof(cell), ",%.5f,%.5f", frame_metrics_[f].recall(k), frame_metrics_[f].precision(k));
      out += cell;
    }
    out += "\n";
  }
  return out;
}

}  // namespace core
}  // namespace act_color
