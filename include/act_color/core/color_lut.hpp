#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "act_color/core/image_view.hpp"
#include "act_color/core/types.hpp"

namespace act_color {
namespace core {

// Color look-up table: one class id per cell of a color space quantised to `bits` per channel.
class ColorLut {
 public:
  explicit ColorLut(int bits_per_channel = 6, ColorSpace space = ColorSpace::kRgb);

  int bitsPerChannel() const { return bits_; }
  ColorSpace colorSpace() const { return space_; }
  size_t size() const { return table_.size(); }

  // cellIndex(c0 >> (8 - bits), c1 >> (8 - bits), c2 >> (8 - bits)), from per-channel tables.
  uint32_t index(uint8_t c0, uint8_t c1, uint8_t c2) const {
    return channel_index_[0][c0] | channel_index_[1][c1] | channel_index_[2][c2];
  }
  // The cell of per-channel cell numbers i0, i1, i2 in [0, 2^bits).
  uint32_t cellIndex(uint32_t i0, uint32_t i1, uint32_t i2) const { return (i0 << (2 * bits_)) | (i1 << bits_) | i2; }
  uint8_t classOf(uint8_t c0, uint8_t c1, uint8_t c2) const { return table_[index(c0, c1, c2)]; }
  uint8_t at(uint32_t cell) const { return table_[cell]; }
  void set(uint32_t cell, uint8_t class_id) {
    uint8_t& current = table_[cell];
    if (current < kNumClasses) --counts_[current];
    if (class_id < kNumClasses) ++counts_[class_id];
    current = class_id;
  }
  void clear();

  // Cells per class id; kept up to date by set(), clear() and assign(), so O(1).
  std::array<uint32_t, kNumClasses> cellCounts() const { return counts_; }
  // Cells mapped to any class (the table's fill), O(1).
  uint32_t mappedCells() const {
    uint32_t n = 0;
    for (int k = 1; k < kNumClasses; ++k) n += counts_[k];
    return n;
  }

  const std::vector<uint8_t>& table() const { return table_; }
  // Replaces the table; `table.size()` must equal size().
  void assign(const std::vector<uint8_t>& table);
  const uint8_t* data() const { return table_.data(); }

 private:
  int bits_;
  ColorSpace space_;
  std::vector<uint8_t> table_;
  std::array<uint32_t, kNumClasses> counts_{};  // cells per class id < kNumClasses
  // Each channel value's share of its cell index (a few loads instead of variable shifts).
  std::array<std::array<uint32_t, 256>, 3> channel_index_{};
};

}  // namespace core
}  // namespace act_color
