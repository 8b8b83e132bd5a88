#include "act_color/core/color_lut.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace act_color {
namespace core {

ColorLut::ColorLut(int bits_per_channel, ColorSpace space)
    : bits_(bits_per_channel), shift_(8 - bits_per_channel), space_(space) {
  if (bits_per_channel < 1 || bits_per_channel > 8) {
    throw std::invalid_argument("lut_bits must be in [1, 8], is " + std::to_string(bits_per_channel));
  }
  table_.assign(size_t{1} << (3 * bits_), kUnknown);
}

void ColorLut::clear() { std::fill(table_.begin(), table_.end(), static_cast<uint8_t>(kUnknown)); }

std::array<uint32_t, kNumClasses> ColorLut::cellCounts() const {
  std::array<uint32_t, kNumClasses> counts{};
  for (uint8_t c : table_) {
    if (c < kNumClasses) ++counts[c];
  }
  return counts;
}

void ColorLut::assign(const std::vector<uint8_t>& table) {
  if (table.size() != table_.size()) {
    throw std::invalid_argument("table has " + std::to_string(table.size()) + " cells, expected " +
                                std::to_string(table_.size()));
  }
  table_ = table;
}

}  // namespace core
}  // namespace act_color
