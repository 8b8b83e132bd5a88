#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/color_lut.hpp"
#include "act_color/core/image_view.hpp"

namespace act_color {
namespace core {

// A look-up table owned by someone else (e.g. a shared, immutable ColorLut message): the
// segmentation classifies with a table it must not copy.
struct LutView {
  const uint8_t* table = nullptr;
  size_t size = 0;
  int bits = 6;
  ColorSpace space = ColorSpace::kRgb;
};

// Classifies whole images with a look-up table.
class Segmenter {
 public:
  // Without a camera: every pixel is classified.
  Segmenter() = default;
  // With a camera: only pixels inside the mirror are classified, the rest are kUnknown. The pixels
  // of the camera's self mask (the own robot's struts, a cable) are kBlack whatever their color, as
  // the own chassis is: the contract's black is the robots, the own one included.
  explicit Segmenter(const CameraCalibration& camera);

  // labels: CV_8UC1 of the image's size, reallocated only when its size differs. Throws
  // std::invalid_argument when the table's color space does not fit the image's format or the
  // image size does not fit the camera.
  void classify(const ColorLut& lut, const ImageView& image, cv::Mat& labels) const;
  // The same with a borrowed table; also throws when the view is inconsistent (size vs bits).
  void classify(const LutView& lut, const ImageView& image, cv::Mat& labels) const;

 private:
  int width_ = 0;
  int height_ = 0;
  // Per row, the half-open column span inside the mirror; empty when no camera was given.
  std::vector<std::pair<int, int>> spans_;
  std::vector<uint32_t> self_pixels_;  // the camera's self mask, as pixel indices
};

// Class ids to the rgb8 palette of classPalette(); 255 (not imaged) becomes dark grey.
void colorizeLabels(const cv::Mat& labels, cv::Mat& rgb);

}  // namespace core
}  // namespace act_color
