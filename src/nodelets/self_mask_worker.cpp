#include "act_color/ros/self_mask_worker.hpp"

#include <chrono>

#include "act_color/core/image_view.hpp"
#include "act_color/ros/conversions.hpp"

namespace act_color {
namespace ros_conversions {

SelfMaskWorker::SelfMaskWorker(const core::Calibration& calibration)
    : calibration_(calibration), learner_(calibration), hand_over_(calibration), thread_([this] { run(); }) {}

SelfMaskWorker::~SelfMaskWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

bool SelfMaskWorker::offer(const sensor_msgs::ImageConstPtr& image, const core::Pose2D& pose,
                           const core::ColorLut& lut) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (busy_ || job_) return false;
  if (last_taken_ && !core::SelfMaskLearner::isNewPose(*last_taken_, pose)) return false;
  last_taken_ = pose;
  job_ = Job{image, pose, lut};
  wake_.notify_all();
  return true;
}

SelfMaskWorker::Progress SelfMaskWorker::progress() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return progress_;
}

core::CameraCalibration SelfMaskWorker::learned(int* poses, size_t* headings) const {
  core::CameraCalibration camera = calibration_.camera;
  camera.self_mask_file.clear();
  std::lock_guard<std::mutex> lock(learner_mutex_);
  camera.self_mask = learner_.mask();
  *poses = learner_.frames();
  *headings = learner_.headingsFaced();
  return camera;
}

std::unique_ptr<SelfMaskWorker::LearnedModel> SelfMaskWorker::takeLearnedModel() {
  std::lock_guard<std::mutex> lock(mutex_);
  return std::move(learned_model_);
}

std::unique_ptr<SelfMaskWorker::LearnedModel> SelfMaskWorker::buildModelIfChanged(int poses) {
  std::optional<core::Calibration> calibration = hand_over_.next(learner_);
  if (!calibration) return nullptr;
  return std::unique_ptr<LearnedModel>(
      new LearnedModel{core::ExpectedClassModel(*calibration), poses, hand_over_.pixels()});
}

void SelfMaskWorker::run() {
  for (;;) {
    Job job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || job_; });
      if (stop_) return;
      job = std::move(*job_);
      job_.reset();
      busy_ = true;
    }
    const auto start = std::chrono::steady_clock::now();
    std::string error;
    int poses = 0;
    size_t headings = 0;
    std::unique_ptr<LearnedModel> learned;
    core::ImageView view;
    if (imageView(*job.image, &view, &error)) {
      try {
        std::lock_guard<std::mutex> lock(learner_mutex_);
        learner_.add(view, job.pose, job.lut);
        poses = learner_.frames();
        headings = learner_.headingsFaced();
        learned = buildModelIfChanged(poses);
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::lock_guard<std::mutex> lock(mutex_);
    busy_ = false;
    progress_.last_ms = ms;
    progress_.last_error = error;
    if (error.empty()) {
      progress_.poses = poses;
      progress_.headings = headings;
    }
    if (learned) learned_model_ = std::move(learned);  // a model not yet taken gives way to the newer one
  }
}

}  // namespace ros_conversions
}  // namespace act_color
