#include "act_color/core/metrics.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace act_color {
namespace core {

void ClassificationMetrics::add(const cv::Mat& labels, const cv::Mat& truth) {
  if (labels.type() != CV_8UC1 || truth.type() != CV_8UC1 || labels.size() != truth.size()) {
    throw std::invalid_argument("labels and truth must be mono8 images of the same size");
  }
  for (int v = 0; v < labels.rows; ++v) {
    const uint8_t* l = labels.ptr<uint8_t>(v);
    const uint8_t* t = truth.ptr<uint8_t>(v);
    for (int u = 0; u < labels.cols; ++u) {
      if (t[u] >= kNumClasses) continue;  // not imaged
      const uint8_t predicted = l[u] < kNumClasses ? l[u] : static_cast<uint8_t>(kUnknown);
      ++confusion_[t[u]][predicted];
    }
  }
}

void ClassificationMetrics::merge(const ClassificationMetrics& other) {
  for (int t = 0; t < kNumClasses; ++t) {
    for (int p = 0; p < kNumClasses; ++p) confusion_[t][p] += other.confusion_[t][p];
  }
}

uint64_t ClassificationMetrics::truthCount(int k) const {
  uint64_t n = 0;
  for (int p = 0; p < kNumClasses; ++p) n += confusion_[k][p];
  return n;
}

uint64_t ClassificationMetrics::predictedCount(int k) const {
  uint64_t n = 0;
  for (int t = 0; t < kNumClasses; ++t) n += confusion_[t][k];
  return n;
}

double ClassificationMetrics::recall(int k) const {
  const uint64_t n = truthCount(k);
  return n == 0 ? std::numeric_limits<double>::quiet_NaN() : static_cast<double>(confusion_[k][k]) / n;
}

double ClassificationMetrics::precision(int k) const {
  const uint64_t n = predictedCount(k);
  return n == 0 ? std::numeric_limits<double>::quiet_NaN() : static_cast<double>(confusion_[k][k]) / n;
}

double ClassificationMetrics::fitness(const std::vector<int>& classes) const {
  double f = 0.0;
  for (int k : classes) {
    const double r = recall(k);
    if (!std::isnan(r)) f += 1.0 - r;  // eq. 6
  }
  return f;
}

std::string ClassificationMetrics::report() const {
  std::string out;
  char line[160];
  std::snprintf(line, sizeof(line), "%-8s %8s %9s %12s %12s\n", "class", "recall", "precision", "truth_px",
                "predicted_px");
  out += line;
  for (int k = 0; k < kNumClasses; ++k) {
    if (truthCount(k) == 0 && predictedCount(k) == 0) continue;
    std::snprintf(line, sizeof(line), "%-8s %8.4f %9.4f %12llu %12llu\n", className(k), recall(k), precision(k),
                  static_cast<unsigned long long>(truthCount(k)), static_cast<unsigned long long>(predictedCount(k)));
    out += line;
  }
  return out;
}

const std::vector<int>& trainableClasses() {
  static const std::vector<int> kClasses = {kGreen, kWhite, kYellow, kBlue, kBlack};
  return kClasses;
}

}  // namespace core
}  // namespace act_color
