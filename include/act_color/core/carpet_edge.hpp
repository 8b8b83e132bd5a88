#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "act_color/core/omni_camera_model.hpp"

namespace act_color {
namespace core {

// Beyond the paper (ActParams::carpet_edge): the lines and the robots stand on the carpet, so white
// seen beyond the carpet's outer edge is the hall (a white wall, a shirt, a lamp, a bright floor),
// and so is black there unless a robot stands on the carpet in that direction (its body then reaches
// beyond the edge in the image), whatever the table says of their colors. The edge is found in the
// classified image itself, without the pose: along each of kSectors sectors of bearings, the
// farthest ground distance (in bins of kBinM) at which at least kMinGreenShare of the imaged pixels
// (and kMinGreenPixels) are green; a sector's edge is the farthest of its own and its kSpreadSectors
// neighbours' on either side (a robot or a person standing on the carpet hides it in a few
// sectors). Beyond the edge plus kMarginM (the outer line and the blur round it, where the carpet
// ends right behind the line) white is labelled unknown, and black too in a sector where no black
// lies within that reach in it or its kSpreadSectors neighbours. A sector where no green is seen
// keeps its labels: nothing is known there.
class CarpetEdge {
 public:
  explicit CarpetEdge(const OmniCameraModel& camera);

  // labels: CV_8UC1 of the camera's size (class ids), as core::Segmenter gives them. Returns how
  // many pixels were labelled kUnknown; labels of another size or type are left as they are (0).
  uint32_t unlabelBeyond(cv::Mat& labels) const;

  static constexpr int kSectors = 256;
  static constexpr double kBinM = 0.1;
  // The last bin, kBins: above the horizon or farther than the bins before it.
  static constexpr int kBins = 254;
  static constexpr double kMinGreenShare = 0.25;
  static constexpr uint32_t kMinGreenPixels = 2;
  static constexpr int kSpreadSectors = 2;
  static constexpr double kMarginM = 0.3;

 private:
  static constexpr int kCells = kSectors << 8;  // sector << 8 | bin
  int width_ = 0, height_ = 0;
  // The imaged pixels (not outside the mirror, the own chassis or the calibration's self mask) by
  // cell: those of cell c are pixels_[cell_start_[c] .. cell_start_[c + 1]). A frame reads the
  // cells from the hall inwards to the edge, and beyond it, not the whole image (runs along the
  // rows instead of pixels took twice as long: a cell is a pixel or two wide).
  std::vector<uint32_t> cell_start_;
  std::vector<uint32_t> pixels_;
};

}  // namespace core
}  // namespace act_color
