#pragma once

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

namespace act_color {
namespace core {

// Pixel layouts the package accepts (ROS encodings rgb8, bgr8, yuv422 = UYVY).
enum class PixelFormat : uint8_t { kRgb8 = 0, kBgr8 = 1, kUyvy = 2 };

// Color space of look-up tables and clusters: the camera's own, so that classification needs no
// conversion: RGB for rgb8/bgr8 images, YUV for yuv422.
enum class ColorSpace : uint8_t { kRgb = 0, kYuv = 1 };

ColorSpace nativeColorSpace(PixelFormat format);
// Bytes per pixel of a row: 2 for yuv422 (UYVY, two pixels in 4 bytes), 3 for rgb8 and bgr8.
inline size_t bytesPerPixel(PixelFormat format) { return format == PixelFormat::kUyvy ? 2 : 3; }
// Parses a ROS encoding string; false for anything unsupported.
bool pixelFormatFromEncoding(const std::string& encoding, PixelFormat* format);
const char* encodingName(PixelFormat format);
// Why an image of width x height px cannot be one of a camera calibrated for camera_width x
// camera_height ("image is ... px, the calibration is for ..."); empty when the sizes agree.
std::string imageSizeProblem(int width, int height, int camera_width, int camera_height);

// A non-owning view of an image in one of the supported layouts.
struct ImageView {
  const uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  size_t step = 0;  // bytes per row
  PixelFormat format = PixelFormat::kRgb8;

  ImageView() = default;
  ImageView(const uint8_t* d, int w, int h, size_t s, PixelFormat f)
      : data(d), width(w), height(h), step(s), format(f) {}
  // rgb8/bgr8: CV_8UC3; UYVY: CV_8UC2 (OpenCV's layout for YUV 4:2:2).
  static ImageView fromMat(const cv::Mat& mat, PixelFormat format);

  // Color of pixel (u, v) in the native color space: (R, G, B) or (Y, U, V).
  void color(int u, int v, uint8_t out[3]) const {
    const uint8_t* row = data + static_cast<size_t>(v) * step;
    if (format == PixelFormat::kUyvy) {
      const uint8_t* p = row + 4 * (u >> 1);
      out[0] = p[(u & 1) ? 3 : 1];
      out[1] = p[0];
      out[2] = p[2];
      return;
    }
    const uint8_t* p = row + 3 * u;
    const bool bgr = format == PixelFormat::kBgr8;
    out[0] = p[bgr ? 2 : 0];
    out[1] = p[1];
    out[2] = p[bgr ? 0 : 2];
  }

  // Intensity used by the white filter (eq. 1): R+G+B, or 3*Y, so both spaces compare alike.
  int intensity(int u, int v) const {
    const uint8_t* row = data + static_cast<size_t>(v) * step;
    switch (format) {
      case PixelFormat::kRgb8:
      case PixelFormat::kBgr8: {
        const uint8_t* p = row + 3 * u;
        return p[0] + p[1] + p[2];
      }
      case PixelFormat::kUyvy:
        return 3 * row[4 * (u >> 1) + ((u & 1) ? 3 : 1)];
    }
    return 0;
  }
};

// Pixels by index, column and row, for loops over many pixels of one image. PackedPixels: rgb8 or
// bgr8 rows without padding, where a pixel's bytes lie at 3 x its index; AnyPixels: every format
// and row step. withPixels calls fn with the one that fits the image: the layout is decided once
// per loop, not at every pixel.
template <bool kBgr>
struct PackedPixels {
  const uint8_t* data;
  const uint8_t* address(uint32_t pixel, int, int) const { return data + 3 * static_cast<size_t>(pixel); }
  void color(uint32_t pixel, int, int, uint8_t out[3]) const {
    const uint8_t* p = address(pixel, 0, 0);
    out[0] = p[kBgr ? 2 : 0];
    out[1] = p[1];
    out[2] = p[kBgr ? 0 : 2];
  }
};

struct AnyPixels {
  const ImageView& image;
  const uint8_t* address(uint32_t, int u, int v) const {
    return image.data + static_cast<size_t>(v) * image.step + static_cast<size_t>(u) * bytesPerPixel(image.format);
  }
  void color(uint32_t, int u, int v, uint8_t out[3]) const { image.color(u, v, out); }
};

// Rows without padding: a pixel's bytes lie at bytesPerPixel x its index.
inline bool packedRows(const ImageView& image) {
  return image.step == bytesPerPixel(image.format) * static_cast<size_t>(image.width);
}

template <class Fn>
void withPixels(const ImageView& image, Fn&& fn) {
  const bool packed = packedRows(image);
  if (packed && image.format == PixelFormat::kRgb8) {
    fn(PackedPixels<false>{image.data});
  } else if (packed && image.format == PixelFormat::kBgr8) {
    fn(PackedPixels<true>{image.data});
  } else {
    fn(AnyPixels{image});
  }
}

// Converts an rgb8 image (CV_8UC3) to UYVY (CV_8UC2), BT.601 full range; for tests and the
// simulator's yuv422 output.
cv::Mat rgbToUyvy(const cv::Mat& rgb);

}  // namespace core
}  // namespace act_color
