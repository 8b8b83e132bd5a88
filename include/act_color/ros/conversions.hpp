#pragma once

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <sensor_msgs/Image.h>

#include <cmath>
#include <string>
#include <vector>

#include "act_color/ColorLut.h"
#include "act_color/core/act_trainer.hpp"
#include "act_color/core/color_lut.hpp"
#include "act_color/core/image_view.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/core/types.hpp"

namespace act_color {
namespace ros_conversions {

// Why a camera image message cannot be read safely (encoding rgb8, bgr8 or yuv422; width and
// height not 0; step >= width * bytes per pixel; data.size() >= step * height; an even width for
// yuv422), or "" when it can. Checks the message against itself only, not against a calibration.
std::string imageMessageProblem(const sensor_msgs::Image& image);
// The layout part of it for `bytes_per_pixel` bytes per pixel (sizes, step, data), or "".
std::string imageLayoutProblem(const sensor_msgs::Image& image, size_t bytes_per_pixel);
// A view of a sensor_msgs/Image (rgb8, bgr8, yuv422); false with imageMessageProblem's reason.
bool imageView(const sensor_msgs::Image& image, core::ImageView* view, std::string* error);

// The table and clusters of a trainer as a message (the table is copied once).
act_color::ColorLutPtr toMsg(const core::ActTrainer& trainer, const std_msgs::Header& header);

// The table of a message; false with a reason when the message is inconsistent.
bool fromMsg(const act_color::ColorLut& msg, core::ColorLut* lut, std::string* error);
// The table and its clusters (for core::ActTrainer::restore); false with a reason.
bool fromMsg(const act_color::ColorLut& msg, core::ColorLut* lut, std::vector<core::ActTrainer::SavedCluster>* clusters,
             std::string* error);

// Pose of base_link in field from a pose message; false with a reason for NaN/inf, a height off
// the floor beyond kMaxHeightM, a quaternion that is not a unit one (within
// kMaxQuaternionNormError) or a tilt (roll/pitch) above kMaxTiltRad.
constexpr double kMaxQuaternionNormError = 0.01;
constexpr double kMaxTiltRad = 10.0 * M_PI / 180.0;
constexpr double kMaxHeightM = 1.0;
bool pose2D(const geometry_msgs::Pose& pose, core::Pose2D* out, std::string* error);

// mono8 label image message with the given header (copies the labels once).
sensor_msgs::ImagePtr labelsToMsg(const cv::Mat& labels, const std_msgs::Header& header);

// A mono8 labels message shaped like `image` (its header, every pixel kUnknown) and, in *labels,
// a cv::Mat over the message's data: the labels are written straight into what is published.
sensor_msgs::ImagePtr newLabelsMsg(const sensor_msgs::Image& image, cv::Mat* labels);

// The table of a message, borrowed (no copy): valid while the message lives.
core::LutView lutView(const act_color::ColorLut& msg);

}  // namespace ros_conversions
}  // namespace act_color
