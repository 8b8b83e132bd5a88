#include "act_color/core/lut_image.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

#include "act_color/core/types.hpp"

namespace act_color {
namespace core {

const char* channelName(ColorSpace space, int channel) {
  static const char* const kRgb[3] = {"R", "G", "B"};
  static const char* const kYuv[3] = {"Y", "U", "V"};
  return (space == ColorSpace::kYuv ? kYuv : kRgb)[channel];
}

namespace {

constexpr int kPadPx = 8;
constexpr int kHeaderPx = 44;
constexpr int kLabelPx = 18;
constexpr int kLegendPx = 28;
constexpr int kMinWidthPx = 820;
const cv::Scalar kBackground(235, 235, 235);  // also chroma bins no color of the table falls in
const cv::Scalar kUnknownColor(64, 64, 64);   // darker than the palette's grey: stands back
const cv::Scalar kText(0, 0, 0);

cv::Scalar classColor(int class_id) {
  if (class_id <= kUnknown || class_id >= kNumClasses) return kUnknownColor;
  const auto& rgb = classPalette()[class_id];
  return cv::Scalar(rgb[2], rgb[1], rgb[0]);  // BGR, as cv::imwrite takes it
}

// The most frequent class other than unknown; unknown when there is none; ties to the lower id.
int dominantClass(const uint32_t* counts) {
  int best = kUnknown;
  for (int k = 1; k < kNumClasses; ++k) {
    if (counts[k] > 0 && (best == kUnknown || counts[k] > counts[best])) best = k;
  }
  return best;
}

// A canvas for `maps` square maps of `map_px`, with the header and the legend drawn.
struct Canvas {
  cv::Mat image;
  int cols = 1;
  int map_px = 0;
  cv::Point origin(int k) const {
    return cv::Point(kPadPx + (k % cols) * (map_px + kPadPx),
                     kHeaderPx + (k / cols) * (kLabelPx + map_px + kPadPx) + kLabelPx);
  }
};

void text(cv::Mat& image, const std::string& s, cv::Point at) {
  cv::putText(image, s, at, cv::FONT_HERSHEY_SIMPLEX, 0.4, kText, 1, cv::LINE_AA);
}

Canvas makeCanvas(int maps, int map_px, const std::string& heading, const std::string& subtitle) {
  Canvas c;
  c.cols = maps <= 4 ? maps : (maps <= 16 ? 4 : 8);
  c.map_px = map_px;
  const int rows = (maps + c.cols - 1) / c.cols;
  const int width = std::max(kMinWidthPx, kPadPx + c.cols * (map_px + kPadPx));
  const int height = kHeaderPx + rows * (kLabelPx + map_px + kPadPx) + kLegendPx;
  c.image = cv::Mat(height, width, CV_8UC3, kBackground);
  text(c.image, heading, cv::Point(kPadPx, 17));
  text(c.image, subtitle, cv::Point(kPadPx, 35));
  const int legend_y = height - kLegendPx + 6;
  for (int k = 0; k < kNumClasses; ++k) {
    const int x = kPadPx + k * 110;
    cv::rectangle(c.image, cv::Rect(x, legend_y, 14, 14), classColor(k), cv::FILLED);
    cv::rectangle(c.image, cv::Rect(x, legend_y, 14, 14), cv::Scalar(160, 160, 160), 1);
    text(c.image, className(k), cv::Point(x + 19, legend_y + 12));
  }
  return c;
}

// BT.601 full range, as rgbToUyvy converts.
uint8_t clampByte(double x) { return static_cast<uint8_t>(std::min(255.0, std::max(0.0, std::round(x)))); }

}  // namespace

cv::Mat renderLutSlices(const ColorLut& lut, int slices, const std::string& heading) {
  if (slices < 1 || slices > (1 << lut.bitsPerChannel())) {
    throw std::invalid_argument("slices must be in [1, " + std::to_string(1 << lut.bitsPerChannel()) + "], is " +
                                std::to_string(slices));
  }
  const ColorSpace space = lut.colorSpace();
  const int bits = lut.bitsPerChannel();
  const uint32_t n = 1u << bits;
  const int cell_px = kLutSliceMapPx / static_cast<int>(n);
  const int shift = 8 - bits;
  const std::string c0 = channelName(space, 0), c1 = channelName(space, 1), c2 = channelName(space, 2);
  Canvas canvas = makeCanvas(slices, kLutSliceMapPx, heading,
                             "slices along " + c0 + "; in each x = " + c1 + " 0-255 (right), y = " + c2 +
                                 " 0-255 (up), the most frequent class of the slice, unknown dark grey");
  uint32_t counts[kNumClasses];
  for (int s = 0; s < slices; ++s) {
    const uint32_t begin = s * n / slices, end = (s + 1) * n / slices;
    const cv::Point o = canvas.origin(s);
    text(canvas.image, c0 + " " + std::to_string(begin << shift) + "-" + std::to_string((end << shift) - 1),
         cv::Point(o.x, o.y - 5));
    for (uint32_t i1 = 0; i1 < n; ++i1) {
      for (uint32_t i2 = 0; i2 < n; ++i2) {
        std::fill(std::begin(counts), std::end(counts), 0u);
        for (uint32_t i0 = begin; i0 < end; ++i0) {
          const uint8_t k = lut.at(lut.cellIndex(i0, i1, i2));
          if (k < kNumClasses) ++counts[k];
        }
        const cv::Rect r(o.x + static_cast<int>(i1) * cell_px, o.y + static_cast<int>(n - 1 - i2) * cell_px, cell_px,
                         cell_px);
        cv::rectangle(canvas.image, r, classColor(dominantClass(counts)), cv::FILLED);
      }
    }
  }
  return canvas.image;
}

cv::Mat renderLutChroma(const ColorLut& lut, const std::string& heading) {
  const bool yuv = lut.colorSpace() == ColorSpace::kYuv;
  const int bits = lut.bitsPerChannel();
  const uint32_t n = 1u << bits;
  const int cell_px = kLutChromaMapPx / static_cast<int>(n);
  const int shift = 8 - bits;
  const double half = shift > 0 ? 0.5 * (1 << shift) : 0.0;
  Canvas canvas = makeCanvas(1, kLutChromaMapPx, heading,
                             "U-V map: x = U 0-255 (right), y = V 0-255 (up), the most frequent class over Y, unknown "
                             "dark grey");
  std::vector<uint32_t> counts(size_t{n} * n * kNumClasses, 0);
  std::vector<uint8_t> seen(size_t{n} * n, 0);
  for (uint32_t i0 = 0; i0 < n; ++i0) {
    for (uint32_t i1 = 0; i1 < n; ++i1) {
      for (uint32_t i2 = 0; i2 < n; ++i2) {
        uint32_t u = i1, v = i2;
        if (!yuv) {
          const double r = (i0 << shift) + half, g = (i1 << shift) + half, b = (i2 << shift) + half;
          u = clampByte(-0.168736 * r - 0.331264 * g + 0.5 * b + 128) >> shift;
          v = clampByte(0.5 * r - 0.418688 * g - 0.081312 * b + 128) >> shift;
        }
        const size_t bin = size_t{u} * n + v;
        seen[bin] = 1;
        const uint8_t k = lut.at(lut.cellIndex(i0, i1, i2));
        if (k < kNumClasses) ++counts[bin * kNumClasses + k];
      }
    }
  }
  const cv::Point o = canvas.origin(0);
  text(canvas.image, yuv ? "U-V over all Y" : "RGB cells at their centres' BT.601 U, V; light grey: none",
       cv::Point(o.x, o.y - 5));
  for (uint32_t u = 0; u < n; ++u) {
    for (uint32_t v = 0; v < n; ++v) {
      const size_t bin = size_t{u} * n + v;
      if (!seen[bin]) continue;
      const cv::Rect r(o.x + static_cast<int>(u) * cell_px, o.y + static_cast<int>(n - 1 - v) * cell_px, cell_px,
                       cell_px);
      cv::rectangle(canvas.image, r, classColor(dominantClass(&counts[bin * kNumClasses])), cv::FILLED);
    }
  }
  return canvas.image;
}

}  // namespace core
}  // namespace act_color
