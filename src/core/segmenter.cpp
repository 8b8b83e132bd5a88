#include "act_color/core/segmenter.hpp"

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace act_color {
namespace core {

Segmenter::Segmenter(const CameraCalibration& camera) : width_(camera.width), height_(camera.height) {
  // Inside the mirror: r <= mirror radius (and the elevation table's end), as OmniCameraModel.
  const double r_max = std::min(camera.mirror_radius_px, camera.elevation_map.back().first);
  spans_.resize(height_);
  for (int v = 0; v < height_; ++v) {
    const double dv = v - camera.center_v;
    const double half_sq = r_max * r_max - dv * dv;
    if (half_sq < 0) {
      spans_[v] = {0, 0};
      continue;
    }
    const double half = std::sqrt(half_sq);
    const int u0 = std::max(0, static_cast<int>(std::ceil(camera.center_u - half)));
    const int u1 = std::min(width_, static_cast<int>(std::floor(camera.center_u + half)) + 1);
    spans_[v] = {u0, std::max(u0, u1)};
  }
  // The own robot's pixels inside the mirror (the mask itself; OmniCameraModel's PixelRegion::kSelf,
  // which trains nothing, also takes their blurred edges).
  if (camera.self_mask.size() == static_cast<size_t>(width_) * height_) {
    for (int v = 0; v < height_; ++v) {
      for (int u = spans_[v].first; u < spans_[v].second; ++u) {
        const size_t i = static_cast<size_t>(v) * width_ + u;
        if (camera.self_mask[i] != 0) self_pixels_.push_back(static_cast<uint32_t>(i));
      }
    }
  }
}

namespace {

template <int I0, int I1, int I2, int kBytes>
void classifyRgbRow(const uint8_t* in, uint8_t* out, int u0, int u1, const uint8_t* table, int bits) {
  const int shift = 8 - bits;
  const int s1 = bits;
  const int s0 = 2 * bits;
  for (int u = u0; u < u1; ++u) {
    const uint8_t* p = in + kBytes * u;
    const uint32_t idx = (static_cast<uint32_t>(p[I0] >> shift) << s0) | (static_cast<uint32_t>(p[I1] >> shift) << s1) |
                         static_cast<uint32_t>(p[I2] >> shift);
    out[u] = table[idx];
  }
}

// The same cells as classifyRgbRow for a table of kBits per channel, four pixels per iteration:
// each pixel's three bytes are read as one 32-bit word (the fourth byte belongs to the next
// pixel, so the row's last pixel is done bytewise) and the index is formed with masks.
template <int kBits, bool kBgr>
void classifyRgbRowFast(const uint8_t* in, uint8_t* out, int u0, int u1, const uint8_t* table) {
  constexpr int kShift = 8 - kBits;
  constexpr uint32_t kMask = (1u << kBits) - 1;
  auto cell = [](const uint8_t* p) {
    uint32_t w;
    std::memcpy(&w, p, sizeof w);
    const uint32_t first = (w >> kShift) & kMask;         // byte 0
    const uint32_t second = (w >> (8 + kShift)) & kMask;  // byte 1
    const uint32_t third = (w >> (16 + kShift)) & kMask;  // byte 2
    return kBgr ? (third << (2 * kBits)) | (second << kBits) | first
                : (first << (2 * kBits)) | (second << kBits) | third;
  };
  int u = u0;
  const int last = u1 - 1;  // the last pixel may end the buffer: no 4-byte read there
  for (; u + 4 <= last; u += 4) {
    const uint8_t* p = in + 3 * u;
    const uint32_t a = cell(p), b = cell(p + 3), c = cell(p + 6), d = cell(p + 9);
    out[u] = table[a];
    out[u + 1] = table[b];
    out[u + 2] = table[c];
    out[u + 3] = table[d];
  }
  for (; u < last; ++u) out[u] = table[cell(in + 3 * u)];
  if (u < u1) classifyRgbRow<kBgr ? 2 : 0, 1, kBgr ? 0 : 2, 3>(in, out, u, u1, table, kBits);
}

void classifyUyvyRow(const uint8_t* in, uint8_t* out, int u0, int u1, const uint8_t* table, int bits) {
  const int shift = 8 - bits;
  for (int u = u0; u < u1; ++u) {
    const uint8_t* p = in + 4 * (u >> 1);
    const uint8_t y = p[(u & 1) ? 3 : 1];
    const uint32_t idx = (static_cast<uint32_t>(y >> shift) << (2 * bits)) |
                         (static_cast<uint32_t>(p[0] >> shift) << bits) | static_cast<uint32_t>(p[2] >> shift);
    out[u] = table[idx];
  }
}

}  // namespace

void Segmenter::classify(const ColorLut& lut, const ImageView& image, cv::Mat& labels) const {
  classify(LutView{lut.data(), lut.size(), lut.bitsPerChannel(), lut.colorSpace()}, image, labels);
}

void Segmenter::classify(const LutView& lut, const ImageView& image, cv::Mat& labels) const {
  if (lut.table == nullptr || lut.bits < 1 || lut.bits > 8 || lut.size != (size_t{1} << (3 * lut.bits))) {
    throw std::invalid_argument("the color table is inconsistent (" + std::to_string(lut.size) + " cells for " +
                                std::to_string(lut.bits) + " bits per channel)");
  }
  if (lut.space != nativeColorSpace(image.format)) {
    throw std::invalid_argument(std::string("the table's color space does not fit ") + encodingName(image.format) +
                                " images");
  }
  if (!spans_.empty()) {
    const std::string size = imageSizeProblem(image.width, image.height, width_, height_);
    if (!size.empty()) throw std::invalid_argument(size);
  }
  labels.create(image.height, image.width, CV_8UC1);
  const uint8_t* table = lut.table;
  const int bits = lut.bits;
  for (int v = 0; v < image.height; ++v) {
    const uint8_t* in = image.data + static_cast<size_t>(v) * image.step;
    uint8_t* out = labels.ptr<uint8_t>(v);
    int u0 = 0, u1 = image.width;
    if (!spans_.empty()) {
      u0 = spans_[v].first;
      u1 = spans_[v].second;
      std::fill(out, out + u0, static_cast<uint8_t>(kUnknown));
      std::fill(out + u1, out + image.width, static_cast<uint8_t>(kUnknown));
    }
    switch (image.format) {
      case PixelFormat::kRgb8:
        if (bits == 6) {
          classifyRgbRowFast<6, false>(in, out, u0, u1, table);
        } else {
          classifyRgbRow<0, 1, 2, 3>(in, out, u0, u1, table, bits);
        }
        break;
      case PixelFormat::kBgr8:
        if (bits == 6) {
          classifyRgbRowFast<6, true>(in, out, u0, u1, table);
        } else {
          classifyRgbRow<2, 1, 0, 3>(in, out, u0, u1, table, bits);
        }
        break;
      case PixelFormat::kUyvy:
        classifyUyvyRow(in, out, u0, u1, table, bits);
        break;
    }
  }
  uint8_t* out = labels.ptr<uint8_t>();  // continuous: made by create()
  for (const uint32_t i : self_pixels_) out[i] = kBlack;
}

void colorizeLabels(const cv::Mat& labels, cv::Mat& rgb) {
  CV_Assert(labels.type() == CV_8UC1);
  rgb.create(labels.rows, labels.cols, CV_8UC3);
  const auto& palette = classPalette();
  for (int v = 0; v < labels.rows; ++v) {
    const uint8_t* in = labels.ptr<uint8_t>(v);
    uint8_t* out = rgb.ptr<uint8_t>(v);
    for (int u = 0; u < labels.cols; ++u) {
      const uint8_t c = in[u];
      if (c < kNumClasses) {
        out[3 * u] = palette[c][0];
        out[3 * u + 1] = palette[c][1];
        out[3 * u + 2] = palette[c][2];
      } else {
        out[3 * u] = out[3 * u + 1] = out[3 * u + 2] = 40;
      }
    }
  }
}

}  // namespace core
}  // namespace act_color
