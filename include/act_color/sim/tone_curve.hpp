#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <random>
#include <string>

namespace act_color {
namespace sim {

// A global per-channel monotone (non-decreasing) change of the final 8-bit image: what a change of
// light level or color, or of the camera's gain, contrast, gamma or white balance, does to every
// pixel. One 256-entry table per channel of an rgb8 image.
class ToneCurve {
 public:
  using Table = std::array<uint8_t, 256>;

  ToneCurve();  // identity
  explicit ToneCurve(const std::array<Table, 3>& tables);

  uint8_t map(int channel, uint8_t value) const { return tables_[channel][value]; }
  const std::array<Table, 3>& tables() const { return tables_; }
  bool isIdentity() const;
  // This curve, then `next`.
  ToneCurve then(const ToneCurve& next) const;
  // Applies the curve in place to an rgb8 image (CV_8UC3).
  void apply(cv::Mat& rgb) const;

  // out = clamp(round(gain_c * in)).
  static ToneCurve gain(const Eigen::Vector3d& gain);
  // Image-editor brightness and contrast: out = ((in - 127.5) * contrast + 127.5) * brightness.
  // (0.5, 0.5) is the paper's darkening (section 3.2).
  static ToneCurve brightnessContrast(double brightness, double contrast);
  // out = 255 * (in / 255)^gamma (gamma > 1 darkens the mid-tones).
  static ToneCurve gamma(double gamma);
  // A white balance towards warm (kelvin_shift < 0: red up, blue down) or cold light: per-channel
  // gains of a color temperature change, normalised so that green keeps its level.
  static ToneCurve whiteBalance(double kelvin_shift);
  // out = black + (255 - black) * in / 255: a raised black level (lifts the shadows).
  static ToneCurve blackLevel(double black);
  // A random composition of the kinds above (gain, affine, gamma, white balance, black level) with
  // a strength in [0, 1]: 1 reaches the paper's darkening or a 1.6x brightening. Deterministic in
  // the generator's state. `description` (optional) receives a readable summary.
  static ToneCurve random(std::mt19937& rng, double strength, std::string* description = nullptr);

 private:
  std::array<Table, 3> tables_;
};

}  // namespace sim
}  // namespace act_color
