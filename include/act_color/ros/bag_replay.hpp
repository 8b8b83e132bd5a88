#pragma once

#include <sensor_msgs/Image.h>

#include <cstdint>
#include <ostream>
#include <stdexcept>
#include <string>

#include "act_color/core/act_trainer.hpp"
#include "act_color/core/run_evaluation.hpp"
#include "act_color/ros/conversions.hpp"

namespace act_color {
namespace ros_layer {

// What act_replay does (see README, "act_replay").
struct ReplayOptions {
  std::string input_bag;
  std::string calibration;
  std::string output_bag;
  std::string image_topic = "/omni/image_raw";
  std::string pose_topic = "/localization/pose";
  std::string truth_topic = "/omni/labels_truth";
  std::string events_topic = "/scenario/events";
  core::ActParams params;
  int bootstrap_cycles = core::kDefaultBootstrapCycles;  // cycles on the first image with a pose (paper, section 2)
  size_t lut_every = 1;                                  // write /act/color_lut with every n-th frame
  size_t adapt_frames = 12;                              // frames after each event excluded from the "adapted" figures
  std::string csv_path;                                  // per-frame recall/precision, when not empty
  std::string png_dir;    // side-by-side PNGs (image | classified | truth), when not empty
  size_t png_every = 10;  // of every n-th frame
  bool progress = true;   // a progress line on stderr every few seconds
  // The own robot's pixels learned over the replay (core::SelfMaskLearner) are written here as a
  // PNG for the calibration's camera.self_mask, when not empty. They are also used while the replay
  // runs, as the trainer nodelet's ~learn_self_mask does (core::SelfMaskHandOver).
  std::string self_mask_png;
};

struct ReplayResult {
  size_t images = 0;
  size_t trained = 0;             // frames with a usable pose
  size_t without_pose = 0;        // frames before the first pose, or with a NaN pose
  size_t pose_contradicted = 0;   // of the trained: the table contradicted the pose, nothing trained (pose_check)
  size_t unusable_images = 0;     // encoding, size, step or data unfit: labelled all unknown, left out of the metrics
  size_t with_truth = 0;          // frames in the metrics (a usable image and a usable truth image)
  size_t unusable_truth = 0;      // truth images that do not fit their image (encoding, size, step, data)
  size_t truth_left_out = 0;      // frames with a truth image left out of the metrics (unusable truth or image)
  int self_mask_poses = 0;        // distinct poses the self mask was learned from
  double self_mask_fraction = 0;  // of the imaged pixels
  size_t self_masks_used = 0;     // learned masks taken over while the replay ran
  size_t self_mask_first_frame = 0;  // the first frame that used one (0-based)
  size_t self_mask_used_pixels = 0;  // in the last one taken over (with the calibration's own mask)
  core::RunEvaluation evaluation;
};

// Thrown for a bag or calibration that cannot be used at all; the message says why. Nothing is
// left at the output path when runReplay throws after it started writing (OUT.bag is written as
// OUT.bag.active and renamed when complete).
class ReplayError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Why a camera image message cannot be read safely, or "" (the nodelets' check).
using ros_conversions::imageMessageProblem;
// The same for a truth label image: mono8, `width` x `height` (those of its camera image), step
// >= width, data.size() >= step * height.
std::string truthMessageProblem(const sensor_msgs::Image& truth, uint32_t width, uint32_t height);

// Runs ACT and the segmentation over every image of the input bag, in order, with the pose
// nearest in time at or before each image; writes /segmentation/labels and /act/color_lut.
// A frame whose image or truth message does not fit is skipped with a warning on `log` (counted in
// the result); a truncated or corrupt bag throws ReplayError naming the file and `rosbag reindex`.
ReplayResult runReplay(const ReplayOptions& options, std::ostream& log);

}  // namespace ros_layer
}  // namespace act_color
