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

}  // namespace core
}  // namespace act_color
