#include "act_color/core/image_view.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace act_color {
namespace core {

ColorSpace nativeColorSpace(PixelFormat format) {
  return format == PixelFormat::kUyvy ? ColorSpace::kYuv : ColorSpace::kRgb;
}

std::string imageSizeProblem(int width, int height, int camera_width, int camera_height) {
  if (width == camera_width && height == camera_height) return "";
  return "image is " + std::to_string(width) + "x" + std::to_string(height) + " px, the calibration is for " +
         std::to_string(camera_width) + "x" + std::to_string(camera_height);
}

bool pixelFormatFromEncoding(const std::string& encoding, PixelFormat* format) {
  if (encoding == "rgb8") {
    *format = PixelFormat::kRgb8;
  } else if (encoding == "bgr8") {
    *format = PixelFormat::kBgr8;
  } else if (encoding == "yuv422" || encoding == "uyvy") {
    *format = PixelFormat::kUyvy;
  } else {
    return false;
  }
  return true;
}

const char* encodingName(PixelFormat format) {
  switch (format) {
    case PixelFormat::kRgb8:
      return "rgb8";
    case PixelFormat::kBgr8:
      return "bgr8";
    case PixelFormat::kUyvy:
      return "yuv422";
  }
  return "?";
}

ImageView ImageView::fromMat(const cv::Mat& mat, PixelFormat format) {
  const int expected_type = format == PixelFormat::kUyvy ? CV_8UC2 : CV_8UC3;
  if (mat.type() != expected_type)
    throw std::invalid_argument(std::string("image type does not fit ") + encodingName(format));
  if (format == PixelFormat::kUyvy && mat.cols % 2 != 0)
    throw std::invalid_argument("yuv422 images need an even width");
  return ImageView(mat.data, mat.cols, mat.rows, mat.step, format);
}

cv::Mat rgbToUyvy(const cv::Mat& rgb) {
  CV_Assert(rgb.type() == CV_8UC3 && rgb.cols % 2 == 0);
  cv::Mat out(rgb.rows, rgb.cols, CV_8UC2);
  auto clamp = [](double x) { return static_cast<uint8_t>(std::min(255.0, std::max(0.0, std::round(x)))); };
  for (int v = 0; v < rgb.rows; ++v) {
    const uint8_t* in = rgb.ptr<uint8_t>(v);
    uint8_t* o = out.ptr<uint8_t>(v);
    for (int u = 0; u < rgb.cols; u += 2) {
      double y[2], cb = 0, cr = 0;
      for (int k = 0; k < 2; ++k) {
        const double r = in[3 * (u + k)], g = in[3 * (u + k) + 1], b = in[3 * (u + k) + 2];
        y[k] = 0.299 * r + 0.587 * g + 0.114 * b;
        cb += 0.5 * (-0.168736 * r - 0.331264 * g + 0.5 * b + 128);
        cr += 0.5 * (0.5 * r - 0.418688 * g - 0.081312 * b + 128);
      }
      o[2 * u + 0] = clamp(cb);
      o[2 * u + 1] = clamp(y[0]);
      o[2 * u + 2] = clamp(cr);
      o[2 * u + 3] = clamp(y[1]);
    }
  }
  return out;
}

}  // namespace core
}  // namespace act_color
