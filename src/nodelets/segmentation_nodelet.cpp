// Segmentation nodelet: classifies every camera image with the color table the ACT trainer
// trained on that very image (zero copy: the table is the trainer's shared message), publishes
// the labels and the features the robot's other modules need.
#include <cv_bridge/cv_bridge.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/Pose2D.h>
#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <std_msgs/UInt64MultiArray.h>

#include <boost/make_shared.hpp>
#include <deque>
#include <memory>
#include <mutex>
#include <pluginlib/class_list_macros.hpp>
#include <string>

#include "act_color/ColorLut.h"
#include "act_color/VisionFeatures.h"
#include "act_color/core/calibration.hpp"
#include "act_color/core/feature_extractor.hpp"
#include "act_color/core/omni_camera_model.hpp"
#include "act_color/core/segmenter.hpp"
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

  void onInit() override;
  bool configure(std::string* error);
  void connectCb();
  void onImage(const sensor_msgs::ImageConstPtr& msg);
  void onTable(const act_color::ColorLutConstPtr& msg);
  void flush();
  void process(const sensor_msgs::ImageConstPtr& image, const act_color::ColorLutConstPtr& lut);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle nh_, pnh_;
  std::unique_ptr<image_transport::ImageTransport> it_;
  image_transport::Subscriber image_sub_;
  ros::Subscriber lut_sub_;
  image_transport::Publisher labels_pub_, labels_color_pub_;
  ros::Publisher features_pub_, debug_pub_;
  ros::WallTimer flush_timer_;
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  ros::Timer diagnostics_timer_;
  ros_conversions::PoseSource pose_source_;

  std::mutex mutex_;  // guards everything below
  std::string config_error_;
  std::unique_ptr<core::OmniCameraModel> camera_;
  std::unique_ptr<core::Segmenter> segmenter_;
  core::FeatureParams feature_params_;
  bool lazy_ = false;
  bool debug_addresses_ = false;
  size_t queue_size_ = 5;
  double max_wait_s_ = 0.2;
  size_t table_history_ = 10;
  std::deque<PendingImage> pending_;                // by arrival
  std::deque<act_color::ColorLutConstPtr> tables_;  // shared, never copied; by arrival
  // Statistics.
  uint64_t images_ = 0, labeled_ = 0, exact_table_ = 0, older_table_ = 0, no_table_ = 0, rejected_ = 0;
};

void SegmentationNodelet::onInit() {
  nh_ = getNodeHandle();
  pnh_ = getPrivateNodeHandle();
  updater_ = ros_conversions::makeDiagnostics(
      nh_, pnh_, getName(), "segmentation", [this](diagnostic_updater::DiagnosticStatusWrapper& s) { diagnose(s); },
      &diagnostics_timer_);
  const std::string error = ros_conversions::runConfigure([this](std::string* e) { return configure(e); });
  if (!error.empty()) {
    NODELET_ERROR("not started: %s", error.c_str());
    std::lock_guard<std::mutex> lock(mutex_);
    config_error_ = error;
  }
}

bool SegmentationNodelet::configure(std::string* error) {
  core::Calibration calibration;
  std::string calibration_path;
  if (!ros_conversions::loadCalibrationParam(pnh_, &calibration, &calibration_path, error)) return false;
  const int queue_size = pnh_.param("queue_size", 5);
  const double max_wait = pnh_.param("max_wait", 0.2);
  const int history = pnh_.param("table_history", 10);
  if (queue_size < 1 || queue_size > 100 || !(max_wait >= 0.0 && max_wait <= 10.0) || history < 1 || history > 100) {
    *error = "~queue_size must be in [1, 100], ~max_wait in [0, 10] s, ~table_history in [1, 100]";
    return false;
  }
  core::FeatureParams fp;
  fp.scan_lines = pnh_.param("scan_lines", fp.scan_lines);
  fp.min_ball_pixels = pnh_.param("min_ball_pixels", fp.min_ball_pixels);
  if (fp.scan_lines < 4 || fp.scan_lines > 3600) {
    *error = "~scan_lines must be in [4, 3600]";
    return false;
  }
  if (!pose_source_.init(nh_, pnh_, getName(), error)) return false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    camera_ = std::make_unique<core::OmniCameraModel>(calibration.camera);
    segmenter_ = std::make_unique<core::Segmenter>(calibration.camera);
    feature_params_ = fp;
    queue_size_ = static_cast<size_t>(queue_size);
    max_wait_s_ = max_wait;
    table_history_ = static_cast<size_t>(history);
    lazy_ = pnh_.param("lazy", false);
    debug_addresses_ = pnh_.param("debug_lut_addresses", false);
  }
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
  flush_timer_ = nh_.createWallTimer(ros::WallDuration(0.02), [this](const ros::WallTimerEvent&) {
    try {
      flush();
    } catch (const std::exception& e) {
      NODELET_ERROR_THROTTLE(5.0, "%s", e.what());
    }
  });
  connectCb();
  NODELET_INFO("segmentation ready: calibration %s, %s", calibration_path.c_str(),
               lazy_ ? "inputs subscribed while someone listens" : "always subscribed");
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
  } else if (!wanted && image_sub_) {
    image_sub_.shutdown();
    lut_sub_.shutdown();
    pending_.clear();
  }
}

void SegmentationNodelet::onImage(const sensor_msgs::ImageConstPtr& msg) {
  try {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!segmenter_) return;
      ++images_;
      pending_.push_back({msg, ros::WallTime::now()});
    }
    flush();
  } catch (const std::exception& e) {
    NODELET_ERROR_THROTTLE(5.0, "image stamped %.3f: %s", msg->header.stamp.toSec(), e.what());
  }
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
    }
    flush();
  } catch (const std::exception& e) {
    NODELET_ERROR_THROTTLE(5.0, "color table stamped %.3f: %s", msg->header.stamp.toSec(), e.what());
  }
}

// Classifies the waiting images whose table is known. Image t takes the table stamped t; once a
// later table exists, or the image waited ~max_wait or the queue is full (the trainer skipped
// it or is not running), it takes the latest table stamped before t. Every image is published.
void SegmentationNodelet::flush() {
  while (true) {
    sensor_msgs::ImageConstPtr image;
    act_color::ColorLutConstPtr lut;
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
      const bool timed_out = (ros::WallTime::now() - front.arrival).toSec() >= max_wait_s_;
      if (exact) {
        lut = exact;
        ++exact_table_;
      } else if (after || timed_out || pending_.size() > queue_size_) {
        lut = before;
        if (before) {
          ++older_table_;
        } else {
          ++no_table_;
        }
        if (!after && !before) {
          NODELET_WARN_THROTTLE(5.0,
                                "no color table for the image stamped %.3f yet (is the ACT trainer running?): "
                                "labels are all unknown",
                                t.toSec());
        } else if (!after) {
          NODELET_WARN_THROTTLE(5.0, "no table trained on the image stamped %.3f after %.2f s: using the one of %.3f",
                                t.toSec(), (ros::WallTime::now() - front.arrival).toSec(),
                                before->header.stamp.toSec());
        }
      } else {
        return;  // the table of this image is on its way
      }
      image = front.image;
      pending_.pop_front();
    }
    try {
      process(image, lut);
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      ++rejected_;
      NODELET_ERROR_THROTTLE(5.0, "image stamped %.3f not classified: %s", image->header.stamp.toSec(), e.what());
    }
  }
}

void SegmentationNodelet::process(const sensor_msgs::ImageConstPtr& image, const act_color::ColorLutConstPtr& lut) {
  core::ImageView view;
  std::string error;
  if (!ros_conversions::imageView(*image, &view, &error)) throw std::invalid_argument(error);
  // Labels written straight into the outgoing message.
  cv::Mat labels;
  sensor_msgs::ImagePtr labels_msg = ros_conversions::newLabelsMsg(*image, &labels);
  if (lut) {
    segmenter_->classify(ros_conversions::lutView(*lut), view, labels);  // throws for a wrong size or color space
  } else if (image->width != static_cast<uint32_t>(camera_->width()) ||
             image->height != static_cast<uint32_t>(camera_->height())) {
    throw std::invalid_argument("image is " + std::to_string(image->width) + "x" + std::to_string(image->height) +
                                " px, the calibration is for " + std::to_string(camera_->width()) + "x" +
                                std::to_string(camera_->height()));
  }
  if (features_pub_.getNumSubscribers() > 0) {
    auto features = boost::make_shared<act_color::VisionFeatures>();
    features->header = image->header;
    features->lut_revision = lut ? lut->revision : 0;
    std::vector<core::Feature> found = core::extractFeatures(labels, *camera_, feature_params_);
    core::Pose2D pose;
    std::string why;
    features->pose_valid = pose_source_.lookup(image->header.stamp, &pose, &why);
    if (features->pose_valid) {
      core::toField(pose, &found);
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
}

void SegmentationNodelet::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!config_error_.empty() || !segmenter_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "not configured: " + config_error_);
    return;
  }
  if (images_ == 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no image received yet");
  } else if (no_table_ > 0 && labeled_ == no_table_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no color table received");
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "segmenting");
  }
  status.add("images", images_);
  status.add("labels published", labeled_);
  status.add("with the table of the same frame", exact_table_);
  status.add("with an older table (frame not trained)", older_table_);
  status.add("without a table (all unknown)", no_table_);
  status.add("images rejected", rejected_);
  status.add("images waiting", pending_.size());
  status.add("last table revision", tables_.empty() ? 0 : tables_.back()->revision);
}

}  // namespace act_color

PLUGINLIB_EXPORT_CLASS(act_color::SegmentationNodelet, nodelet::Nodelet)
