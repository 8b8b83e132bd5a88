#include "act_color/core/types.hpp"

#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace act_color {
namespace core {

const char* className(int class_id) {
  static const char* const kNames[kNumClasses] = {"unknown", "green", "white", "yellow", "blue", "black", "orange"};
  if (class_id >= 0 && class_id < kNumClasses) return kNames[class_id];
  return class_id == kNotImaged ? "not_imaged" : "invalid";
}

const std::array<std::array<uint8_t, 3>, kNumClasses>& classPalette() {
  static const std::array<std::array<uint8_t, 3>, kNumClasses> kPalette = {{
      {{128, 128, 128}},  // unknown
      {{0, 170, 0}},      // green
      {{255, 255, 255}},  // white
      {{255, 230, 0}},    // yellow
      {{0, 60, 255}},     // blue
      {{0, 0, 0}},        // black
      {{255, 120, 0}},    // orange
  }};
  return kPalette;
}

void requireParameterRange(const char* name, double value, double lo, double hi, bool lo_open) {
  const bool below = lo_open ? !(value > lo) : !(value >= lo);
  if (!below && value <= hi) return;
  std::ostringstream s;
  s << std::setprecision(10) << "parameter " << name << " must be in " << (lo_open ? "(" : "[") << lo << ", " << hi
    << "], is " << value;
  throw std::invalid_argument(s.str());
}

}  // namespace core
}  // namespace act_color
