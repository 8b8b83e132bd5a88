// Helpers shared by act_benchmark and act_reproduce: scaled calibrations, baseline classifiers
// (CMVision-style bitmasks, per-class cv::inRange), a small timing harness and OpenCV line plots.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/class_cluster.hpp"
#include "act_color/core/types.hpp"

namespace act_color {
namespace tools {

// The default calibration scaled to another image size: the mirror image keeps its shape and fills
// the shorter side as it fills 580 px in the default one.
inline core::Calibration scaledCalibration(const core::Calibration& base, int width, int height) {
  core::Calibration c = base;
  const double s = static_cast<double>(std::min(width, height)) / std::min(base.camera.width, base.camera.height);
  c.camera.width = width;
  c.camera.height = height;
  c.camera.center_u = base.camera.center_u * s + 0.5 * (width - s * base.camera.width);
  c.camera.center_v = base.camera.center_v * s + 0.5 * (height - s * base.camera.height);
  c.camera.chassis_radius_px = base.camera.chassis_radius_px * s;
  c.camera.mirror_radius_px = base.camera.mirror_radius_px * s;
  for (auto& entry : c.camera.elevation_map) entry.first *= s;
  return c;
}

// Per-class axis-aligned color boxes (lo, hi per channel), the thresholds a team would hand-tune;
// here taken from trained clusters: mean +- `k` sigma / sqrt(3) per channel.
struct ColorBox {
  int class_id = 0;
  std::array<uint8_t, 3> lo{}, hi{};
};

inline std::vector<ColorBox> boxesFromClusters(const std::array<core::ClassCluster, core::kNumClasses>& clusters,
                                               double k = 2.5) {
  std::vector<ColorBox> boxes;
  for (int id = 1; id < core::kNumClasses; ++id) {
    if (!clusters[id].trained()) continue;
    ColorBox b;
    b.class_id = id;
    const double half = k * clusters[id].sigma() / std::sqrt(3.0);
    for (int ch = 0; ch < 3; ++ch) {
      b.lo[ch] = static_cast<uint8_t>(std::clamp(clusters[id].mean()[ch] - half, 0.0, 255.0));
      b.hi[ch] = static_cast<uint8_t>(std::clamp(clusters[id].mean()[ch] + half, 0.0, 255.0));
    }
    boxes.push_back(b);
  }
  return boxes;
}

// CMVision (Bruce, Balch, Veloso 2000): per channel a 256-entry table of class bitmasks; a pixel's
// classes are the AND of its three channels' masks, the first set bit wins.
class CmvisionClassifier {
 public:
  explicit CmvisionClassifier(const std::vector<ColorBox>& boxes) {
    for (auto& t : masks_) t.fill(0);
    class_of_bit_.fill(core::kUnknown);
    for (size_t i = 0; i < boxes.size() && i < 32; ++i) {
      for (int ch = 0; ch < 3; ++ch) {
        for (int v = boxes[i].lo[ch]; v <= boxes[i].hi[ch]; ++v) masks_[ch][v] |= 1u << i;
      }
      class_of_bit_[i] = static_cast<uint8_t>(boxes[i].class_id);
    }
  }
  // rgb: CV_8UC3; labels: CV_8UC1 (reallocated if needed).
  void classify(const cv::Mat& rgb, cv::Mat& labels) const {
    labels.create(rgb.rows, rgb.cols, CV_8UC1);
    for (int v = 0; v < rgb.rows; ++v) {
      const uint8_t* in = rgb.ptr<uint8_t>(v);
      uint8_t* out = labels.ptr<uint8_t>(v);
      for (int u = 0; u < rgb.cols; ++u) {
        const uint32_t m = masks_[0][in[3 * u]] & masks_[1][in[3 * u + 1]] & masks_[2][in[3 * u + 2]];
        out[u] = m ? class_of_bit_[__builtin_ctz(m)] : static_cast<uint8_t>(core::kUnknown);
      }
    }
  }

 private:
  std::array<std::array<uint32_t, 256>, 3> masks_;
  std::array<uint8_t, 32> class_of_bit_;
};

// What a team without a table would write: one cv::inRange per class over the whole image; the
// first class in the list wins where boxes overlap, as in CMVision (the boxes are applied in reverse
// order, each overwriting the ones before).
class InRangeClassifier {
 public:
  explicit InRangeClassifier(const std::vector<ColorBox>& boxes) : boxes_(boxes) {}
  void classify(const cv::Mat& rgb, cv::Mat& labels) const {
    labels.create(rgb.rows, rgb.cols, CV_8UC1);
    labels.setTo(core::kUnknown);
    for (auto it = boxes_.rbegin(); it != boxes_.rend(); ++it) {
      cv::inRange(rgb, cv::Scalar(it->lo[0], it->lo[1], it->lo[2]), cv::Scalar(it->hi[0], it->hi[1], it->hi[2]), mask_);
      labels.setTo(it->class_id, mask_);
    }
  }

 private:
  std::vector<ColorBox> boxes_;
  mutable cv::Mat mask_;
};

// Timing: `samples` samples of `batch` calls each; per-call times of the samples.
struct Timing {
  std::string name;
  int width = 0, height = 0;
  double median_ms = 0, min_ms = 0, p90_ms = 0;
  int samples = 0, batch = 0;
  double pixels_per_s() const { return median_ms > 0 ? width * static_cast<double>(height) / (median_ms * 1e-3) : 0; }
};

inline Timing timeIt(const std::string& name, int width, int height, const std::function<void()>& op, double sample_ms,
                     int samples) {
  using Clock = std::chrono::steady_clock;
  auto ms = [](Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); };
  // Warm up and choose the batch so that a sample takes about sample_ms.
  auto t0 = Clock::now();
  op();
  int batch = 1;
  double one = ms(Clock::now() - t0);
  t0 = Clock::now();
  for (int i = 0; i < 3; ++i) op();
  one = std::max(1e-6, ms(Clock::now() - t0) / 3.0);
  batch = std::max(1, static_cast<int>(sample_ms / one));
  std::vector<double> per_call;
  for (int s = 0; s < samples; ++s) {
    const auto start = Clock::now();
    for (int i = 0; i < batch; ++i) op();
    per_call.push_back(ms(Clock::now() - start) / batch);
  }
  std::sort(per_call.begin(), per_call.end());
  Timing t;
  t.name = name;
  t.width = width;
  t.height = height;
  t.samples = samples;
  t.batch = batch;
  t.median_ms = per_call[per_call.size() / 2];
  t.min_ms = per_call.front();
  t.p90_ms = per_call[std::min(per_call.size() - 1, per_call.size() * 9 / 10)];
  return t;
}

// A line plot drawn with OpenCV: axes, ticks, labels, legend.
struct Series {
  std::string label;
  std::vector<double> x, y;
  cv::Scalar color;  // BGR
  bool dashed = false;
};

inline std::string formatTick(double v) {
  if (std::abs(v) < 1e-9) v = 0.0;  // no "-0"
  char buf[32];
  if (std::abs(v) >= 100 || v == std::round(v)) {
    std::snprintf(buf, sizeof buf, "%.0f", v);
  } else {
    std::snprintf(buf, sizeof buf, "%.2g", v);
  }
  return buf;
}

inline double niceStep(double range, int target) {
  const double raw = range / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    if (m * mag >= raw) return m * mag;
  }
  return 10 * mag;
}

inline cv::Mat plotLines(const std::string& title, const std::string& xlabel, const std::string& ylabel,
                         const std::vector<Series>& series, double ymin, double ymax, int width = 900, int height = 560,
                         const std::vector<std::pair<double, std::string>>& vlines = {}) {
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const int left = 80, right = 230, top = 50, bottom = 70;
  const int pw = width - left - right, ph = height - top - bottom;
  double xmin = 1e300, xmax = -1e300;
  for (const auto& s : series) {
    for (double x : s.x) {
      xmin = std::min(xmin, x);
      xmax = std::max(xmax, x);
    }
  }
  if (!(xmax > xmin)) xmax = xmin + 1;
  if (!(ymax > ymin)) ymax = ymin + 1;
  auto px = [&](double x) { return left + static_cast<int>(std::lround((x - xmin) / (xmax - xmin) * pw)); };
  auto py = [&](double y) { return top + ph - static_cast<int>(std::lround((y - ymin) / (ymax - ymin) * ph)); };
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const cv::Scalar black(0, 0, 0), grid(225, 225, 225);
  // Ticks and grid.
  const double xs = niceStep(xmax - xmin, 8), ys = niceStep(ymax - ymin, 6);
  for (double x = std::ceil(xmin / xs - 1e-9) * xs; x <= xmax + 1e-9; x += xs) {
    cv::line(img, {px(x), top}, {px(x), top + ph}, grid, 1);
    cv::line(img, {px(x), top + ph}, {px(x), top + ph + 5}, black, 1);
    const std::string t = formatTick(x);
    int base = 0;
    const cv::Size sz = cv::getTextSize(t, font, 0.45, 1, &base);
    cv::putText(img, t, {px(x) - sz.width / 2, top + ph + 22}, font, 0.45, black, 1, cv::LINE_AA);
  }
  for (double y = std::ceil(ymin / ys - 1e-9) * ys; y <= ymax + 1e-9; y += ys) {
    cv::line(img, {left, py(y)}, {left + pw, py(y)}, grid, 1);
    cv::line(img, {left - 5, py(y)}, {left, py(y)}, black, 1);
    const std::string t = formatTick(y);
    int base = 0;
    const cv::Size sz = cv::getTextSize(t, font, 0.45, 1, &base);
    cv::putText(img, t, {left - 8 - sz.width, py(y) + 5}, font, 0.45, black, 1, cv::LINE_AA);
  }
  for (const auto& [x, label] : vlines) {
    for (int y = top; y < top + ph; y += 8) cv::line(img, {px(x), y}, {px(x), std::min(top + ph, y + 4)}, black, 1);
    cv::putText(img, label, {px(x) + 4, top + 14}, font, 0.45, black, 1, cv::LINE_AA);
  }
  cv::rectangle(img, {left, top}, {left + pw, top + ph}, black, 1);
  // Series, clipped to the plot area.
  cv::Mat area = img(cv::Rect(left, top, pw + 1, ph + 1));
  for (const auto& s : series) {
    std::vector<cv::Point> pts;
    for (size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.y[i])) continue;
      pts.emplace_back(px(s.x[i]) - left, py(std::clamp(s.y[i], ymin, ymax)) - top);
    }
    for (size_t i = 1; i < pts.size(); ++i) {
      if (s.dashed && i % 2 == 0) continue;
      cv::line(area, pts[i - 1], pts[i], s.color, 2, cv::LINE_AA);
    }
    for (const auto& p : pts) cv::circle(area, p, 3, s.color, -1, cv::LINE_AA);
  }
  // Labels and legend.
  int base = 0;
  cv::Size sz = cv::getTextSize(title, font, 0.6, 1, &base);
  cv::putText(img, title, {left + pw / 2 - sz.width / 2, 30}, font, 0.6, black, 1, cv::LINE_AA);
  sz = cv::getTextSize(xlabel, font, 0.5, 1, &base);
  cv::putText(img, xlabel, {left + pw / 2 - sz.width / 2, height - 20}, font, 0.5, black, 1, cv::LINE_AA);
  cv::Mat ylab(30, ph, CV_8UC3, cv::Scalar(255, 255, 255));
  sz = cv::getTextSize(ylabel, font, 0.5, 1, &base);
  cv::putText(ylab, ylabel, {ph / 2 - sz.width / 2, 20}, font, 0.5, black, 1, cv::LINE_AA);
  cv::rotate(ylab, ylab, cv::ROTATE_90_COUNTERCLOCKWISE);
  ylab.copyTo(img(cv::Rect(8, top, 30, ph)));
  int ly = top + 10;
  for (const auto& s : series) {
    cv::line(img, {left + pw + 15, ly}, {left + pw + 45, ly}, s.color, 2, cv::LINE_AA);
    cv::circle(img, {left + pw + 30, ly}, 3, s.color, -1, cv::LINE_AA);
    cv::putText(img, s.label, {left + pw + 52, ly + 5}, font, 0.42, black, 1, cv::LINE_AA);
    ly += 22;
  }
  return img;
}

}  // namespace tools
}  // namespace act_color
