#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "act_color/core/expected_class_model.hpp"

namespace act_color {
namespace sim {

// A frame and its truth labels.
struct LabeledFrame {
  cv::Mat rgb;     // CV_8UC3, rgb8
  cv::Mat labels;  // CV_8UC1, class ids, core::kNotImaged outside the mirror
};

// The simplest synthetic frame: each pixel painted with a flat color of the class the field model
// expects for it (off-field pixels get clutter colors), scaled by `brightness`, plus noise. No
// shading, no 3-D objects but the goals: a fixture for unit tests and a quick demo; the renderer
// is the realistic simulator.
LabeledFrame paintFlatFrame(const core::ExpectedClassModel& model, const core::Pose2D& pose, double brightness,
                            uint32_t seed);

}  // namespace sim
}  // namespace act_color
