#pragma once

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "act_color/core/types.hpp"

namespace act_color {
namespace core {

// Confusion counts of label images against truth; truth pixels of kNotImaged are skipped.
class ClassificationMetrics {
 public:
  void add(const cv::Mat& labels, const cv::Mat& truth);
  void clear() { confusion_ = {}; }
  // Adds another's counts (e.g. per-frame metrics into a run's).
  void merge(const ClassificationMetrics& other);
  // Replaces the counts (e.g. a confusion computed elsewhere).
  void setConfusion(const std::array<std::array<uint64_t, kNumClasses>, kNumClasses>& confusion) {
    confusion_ = confusion;
  }

  // confusion()[truth][predicted]
  const std::array<std::array<uint64_t, kNumClasses>, kNumClasses>& confusion() const { return confusion_; }
  uint64_t truthCount(int k) const;
  uint64_t predictedCount(int k) const;
  // TP / (TP + FN); NaN when the class is absent from the truth.
  double recall(int k) const;
  // TP / (TP + FP); NaN when nothing was classified as k.
  double precision(int k) const;
  // Paper, eq. 6: sum over the classes of (1 - recall); lower is better. Absent classes count 0.
  double fitness(const std::vector<int>& classes) const;

  // One line per class present in truth or prediction: recall, precision, pixel counts.
  std::string report() const;

 private:
  std::array<std::array<uint64_t, kNumClasses>, kNumClasses> confusion_{};
};

// The classes ACT can train: green, white, yellow, blue, black.
const std::vector<int>& trainableClasses();

}  // namespace core
}  // namespace act_color
