// Numbers on a tool's command line: "x,y,theta" for --pose, one number for --height-m
// (act_calibrate, act_real_eval).
#pragma once

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace act_color_tools {

// Exactly `count` comma-separated finite numbers; std::invalid_argument naming `option` otherwise.
inline std::vector<double> parseNumbers(const std::string& text, size_t count, const std::string& option) {
  std::vector<double> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(v)) throw std::invalid_argument(option + ": '" + text + "'");
    out.push_back(v);
  }
  if (out.size() != count) {
    throw std::invalid_argument(option + " needs " + std::to_string(count) + " comma-separated numbers");
  }
  return out;
}

inline double parseNumber(const std::string& text, const std::string& option) {
  return parseNumbers(text, 1, option)[0];
}

}  // namespace act_color_tools
