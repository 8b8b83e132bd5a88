#pragma once

#include <fstream>
#include <sstream>
#include <string>

#include "act_color/core/calibration.hpp"

namespace act_color {
namespace test {

inline std::string sourcePath(const std::string& relative) { return std::string(ACT_SOURCE_DIR) + "/" + relative; }

inline std::string readFile(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// The contract's example calibration (two-point elevation map).
inline core::Calibration contractCalibration() {
  return core::loadCalibration(sourcePath("test/data/contract_example.yaml"));
}

// The package's default calibration of the simulated camera.
inline core::Calibration defaultCalibration() {
  return core::loadCalibration(sourcePath("config/calibration/msl_2007_580.yaml"));
}

}  // namespace test
}  // namespace act_color
