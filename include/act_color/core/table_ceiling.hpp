#pragma once

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "act_color/core/color_lut.hpp"
#include "act_color/core/image_view.hpp"
#include "act_color/core/metrics.hpp"
#include "act_color/core/types.hpp"

namespace act_color {
namespace core {

// The best any fixed color table can do on a set of frames with truth: the table whose every
// cell holds the majority class of the truth among the pixels of that color. It maximises pixel
// accuracy; per class it is the honest reference for what a color table can reach on that data
// (issue 11's "ceiling"), since whatever ACT does, it ends up as one such table per frame.
class TableCeiling {
 public:
  explicit TableCeiling(int bits_per_channel = 6, ColorSpace space = ColorSpace::kRgb);

  // Counts every pixel of `image` whose truth is a class (kNotImaged is skipped). Throws
  // std::invalid_argument when sizes or the color space do not fit.
  void add(const ImageView& image, const cv::Mat& truth);
  void clear();
  uint64_t pixels() const { return pixels_; }

  // The majority-vote table (ties go to the lower class id; empty cells are kUnknown).
  ColorLut table() const;
  // Recall and precision of that table on the frames added.
  ClassificationMetrics metrics() const;

 private:
  int bits_;
  ColorSpace space_;
  ColorLut index_;                                         // for its index()
  std::vector<std::array<uint32_t, kNumClasses>> counts_;  // per cell, pixels of each truth class
  uint64_t pixels_ = 0;
};

// Where a classifier's false pixels of each class lie, against the ceiling's table (issue 11's
// precision gap, taken apart): in cells whose majority is the class itself (the ceiling has them
// too), in cells the hall's pixels (truth kUnknown) dominate, or in another class's cells; and how
// many of them are in a cell at the top of a channel (a clipped or nearly clipped color).
struct FalsePixels {
  uint64_t classified = 0;  // pixels classified as the class
  uint64_t shared = 0, hall = 0, other = 0, top = 0;
};

class FalsePixelSources {
 public:
  explicit FalsePixelSources(int bits_per_channel = 6, ColorSpace space = ColorSpace::kRgb);

  // Counts the pixels of `labels` (a classification of `image`) against `truth` (kNotImaged is
  // skipped). Throws std::invalid_argument when sizes or the color space do not fit.
  void add(const ImageView& image, const cv::Mat& labels, const cv::Mat& truth);
  void clear();
  // Per class, against `majority` (TableCeiling::table() of the same frames).
  std::array<FalsePixels, kNumClasses> sources(const ColorLut& majority) const;

 private:
  ColorLut index_;
  // Per cell and class: pixels classified as the class, and of those, truly of it.
  std::vector<std::array<uint32_t, kNumClasses>> classified_, right_;
};

// What a fixed table must give away to reach a recall: from the colors of one class's pixels
// ("wanted") and of pixels it must not take ("unwanted", e.g. the hall), the least share of the
// unwanted pixels that any fixed table classifies as the class while it classifies at least a
// given share of the wanted ones as the class (exact: a knapsack over the cells). A saturated line
// and a saturated wall are one cell: then the share is large whatever a trainer does.
class RecallCost {
 public:
  explicit RecallCost(int bits_per_channel = 6, ColorSpace space = ColorSpace::kRgb);

  void addWanted(const uint8_t c[3]) { ++counts_[index_.index(c[0], c[1], c[2])][0]; }
  void addUnwanted(const uint8_t c[3]) { ++counts_[index_.index(c[0], c[1], c[2])][1]; }
  void clear();
  // The least unwanted share at `recall` (0-1) of the wanted pixels; -1 without wanted or
  // unwanted pixels.
  double leastUnwantedShare(double recall) const;

 private:
  ColorLut index_;
  std::vector<std::array<uint32_t, 2>> counts_;  // per cell: wanted, unwanted
};

}  // namespace core
}  // namespace act_color
