// "A-B" on a tool's command line: an inclusive range of family seeds (act_calibrate --family,
// act_flicker --seeds).
#pragma once

#include <cstdint>
#include <string>

namespace act_color_tools {

// Digits, '-', digits, A <= B, at most max_count seeds; false otherwise.
inline bool parseSeedRange(const std::string& text, uint32_t* first, uint32_t* last, uint32_t max_count = 1000) {
  const size_t dash = text.find('-');
  if (dash == std::string::npos || dash == 0 || dash + 1 == text.size() ||
      text.find_first_not_of("0123456789-") != std::string::npos || text.find('-', dash + 1) != std::string::npos ||
      dash > 9 || text.size() - dash - 1 > 9) {
    return false;
  }
  const unsigned long a = std::stoul(text.substr(0, dash)), b = std::stoul(text.substr(dash + 1));
  if (b < a || b - a >= max_count) return false;
  *first = static_cast<uint32_t>(a);
  *last = static_cast<uint32_t>(b);
  return true;
}

}  // namespace act_color_tools
