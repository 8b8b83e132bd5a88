#pragma once

#include <sensor_msgs/Image.h>

#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "act_color/core/calibration.hpp"
#include "act_color/core/color_lut.hpp"
#include "act_color/core/expected_class_model.hpp"
#include "act_color/core/self_mask_learner.hpp"
#include "act_color/core/types.hpp"

namespace act_color {
namespace ros_conversions {

// The own robot's pixels learned while it drives (the trainer's ~learn_self_mask): a
// core::SelfMaskLearner on a thread of its own. The trainer offers each frame it trained; the
// worker takes one only when it is idle and the pose is new to the learner
// (SelfMaskLearner::isNewPose), and only then copies the table. Training never waits for it: a
// frame offered while one is being counted is passed over (the next new pose comes soon).
// Whenever core::SelfMaskHandOver says the mask learned is to be used, the worker also builds the
// camera model with it (and the calibration's own mask) as the self mask, for the trainer to take
// (takeLearnedModel).
class SelfMaskWorker {
 public:
  explicit SelfMaskWorker(const core::Calibration& calibration);
  SelfMaskWorker(const SelfMaskWorker&) = delete;
  SelfMaskWorker& operator=(const SelfMaskWorker&) = delete;
  // Waits for the frame being counted, if any.
  ~SelfMaskWorker();

  // True when the frame was taken. The image message is kept (not copied) until it is counted.
  bool offer(const sensor_msgs::ImageConstPtr& image, const core::Pose2D& pose, const core::ColorLut& lut);
  // For the diagnostics, without waiting for a frame being counted: the learner's counts as of the
  // last frame counted.
  struct Progress {
    int poses = 0;           // distinct poses counted
    size_t headings = 0;     // directions they faced, of SelfMaskLearner::kHeadingSectors
    double last_ms = 0.0;    // how long counting the last frame took (on the worker's thread)
    std::string last_error;  // why the last frame could not be counted ("" when it was)
  };
  Progress progress() const;
  // The camera with the mask learned so far as its self mask (self_mask empty before any pose), the
  // distinct poses it was learned from and the directions they faced (of
  // SelfMaskLearner::kHeadingSectors). Waits for a frame being counted.
  core::CameraCalibration learned(int* poses, size_t* headings) const;

  // A mask to use from now on, built on the worker's thread: the camera model for
  // core::ActTrainer::replaceModel (its camera().calibration() has the mask, for core::Segmenter).
  struct LearnedModel {
    core::ExpectedClassModel model;
    int poses = 0;      // the distinct poses it was learned from
    size_t pixels = 0;  // in the mask
  };
  // The newest such model not yet taken, once (nullptr when there is none).
  std::unique_ptr<LearnedModel> takeLearnedModel();

 private:
  struct Job {
    sensor_msgs::ImageConstPtr image;
    core::Pose2D pose;
    core::ColorLut lut;
  };
  void run();
  // With learner_mutex_ held: the model of the mask learned so far, when it is to be handed over.
  std::unique_ptr<LearnedModel> buildModelIfChanged(int poses);

  const core::Calibration calibration_;
  // The learner, under learner_mutex_ (held while a frame is counted).
  mutable std::mutex learner_mutex_;
  core::SelfMaskLearner learner_;
  // The hand-over, under mutex_.
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Job> job_;
  bool busy_ = false, stop_ = false;
  std::optional<core::Pose2D> last_taken_;
  Progress progress_;
  std::unique_ptr<LearnedModel> learned_model_;  // not yet taken
  core::SelfMaskHandOver hand_over_;             // worker's thread only
  std::thread thread_;                           // last: starts once everything above is built
};

}  // namespace ros_conversions
}  // namespace act_color
