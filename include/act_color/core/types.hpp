#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>

namespace act_color {
namespace core {

// Class ids of the contract (README, "Color classes"). Label images hold these values.
enum ColorClass : uint8_t {
  kUnknown = 0,
  kGreen = 1,
  kWhite = 2,
  kYellow = 3,
  kBlue = 4,
  kBlack = 5,
  kOrange = 6,
};
constexpr int kNumClasses = 7;
// Truth label value for pixels outside the mirror; evaluators skip it.
constexpr uint8_t kNotImaged = 255;

const char* className(int class_id);

// Palette used for classified images (rgb8), index = class id.
const std::array<std::array<uint8_t, 3>, kNumClasses>& classPalette();

// Pose of base_link in the field frame.
struct Pose2D {
  double x_m = 0.0;
  double y_m = 0.0;
  double theta_rad = 0.0;

  bool isFinite() const { return std::isfinite(x_m) && std::isfinite(y_m) && std::isfinite(theta_rad); }
};

// Throws std::invalid_argument "parameter NAME must be in [lo, hi], is VALUE" (open at lo with
// lo_open) unless value lies in the range; NaN never does. The numbers are printed with up to 10
// significant digits: an integer limit of 1048576 reads as such, not as 1.04858e+06.
void requireParameterRange(const char* name, double value, double lo, double hi, bool lo_open = false);

// An angle in (-pi, pi].
inline double wrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

}  // namespace core
}  // namespace act_color
