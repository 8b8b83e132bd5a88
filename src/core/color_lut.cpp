#include "act_color/core/color_lut.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace act_color {
namespace core {

ColorLut::ColorLut(int bits_per_channel, ColorSpace space) : bits_(bits_per_channel), space_(space) {
  if (bits_per_channel < 1 || bits_per_channel > 8) {
    throw std::invalid_argument("lut_bits must be in [1, 8], is " + std::to_string(bits_per_channel));
  }
  const int shift = 8 - bits_per_channel;
  for (uint32_t c = 0; c < 256; ++c) {
    channel_index_[0][c] = cellIndex(c >> shift, 0, 0);
    channel_index_[1][c] = cellIndex(0, c >> shift, 0);
    channel_index_[2][c] = cellIndex(0, 0, c >> shift);
  }
  clear();
}

void ColorLut::clear() {
  table_.assign(size_t{1} << (3 * bits_), kUnknown);
  counts_.fill(0);
  counts_[kUnknown] = static_cast<uint32_t>(table_.size());
}

void ColorLut::assign(const std::vector<uint8_t>& table) {
  if (table.size() != table_.size()) {
    throw std::invalid_argument("table has " + std::to_string(table.size()) + " cells, expected " +
                                std::to_string(table_.size()));
  }
  table_ = table;
  counts_.fill(0);
  for (uint8_t c : table_) {
    if (c < kNumClasses) ++counts_[c];
  }
}

}  // namespace core
}  // namespace act_color
