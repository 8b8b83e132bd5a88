// Segmentation nodelet: classifies every camera image with the color table the ACT trainer
// trained on that very image (zero copy: the table is the trainer's shared message), publishes
// the labels and the features the robot's other modules need.
#include <cv_bridge/cv_bridge.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PointStamped.h>
#include <geometry_msgs/Pose2D.h>
#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <std_msgs/UInt64MultiArray.h>

#include <algorithm>
#include <boost/make_shared.hpp>
#include <chrono>
#include <cmath>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <pluginlib/class_list_macros.hpp>
#include <string>

#include "act_color/ColorLut.h"
#include "act_color/SegmentationConfig.h"
#include "act_color/VisionFeatures.h"
#include "act_color/core/act_trainer.hpp"
#include "act_color/core/ball_detector.hpp"
#include "act_color/core/calibration.hpp"
#include "act_color/core/carpet_edge.hpp"
#include "act_color/core/feature_extractor.hpp"
#include "act_color/core/omni_camera_model.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/ros/checked_reconfigure.hpp"
#include "act_color/ros/conversions.hpp"
#include "act_color/ros/nodelet_setup.hpp"
#include "act_color/ros/pose_source.hpp"

namespace act_color {

class SegmentationNodelet : public nodelet::Nodelet {
 private:
  struct PendingImage {
    sensor_msgs::ImageConstPtr image;
    ros::WallTime arrival;
  };
  // The trainer's ball sighting of one image (/act/ball: the ball's centre on the carpet, base_link).
  struct BallSighting {
    ros::Time stamp;
    double x_m, y_m;
  };
  // Which table an image was classified with (diagnostics).
  enum class TableUsed { kExact, kOlder, kNewest, kNone, kRejected };
  struct Record {
    ros::WallTime at;
    TableUsed table;
    double classify_ms;
    double latency_ms;  // image stamp to labels (ROS time)
  };

  ~SegmentationNodelet() override { loader_.wait(); }
  void onInit() override;
  // Parameters, topics and timers on the manager's load path; the calibration and the camera
  // model follow in loadCalibration, on loader_'s thread (images are dropped until then).
  bool configure(std::string* error);
  void loadCalibration();
  // The nodelet could not be configured: it stays loaded and does nothing, saying why.
  void notStarted(const std::string& error);
  bool applyConfig(const SegmentationConfig& config, std::string* error);
  void connectCb();
  void onImage(const sensor_msgs::ImageConstPtr& msg);
  void onTable(const act_color::ColorLutConstPtr& msg);
  void onBall(const geometry_msgs::PointStampedConstPtr& msg);
  // The own robot's pixels the trainer learned while the robot drives (its ~learn_self_mask;
  // mono8 of the camera's size, nonzero = own robot), labelled black from then on as the
  // calibration's self mask is. Kept until the calibration is loaded when it comes before.
  void onSelfMask(const sensor_msgs::ImageConstPtr& msg);
  // The segmenter and the carpet's edge of `camera` with that mask (building them takes some 10 ms
  // at 640x480: done without the lock); false (and why) when it does not fit the camera.
  struct Masked {
    std::shared_ptr<const core::Segmenter> segmenter;
    std::shared_ptr<const core::CarpetEdge> carpet_edge;
    size_t pixels = 0;
  };
  static bool withSelfMask(core::CameraCalibration camera, const sensor_msgs::Image& msg, Masked* masked,
                           std::string* error);
  // With the lock held: takes them into use.
  void useSelfMask(Masked masked);
  void flush();
  // The classify time in ms. `ball`: the trainer's sighting in this image, labelled as the ball's
  // image (core::labelBallImage).
  double process(const sensor_msgs::ImageConstPtr& image, const act_color::ColorLutConstPtr& lut,
                 const std::optional<BallSighting>& ball);
  void record(TableUsed table, double classify_ms, double latency_ms);
  // An image not classified (the lock held): counted, its reason kept for the diagnostics.
  void countRejected(const std::string& why);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle nh_, pnh_;
  std::unique_ptr<image_transport::ImageTransport> it_;
  image_transport::Subscriber image_sub_;
  ros::Subscriber lut_sub_, ball_sub_, self_mask_sub_;
  image_transport::Publisher labels_pub_, labels_color_pub_;
  ros::Publisher features_pub_, debug_pub_;
  ros::WallTimer flush_timer_;
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  ros::WallTimer diagnostics_timer_;
  ros_conversions::PoseSource pose_source_;
  std::unique_ptr<ros_conversions::CheckedReconfigure<SegmentationConfig>> reconfigure_;

  std::mutex mutex_;  // guards everything below
  std::string config_error_;
  std::unique_ptr<core::OmniCameraModel> camera_;
  // Replaced (not changed) when a learned self mask comes: process() classifies with its own copy.
  std::shared_ptr<const core::Segmenter> segmenter_;
  sensor_msgs::ImageConstPtr pending_self_mask_;  // came while the calibration was loading
  size_t self_mask_pixels_ = 0;                   // of the learned self mask in use
  // ~carpet_edge: white and black beyond the carpet's edge labelled unknown (core::CarpetEdge, of
  // camera_).
  std::shared_ptr<const core::CarpetEdge> carpet_edge_;
  bool carpet_edge_on_ = true;
  uint32_t beyond_carpet_ = 0;  // pixels it labelled unknown in the last image
  // No segmenter yet and no error: the calibration is being loaded (segmenter_, camera_ and field_
  // follow).
  bool loading() const { return !segmenter_ && config_error_.empty(); }
  core::FieldCalibration field_;
  core::FeatureParams feature_params_;
  bool lazy_ = false;
  bool debug_addresses_ = false;
  size_t queue_size_ = 5;
  double max_wait_s_ = 0.2;
  size_t table_history_ = 10;
  std::deque<PendingImage> pending_;                // by arrival
  std::deque<act_color::ColorLutConstPtr> tables_;  // shared, never copied; by arrival
  std::deque<BallSighting> balls_;                  // by arrival, as many as tables
  double ball_radius_m_ = 0.11;
  // The newest table before time jumped back: used until a table of the new run comes.
  act_color::ColorLutConstPtr fallback_;
  ros_conversions::TimeJumpDetector image_time_;
  // Statistics since the start (or the last time jump) ...
  uint64_t images_ = 0, labeled_ = 0, exact_table_ = 0, older_table_ = 0, newest_table_ = 0, no_table_ = 0,
           rejected_ = 0, time_jumps_ = 0;
  std::string last_error_;
  // ... and of the last seconds.
  static constexpr double kWindowS = 5.0;
  ros_conversions::RecentWindow<Record> window_{kWindowS};
  ros::WallTime last_image_, last_table_;
  ros_conversions::BackgroundTask loader_;
};

void SegmentationNodelet::onInit() {
  nh_ = getNodeHandle();
  pnh_ = getPrivateNodeHandle();
  updater_ = ros_conversions::makeDiagnostics(
      nh_, pnh_, getName(), "segmentation", [this](diagnostic_updater::DiagnosticStatusWrapper& s) { diagnose(s); },
      &diagnostics_timer_);
  const std::string error = ros_conversions::runConfigure([this](std::string* e) { return configure(e); });
  if (!error.empty()) notStarted(error);
}

void SegmentationNodelet::notStarted(const std::string& error) {
  NODELET_ERROR("not started: %s", error.c_str());
  std::lock_guard<std::mutex> lock(mutex_);
  config_error_ = error;
}

bool SegmentationNodelet::configure(std::string* error) {
  using ros_conversions::readParam;
  SegmentationConfig c = SegmentationConfig::__getDefault__();
  bool lazy = false, debug = false;
  if (!readParam(pnh_, "queue_size", &c.queue_size, error) || !readParam(pnh_, "max_wait", &c.max_wait, error) ||
      !readParam(pnh_, "table_history", &c.table_history, error) ||
      !readParam(pnh_, "max_pose_age", &c.max_pose_age, error) ||
      !readParam(pnh_, "scan_lines", &c.scan_lines, error) ||
      !readParam(pnh_, "max_line_run_px", &c.max_line_run_px, error) ||
      !readParam(pnh_, "min_goal_run_px", &c.min_goal_run_px, error) ||
      !readParam(pnh_, "min_obstacle_run_px", &c.min_obstacle_run_px, error) ||
      !readParam(pnh_, "min_ball_pixels", &c.min_ball_pixels, error) ||
      !readParam(pnh_, "obstacle_merge_m", &c.obstacle_merge_m, error) ||
      !readParam(pnh_, "ball_diameter_m", &c.ball_diameter_m, error) ||
      !readParam(pnh_, "carpet_edge", &c.carpet_edge, error) || !readParam(pnh_, "lazy", &lazy, error) ||
      !readParam(pnh_, "debug_lut_addresses", &debug, error)) {
    return false;
  }
  if (!pose_source_.init(nh_, pnh_, getName(), error)) return false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    lazy_ = lazy;
    debug_addresses_ = debug;
  }
  if (!applyConfig(c, error)) return false;
  if (debug_addresses_) debug_pub_ = pnh_.advertise<std_msgs::UInt64MultiArray>("received_lut", 100);
  it_ = std::make_unique<image_transport::ImageTransport>(nh_);
  image_transport::SubscriberStatusCallback it_cb = [this](const image_transport::SingleSubscriberPublisher&) {
    connectCb();
  };
  ros::SubscriberStatusCallback cb = [this](const ros::SingleSubscriberPublisher&) { connectCb(); };
  labels_pub_ = it_->advertise("labels", 2, it_cb, it_cb);
  // The labels in the classes' palette, for rviz; only computed while someone listens.
  labels_color_pub_ = it_->advertise("labels_color", 1, it_cb, it_cb);
  features_pub_ = nh_.advertise<act_color::VisionFeatures>("features", 2, cb, cb);
  // Latched and rare: subscribed whether or not someone listens to the labels.
  self_mask_sub_ = nh_.subscribe("self_mask", 1, &SegmentationNodelet::onSelfMask, this);
  reconfigure_ = std::make_unique<ros_conversions::CheckedReconfigure<SegmentationConfig>>(
      pnh_, c, [this](const SegmentationConfig& config, std::string* e) { return applyConfig(config, e); },
      [this](const std::string& e) {
        ACT_WALL_THROTTLE(0.2,
                          NODELET_ERROR("dynamic_reconfigure: %s; not applied, the previous values stay", e.c_str()));
      });
  flush_timer_ = nh_.createWallTimer(ros::WallDuration(0.02), [this](const ros::WallTimerEvent&) {
    try {
      flush();
    } catch (const std::exception& e) {
      ACT_WALL_THROTTLE(5.0, NODELET_ERROR("%s", e.what()));
    }
  });
  connectCb();
  loader_.start([this] { loadCalibration(); }, [this](const std::string& e) { notStarted(e); });
  return true;
}

void SegmentationNodelet::loadCalibration() {
  std::string calibration_path;
  const core::Calibration calibration = ros_conversions::loadCalibrationParam(pnh_, &pose_source_, &calibration_path);
  auto camera = std::make_unique<core::OmniCameraModel>(calibration.camera);
  auto segmenter = std::make_shared<const core::Segmenter>(calibration.camera);
  auto carpet_edge = std::make_shared<const core::CarpetEdge>(*camera);
  bool lazy = false;
  {
    // Set once: images are queued only while segmenter_ is set, so the processing outside the lock
    // sees all three.
    std::lock_guard<std::mutex> lock(mutex_);
    camera_ = std::move(camera);
    segmenter_ = std::move(segmenter);
    carpet_edge_ = std::move(carpet_edge);
    field_ = calibration.field;
    lazy = lazy_;
    std::string error;
    Masked masked;
    if (pending_self_mask_) {
      if (withSelfMask(camera_->calibration(), *pending_self_mask_, &masked, &error)) {
        useSelfMask(std::move(masked));
      } else {
        NODELET_ERROR("the trainer's self mask is not used: %s", error.c_str());
      }
    }
    pending_self_mask_.reset();
  }
  NODELET_INFO("segmentation ready: calibration %s, %s", calibration_path.c_str(),
               lazy ? "inputs subscribed while someone listens" : "always subscribed");
}

bool SegmentationNodelet::applyConfig(const SegmentationConfig& c, std::string* error) {
  core::FeatureParams fp;
  fp.scan_lines = c.scan_lines;
  fp.max_line_run_px = c.max_line_run_px;
  fp.min_goal_run_px = c.min_goal_run_px;
  fp.min_obstacle_run_px = c.min_obstacle_run_px;
  fp.min_ball_pixels = c.min_ball_pixels;
  fp.obstacle_merge_m = c.obstacle_merge_m;
  std::ostringstream s;
  if (!(c.queue_size >= 1 && c.queue_size <= 100)) {
    s << "parameter queue_size must be in [1, 100], is " << c.queue_size;
  } else if (!(c.max_wait >= 0.0 && c.max_wait <= 10.0)) {
    s << "parameter max_wait must be in [0, 10] s, is " << c.max_wait;
  } else if (!(c.table_history >= 1 && c.table_history <= 100)) {
    s << "parameter table_history must be in [1, 100], is " << c.table_history;
  } else if (!(c.max_pose_age > 0.0 && c.max_pose_age <= 60.0)) {
    s << "parameter max_pose_age must be in (0, 60] s, is " << c.max_pose_age;
  } else {
    try {
      // As the trainer's (ActParams).
      core::requireParameterRange("ball_diameter_m", c.ball_diameter_m, core::kMinBallDiameterM,
                                  core::kMaxBallDiameterM);
      fp.validate();
    } catch (const std::exception& e) {
      s << e.what();
    }
  }
  if (!s.str().empty()) {
    *error = s.str();
    return false;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  feature_params_ = fp;
  queue_size_ = static_cast<size_t>(c.queue_size);
  max_wait_s_ = c.max_wait;
  table_history_ = static_cast<size_t>(c.table_history);
  ball_radius_m_ = 0.5 * c.ball_diameter_m;
  carpet_edge_on_ = c.carpet_edge;
  pose_source_.setMaxAge(c.max_pose_age);
  return true;
}

void SegmentationNodelet::connectCb() {
  std::lock_guard<std::mutex> lock(mutex_);
  const bool wanted = !lazy_ || labels_pub_.getNumSubscribers() > 0 || features_pub_.getNumSubscribers() > 0 ||
                      labels_color_pub_.getNumSubscribers() > 0;
  if (wanted && !image_sub_) {
    const image_transport::TransportHints hints("raw", ros::TransportHints(), pnh_);
    image_sub_ = it_->subscribe("image", 5, &SegmentationNodelet::onImage, this, hints);
    // ConstPtr: the trainer's very object when in the same manager.
    lut_sub_ = nh_.subscribe("color_lut", 5, &SegmentationNodelet::onTable, this);
    // Published by the trainer before the table of the same image, so it is here when that comes.
    ball_sub_ = nh_.subscribe("ball", 5, &SegmentationNodelet::onBall, this);
  } else if (!wanted && image_sub_) {
    image_sub_.shutdown();
    lut_sub_.shutdown();
    ball_sub_.shutdown();
    pending_.clear();
    balls_.clear();
  }
}

void SegmentationNodelet::onImage(const sensor_msgs::ImageConstPtr& msg) {
  try {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!segmenter_) {
        if (loading()) ACT_WALL_THROTTLE(2.0, NODELET_INFO("image dropped: the calibration is still loading"));
        return;
      }
      // An image no table can classify is refused now, not after waiting ~max_wait for its table.
      std::string problem = ros_conversions::imageMessageProblem(*msg);
      if (problem.empty()) {
        problem = core::imageSizeProblem(static_cast<int>(msg->width), static_cast<int>(msg->height), camera_->width(),
                                         camera_->height());
      }
      if (!problem.empty()) {
        ++images_;
        countRejected(problem);
        ACT_WALL_THROTTLE(
            5.0, NODELET_ERROR("image stamped %.3f not classified: %s", msg->header.stamp.toSec(), problem.c_str()));
        return;
      }
      const ros::Time before = image_time_.latest();
      if (image_time_.jumpedBack(msg->header.stamp)) {
        // A new replay: the old run's tables are stamped in this run's future and would be taken
        // for trained tables. The newest stays as a fallback until this run's first table.
        ++time_jumps_;
        NODELET_WARN(
            "time jumped back from %.3f to %.3f (a new replay?): tables, waiting images and statistics "
            "start afresh",
            before.toSec(), msg->header.stamp.toSec());
        if (!tables_.empty()) fallback_ = tables_.back();
        tables_.clear();
        balls_.clear();
        pending_.clear();
        window_.clear();
        images_ = labeled_ = exact_table_ = older_table_ = newest_table_ = no_table_ = rejected_ = 0;
        pose_source_.forgetNewerThan(msg->header.stamp + ros::Duration(ros_conversions::TimeJumpDetector::kJumpBackS));
      }
      ++images_;
      last_image_ = ros::WallTime::now();
      pending_.push_back({msg, last_image_});
    }
    flush();
  } catch (const std::exception& e) {
    ACT_WALL_THROTTLE(5.0, NODELET_ERROR("image stamped %.3f: %s", msg->header.stamp.toSec(), e.what()));
  }
}

void SegmentationNodelet::onSelfMask(const sensor_msgs::ImageConstPtr& msg) {
  core::CameraCalibration camera;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!segmenter_) {
      if (loading()) pending_self_mask_ = msg;
      return;
    }
    camera = camera_->calibration();
  }
  std::string error;
  Masked masked;
  if (!withSelfMask(std::move(camera), *msg, &masked, &error)) {
    ACT_WALL_THROTTLE(5.0, NODELET_ERROR("the trainer's self mask is not used: %s", error.c_str()));
    return;
  }
  const size_t pixels = masked.pixels;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    useSelfMask(std::move(masked));
  }
  NODELET_INFO("the own robot's pixels learned by the trainer (%zu px) are labelled black from now on", pixels);
}

bool SegmentationNodelet::withSelfMask(core::CameraCalibration camera, const sensor_msgs::Image& msg, Masked* masked,
                                       std::string* error) {
  if (msg.encoding != "mono8") {
    *error = "encoding '" + msg.encoding + "', not mono8";
    return false;
  }
  *error =
      core::imageSizeProblem(static_cast<int>(msg.width), static_cast<int>(msg.height), camera.width, camera.height);
  if (!error->empty()) return false;
  if (msg.step < msg.width || msg.data.size() < static_cast<size_t>(msg.step) * msg.height) {
    *error = "its data is shorter than its step and height say";
    return false;
  }
  // The calibration's own mask stays part of it (the trainer sends the two together).
  core::addSelfMask(camera, msg.data.data(), camera.width, camera.height, msg.step);
  camera.self_mask_file.clear();
  masked->segmenter = std::make_shared<const core::Segmenter>(camera);
  // Its pixels are the own robot's, not the hall's or the carpet's: out of the carpet's edge too.
  masked->carpet_edge = std::make_shared<const core::CarpetEdge>(core::OmniCameraModel(camera));
  masked->pixels = static_cast<size_t>(std::count(camera.self_mask.begin(), camera.self_mask.end(), 1));
  return true;
}

void SegmentationNodelet::useSelfMask(Masked masked) {
  segmenter_ = std::move(masked.segmenter);
  carpet_edge_ = std::move(masked.carpet_edge);
  self_mask_pixels_ = masked.pixels;
}

void SegmentationNodelet::onTable(const act_color::ColorLutConstPtr& msg) {
  try {
    if (debug_addresses_) {
      std_msgs::UInt64MultiArray debug;
      debug.data = {msg->header.stamp.toNSec(), reinterpret_cast<uint64_t>(msg.get()), msg->revision};
      debug_pub_.publish(debug);
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!segmenter_) return;
      tables_.push_back(msg);  // keeps the shared pointer: no copy of the table
      while (tables_.size() > table_history_) tables_.pop_front();
      last_table_ = ros::WallTime::now();
    }
    flush();
  } catch (const std::exception& e) {
    ACT_WALL_THROTTLE(5.0, NODELET_ERROR("color table stamped %.3f: %s", msg->header.stamp.toSec(), e.what()));
  }
}

void SegmentationNodelet::onBall(const geometry_msgs::PointStampedConstPtr& msg) {
  if (!std::isfinite(msg->point.x) || !std::isfinite(msg->point.y)) {
    ACT_WALL_THROTTLE(5.0, NODELET_ERROR("ball stamped %.3f: not a finite point, ignored", msg->header.stamp.toSec()));
    return;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  balls_.push_back({msg->header.stamp, msg->point.x, msg->point.y});
  while (balls_.size() > table_history_) balls_.pop_front();
}

// Classifies the waiting images whose table is known. Image t takes the table stamped t; once a
// later table exists, or the image waited ~max_wait or the queue is full (the trainer skipped
// it or is not running), it takes the latest table stamped before t, else the newest there is
// (after time jumped back, or for an image older than every table kept). Every image is published;
// all unknown only while there is no table at all, and diagnostics say so.
void SegmentationNodelet::flush() {
  while (true) {
    sensor_msgs::ImageConstPtr image;
    act_color::ColorLutConstPtr lut;
    TableUsed used = TableUsed::kNone;
    std::optional<BallSighting> ball;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (pending_.empty()) return;
      const PendingImage& front = pending_.front();
      const ros::Time t = front.image->header.stamp;
      act_color::ColorLutConstPtr exact, before, after;
      for (const auto& table : tables_) {
        const ros::Time s = table->header.stamp;
        if (s == t) exact = table;
        if (s < t && (!before || s >= before->header.stamp)) before = table;
        if (s > t) after = table;
      }
      const double waited = (ros::WallTime::now() - front.arrival).toSec();
      if (exact) {
        lut = exact;
        used = TableUsed::kExact;
        ++exact_table_;
      } else if (after || waited >= max_wait_s_ || pending_.size() > queue_size_) {
        if (before) {
          lut = before;
          used = TableUsed::kOlder;
          ++older_table_;
          if (!after) {
            ACT_WALL_THROTTLE(5.0, NODELET_WARN("no table trained on the image stamped %.3f after %.2f s: using the "
                                                "one of %.3f",
                                                t.toSec(), waited, before->header.stamp.toSec()));
          }
        } else if (!tables_.empty() || fallback_) {
          lut = !tables_.empty() ? tables_.back() : fallback_;
          used = TableUsed::kNewest;
          ++newest_table_;
          ACT_WALL_THROTTLE(5.0, NODELET_WARN("no table stamped at or before the image stamped %.3f: using the newest "
                                              "(stamped %.3f)",
                                              t.toSec(), lut->header.stamp.toSec()));
        } else {
          ++no_table_;
          ACT_WALL_THROTTLE(5.0, NODELET_WARN("no color table for the image stamped %.3f yet (is the ACT trainer "
                                              "running?): labels are all unknown",
                                              t.toSec()));
        }
      } else {
        return;  // the table of this image is on its way
      }
      if (used != TableUsed::kNewest && used != TableUsed::kNone) fallback_.reset();
      image = front.image;
      pending_.pop_front();
      // The ball the trainer saw in this very image (with its table).
      if (used == TableUsed::kExact) {
        for (const BallSighting& b : balls_) {
          if (b.stamp == t) ball = b;
        }
      }
    }
    try {
      const double classify_ms = process(image, lut, ball);
      std::lock_guard<std::mutex> lock(mutex_);
      record(used, classify_ms, (ros::Time::now() - image->header.stamp).toSec() * 1000.0);
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      countRejected(e.what());
      ACT_WALL_THROTTLE(5.0,
                        NODELET_ERROR("image stamped %.3f not classified: %s", image->header.stamp.toSec(), e.what()));
    }
  }
}

void SegmentationNodelet::countRejected(const std::string& why) {
  ++rejected_;
  last_error_ = why;
  record(TableUsed::kRejected, 0.0, -1.0);
}

void SegmentationNodelet::record(TableUsed table, double classify_ms, double latency_ms) {
  const ros::WallTime now = ros::WallTime::now();
  window_.add({now, table, classify_ms, latency_ms});
}

double SegmentationNodelet::process(const sensor_msgs::ImageConstPtr& image, const act_color::ColorLutConstPtr& lut,
                                    const std::optional<BallSighting>& ball) {
  core::ImageView view;
  std::string error;
  if (!ros_conversions::imageView(*image, &view, &error)) throw std::invalid_argument(error);
  // Labels written straight into the outgoing message.
  cv::Mat labels;
  sensor_msgs::ImagePtr labels_msg = ros_conversions::newLabelsMsg(*image, &labels);
  std::shared_ptr<const core::Segmenter> segmenter;
  std::shared_ptr<const core::CarpetEdge> carpet_edge;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    segmenter = segmenter_;
    if (carpet_edge_on_) carpet_edge = carpet_edge_;
  }
  const auto start = std::chrono::steady_clock::now();
  if (lut) {
    segmenter->classify(ros_conversions::lutView(*lut), view, labels);  // throws for a wrong size or color space
    const uint32_t unlabelled = carpet_edge ? carpet_edge->unlabelBeyond(labels) : 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      beyond_carpet_ = unlabelled;
    }
    if (ball) {
      double radius_m = 0;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        radius_m = ball_radius_m_;
      }
      core::labelBallImage(*camera_, radius_m, ball->x_m, ball->y_m, labels);
    }
  }
  const double classify_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (features_pub_.getNumSubscribers() > 0) {
    auto features = boost::make_shared<act_color::VisionFeatures>();
    features->header = image->header;
    features->lut_revision = lut ? lut->revision : 0;
    core::FeatureParams params;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      params = feature_params_;
    }
    std::vector<core::Feature> found = core::extractFeatures(labels, *camera_, params);
    core::Pose2D pose;
    std::string why;
    features->pose_valid = pose_source_.lookup(image->header.stamp, &pose, &why);
    if (features->pose_valid) {
      core::toField(pose, &found);
      core::removeOffField(field_, &found);  // hall clutter and people beyond the carpet
      features->pose.x = pose.x_m;
      features->pose.y = pose.y_m;
      features->pose.theta = pose.theta_rad;
    }
    features->features.reserve(found.size());
    for (const core::Feature& f : found) {
      act_color::VisionFeature m;
      m.type = static_cast<uint8_t>(f.type);
      m.u = f.u;
      m.v = f.v;
      m.centroid_u = f.centroid_u;
      m.centroid_v = f.centroid_v;
      m.base_x = f.base_x_m;
      m.base_y = f.base_y_m;
      m.field_x = f.field_x_m;
      m.field_y = f.field_y_m;
      m.size = f.size;
      features->features.push_back(m);
    }
    features_pub_.publish(boost::shared_ptr<const act_color::VisionFeatures>(features));
  }
  if (labels_color_pub_.getNumSubscribers() > 0) {
    cv_bridge::CvImage color(image->header, "rgb8");
    core::colorizeLabels(labels, color.image);
    labels_color_pub_.publish(color.toImageMsg());
  }
  labels_pub_.publish(boost::shared_ptr<const sensor_msgs::Image>(labels_msg));
  std::lock_guard<std::mutex> lock(mutex_);
  ++labeled_;
  return classify_ms;
}

void SegmentationNodelet::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  std::lock_guard<std::mutex> lock(mutex_);
  if (loading()) {
    status.summary(DiagnosticStatus::WARN, "loading the calibration");
    return;
  }
  if (!config_error_.empty() || !segmenter_) {
    status.summary(DiagnosticStatus::ERROR, "not configured: " + config_error_);
    return;
  }
  const ros::WallTime now = ros::WallTime::now();
  window_.trim(now);
  size_t counts[5] = {0, 0, 0, 0, 0};
  double sum_ms = 0, max_ms = 0, sum_latency = 0, max_latency = 0;
  size_t classified = 0;
  for (const Record& r : window_) {
    ++counts[static_cast<int>(r.table)];
    if (r.table == TableUsed::kRejected) continue;
    ++classified;
    sum_ms += r.classify_ms;
    max_ms = std::max(max_ms, r.classify_ms);
    sum_latency += r.latency_ms;
    max_latency = std::max(max_latency, r.latency_ms);
  }
  const size_t n = window_.size();
  using ros_conversions::percent;
  const size_t exact = counts[static_cast<int>(TableUsed::kExact)];
  const size_t none = counts[static_cast<int>(TableUsed::kNone)];
  const size_t rejected = counts[static_cast<int>(TableUsed::kRejected)];
  const size_t stale = counts[static_cast<int>(TableUsed::kOlder)] + counts[static_cast<int>(TableUsed::kNewest)];
  const double since_image = last_image_.isZero() ? -1.0 : (now - last_image_).toSec();
  const double since_table = last_table_.isZero() ? -1.0 : (now - last_table_).toSec();
  std::ostringstream m;
  m.precision(3);
  status.summary(DiagnosticStatus::OK, "segmenting");
  const bool waiting_for_subscribers = lazy_ && !image_sub_;
  if (waiting_for_subscribers) {
    status.summary(DiagnosticStatus::OK, "idle: nobody subscribes to the labels or features");
  } else if (images_ == 0) {
    status.summary(DiagnosticStatus::WARN, "no image received yet");
  } else if (since_image > 2.0) {
    m << "no image for " << since_image << " s (input stale)";
    status.summary(DiagnosticStatus::WARN, m.str());
  } else {
    if (n > 0 && none == n) {
      status.mergeSummary(DiagnosticStatus::ERROR, "no color table received: labels are all unknown");
    } else if (since_table > 2.0 || (since_table < 0 && n > 0)) {
      m << "no new color table for " << since_table << " s (is the ACT trainer running?): labels from an old table";
      status.mergeSummary(DiagnosticStatus::WARN, m.str());
      m.str("");
    } else if (n > 0 && stale > 0.1 * n) {
      m << percent(stale, n) << "% of the images classified with an older table (frames not trained)";
      status.mergeSummary(DiagnosticStatus::WARN, m.str());
      m.str("");
    }
    if (rejected > 0) {
      m << rejected << " of " << n << " images in " << kWindowS << " s not classified: " << last_error_;
      status.mergeSummary(rejected == n ? DiagnosticStatus::ERROR : DiagnosticStatus::WARN, m.str());
    }
  }
  status.add("label rate (Hz)", window_.rateHz());
  status.add("own robot's pixels learned by the trainer, labelled black", self_mask_pixels_);
  status.add("pixels beyond the carpet's edge labelled unknown (last image)", beyond_carpet_);
  status.add("with the table of the same frame (%, last 5 s)", percent(exact, n));
  status.add("with an older or the newest table (%, last 5 s)", percent(stale, n));
  status.add("without a table, all unknown (%, last 5 s)", percent(none, n));
  status.add("classify time mean (ms, last 5 s)", classified ? sum_ms / classified : 0.0);
  status.add("classify time max (ms, last 5 s)", max_ms);
  status.add("latency image stamp to labels mean (ms, last 5 s)", classified ? sum_latency / classified : 0.0);
  status.add("latency image stamp to labels max (ms, last 5 s)", max_latency);
  status.add("seconds since the last table", since_table);
  status.add("images", images_);
  status.add("labels published", labeled_);
  status.add("with the table of the same frame", exact_table_);
  status.add("with an older table (frame not trained)", older_table_);
  status.add("with the newest table (none at or before the frame)", newest_table_);
  status.add("without a table (all unknown)", no_table_);
  status.add("images rejected", rejected_);
  status.add("last rejection", last_error_);
  status.add("images waiting", pending_.size());
  status.add("time jumps back", time_jumps_);
  status.add("last table revision", tables_.empty() ? 0 : tables_.back()->revision);
}

}  // namespace act_color

PLUGINLIB_EXPORT_CLASS(act_color::SegmentationNodelet, nodelet::Nodelet)
