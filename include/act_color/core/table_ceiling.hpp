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

}  // namespace core
}  // namespace act_color
