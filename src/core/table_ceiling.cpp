#include "act_color/core/table_ceiling.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace act_color {
namespace core {

TableCeiling::TableCeiling(int bits_per_channel, ColorSpace space)
    : bits_(bits_per_channel), space_(space), index_(bits_per_channel, space) {
  counts_.assign(index_.size(), std::array<uint32_t, kNumClasses>{});
}

void TableCeiling::clear() {
  std::fill(counts_.begin(), counts_.end(), std::array<uint32_t, kNumClasses>{});
  pixels_ = 0;
}

void TableCeiling::add(const ImageView& image, const cv::Mat& truth) {
  if (truth.type() != CV_8UC1 || truth.cols != image.width || truth.rows != image.height) {
    throw std::invalid_argument("truth must be a mono8 image of the image's size");
  }
  if (nativeColorSpace(image.format) != space_) throw std::invalid_argument("image is not in the table's color space");
  for (int v = 0; v < image.height; ++v) {
    const uint8_t* t = truth.ptr<uint8_t>(v);
    for (int u = 0; u < image.width; ++u) {
      if (t[u] >= kNumClasses) continue;
      uint8_t c[3];
      image.color(u, v, c);
      ++counts_[index_.index(c[0], c[1], c[2])][t[u]];
      ++pixels_;
    }
  }
}

ColorLut TableCeiling::table() const {
  ColorLut lut(bits_, space_);
  for (uint32_t cell = 0; cell < counts_.size(); ++cell) {
    const auto& n = counts_[cell];
    int best = kUnknown;
    for (int k = 1; k < kNumClasses; ++k) {
      if (n[k] > n[best]) best = k;
    }
    if (best != kUnknown) lut.set(cell, static_cast<uint8_t>(best));
  }
  return lut;
}

ClassificationMetrics TableCeiling::metrics() const {
  // The confusion of the majority table follows from the counts alone: every pixel of a cell is
  // classified as the cell's majority class.
  std::array<std::array<uint64_t, kNumClasses>, kNumClasses> confusion{};
  for (const auto& n : counts_) {
    int best = kUnknown;
    for (int k = 1; k < kNumClasses; ++k) {
      if (n[k] > n[best]) best = k;
    }
    for (int t = 0; t < kNumClasses; ++t) confusion[t][best] += n[t];
  }
  ClassificationMetrics m;
  m.setConfusion(confusion);
  return m;
}

FalsePixelSources::FalsePixelSources(int bits_per_channel, ColorSpace space) : index_(bits_per_channel, space) {
  classified_.assign(index_.size(), {});
  right_.assign(index_.size(), {});
}

void FalsePixelSources::clear() {
  std::fill(classified_.begin(), classified_.end(), std::array<uint32_t, kNumClasses>{});
  std::fill(right_.begin(), right_.end(), std::array<uint32_t, kNumClasses>{});
}

void FalsePixelSources::add(const ImageView& image, const cv::Mat& labels, const cv::Mat& truth) {
  if (truth.type() != CV_8UC1 || truth.cols != image.width || truth.rows != image.height || labels.type() != CV_8UC1 ||
      labels.size() != truth.size()) {
    throw std::invalid_argument("labels and truth must be mono8 images of the image's size");
  }
  if (nativeColorSpace(image.format) != index_.colorSpace()) {
    throw std::invalid_argument("image is not in the table's color space");
  }
  for (int v = 0; v < image.height; ++v) {
    const uint8_t* t = truth.ptr<uint8_t>(v);
    const uint8_t* l = labels.ptr<uint8_t>(v);
    for (int u = 0; u < image.width; ++u) {
      if (t[u] >= kNumClasses || l[u] >= kNumClasses) continue;
      uint8_t c[3];
      image.color(u, v, c);
      const uint32_t cell = index_.index(c[0], c[1], c[2]);
      ++classified_[cell][l[u]];
      right_[cell][l[u]] += l[u] == t[u];
    }
  }
}

std::array<FalsePixels, kNumClasses> FalsePixelSources::sources(const ColorLut& majority) const {
  if (majority.size() != index_.size()) throw std::invalid_argument("the majority table has another size");
  std::array<FalsePixels, kNumClasses> out{};
  const int bits = index_.bitsPerChannel();
  const uint32_t top = (1u << bits) - 1;
  for (uint32_t cell = 0; cell < classified_.size(); ++cell) {
    const uint8_t m = majority.at(cell);
    const bool at_top = (cell >> (2 * bits)) == top || ((cell >> bits) & top) == top || (cell & top) == top;
    for (int k = 0; k < kNumClasses; ++k) {
      const uint64_t n = classified_[cell][k], wrong = n - right_[cell][k];
      out[k].classified += n;
      if (wrong == 0) continue;
      (m == k ? out[k].shared : m == kUnknown ? out[k].hall : out[k].other) += wrong;
      if (at_top) out[k].top += wrong;
    }
  }
  return out;
}

RecallCost::RecallCost(int bits_per_channel, ColorSpace space) : index_(bits_per_channel, space) {
  counts_.assign(index_.size(), std::array<uint32_t, 2>{});
}

void RecallCost::clear() { std::fill(counts_.begin(), counts_.end(), std::array<uint32_t, 2>{}); }

double RecallCost::leastUnwantedShare(double recall) const {
  std::vector<std::array<uint32_t, 2>> cells;  // the cells with wanted pixels: no other is worth taking
  uint64_t wanted = 0, unwanted = 0;
  for (const auto& n : counts_) {
    wanted += n[0];
    unwanted += n[1];
    if (n[0] > 0) cells.push_back(n);
  }
  if (wanted == 0 || unwanted == 0) return -1.0;
  const auto need = static_cast<size_t>(std::ceil(std::clamp(recall, 0.0, 1.0) * static_cast<double>(wanted) - 1e-9));
  // A knapsack over whole cells: least[w] is the fewest unwanted pixels of a set of cells with at
  // least w wanted ones (w capped at the need).
  constexpr uint64_t kNone = std::numeric_limits<uint64_t>::max();
  std::vector<uint64_t> least(need + 1, kNone);
  least[0] = 0;
  for (const auto& n : cells) {
    for (size_t w = need + 1; w-- > 0;) {
      if (least[w] == kNone) continue;
      const size_t to = std::min<size_t>(need, w + n[0]);
      least[to] = std::min(least[to], least[w] + n[1]);
    }
  }
  return static_cast<double>(least[need]) / static_cast<double>(unwanted);
}

}  // namespace core
}  // namespace act_color
