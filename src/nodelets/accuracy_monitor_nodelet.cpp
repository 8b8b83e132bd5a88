// Accuracy monitor: compares /segmentation/labels with the simulator's truth labels of the same
// stamp and prints recall and precision per class every few seconds.
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Float64MultiArray.h>

#include <cmath>
#include <deque>
#include <mutex>
#include <opencv2/core.hpp>
#include <pluginlib/class_list_macros.hpp>
#include <sstream>

#include "act_color/core/metrics.hpp"
#include "act_color/core/types.hpp"
#include "act_color/ros/nodelet_setup.hpp"

namespace act_color {

class AccuracyMonitorNodelet : public nodelet::Nodelet {
 private:
  void onInit() override;
  void onLabels(const sensor_msgs::ImageConstPtr& msg);
  void onTruth(const sensor_msgs::ImageConstPtr& msg);
  void match();
  void report();

  ros::Subscriber labels_sub_, truth_sub_;
  ros::Publisher accuracy_pub_;
  ros::WallTimer timer_;
  std::mutex mutex_;
  std::deque<sensor_msgs::ImageConstPtr> labels_, truth_;
  core::ClassificationMetrics window_, total_;
  uint64_t frames_window_ = 0, frames_total_ = 0, unmatched_ = 0;
};

void AccuracyMonitorNodelet::onInit() {
  ros::NodeHandle& nh = getNodeHandle();
  ros::NodeHandle& pnh = getPrivateNodeHandle();
  const double period = pnh.param("report_period", 2.0);
  labels_sub_ = nh.subscribe("labels", 10, &AccuracyMonitorNodelet::onLabels, this);
  truth_sub_ = nh.subscribe("labels_truth", 10, &AccuracyMonitorNodelet::onTruth, this);
  // [pixel accuracy, recall of green, white, yellow, blue, black, min precision] of the last period.
  accuracy_pub_ = pnh.advertise<std_msgs::Float64MultiArray>("accuracy", 10);
  timer_ = nh.createWallTimer(ros::WallDuration(period > 0.1 ? period : 0.1), [this](const ros::WallTimerEvent&) {
    try {
      report();
    } catch (const std::exception& e) {
      ACT_WALL_THROTTLE(10.0, NODELET_ERROR("%s", e.what()));
    }
  });
}

void AccuracyMonitorNodelet::onLabels(const sensor_msgs::ImageConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  labels_.push_back(msg);
  match();
}

void AccuracyMonitorNodelet::onTruth(const sensor_msgs::ImageConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  truth_.push_back(msg);
  match();
}

void AccuracyMonitorNodelet::match() {
  for (auto l = labels_.begin(); l != labels_.end();) {
    bool matched = false;
    for (auto t = truth_.begin(); t != truth_.end(); ++t) {
      if ((*t)->header.stamp != (*l)->header.stamp) continue;
      const auto& a = **l;
      const auto& b = **t;
      if (a.encoding == "mono8" && b.encoding == "mono8" && a.width == b.width && a.height == b.height) {
        const cv::Mat la(a.height, a.width, CV_8UC1, const_cast<uint8_t*>(a.data.data()), a.step);
        const cv::Mat tb(b.height, b.width, CV_8UC1, const_cast<uint8_t*>(b.data.data()), b.step);
        window_.add(la, tb);
        total_.add(la, tb);
        ++frames_window_;
        ++frames_total_;
      } else {
        ACT_WALL_THROTTLE(10.0, NODELET_ERROR("labels and truth of stamp %.3f do not fit (mono8, same size expected)",
                                              a.header.stamp.toSec()));
      }
      truth_.erase(t);
      matched = true;
      break;
    }
    l = matched ? labels_.erase(l) : l + 1;
  }
  // Whatever has not found its partner within 60 messages never will.
  while (labels_.size() > 60) {
    labels_.pop_front();
    ++unmatched_;
  }
  while (truth_.size() > 60) truth_.pop_front();
}

void AccuracyMonitorNodelet::report() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (frames_window_ == 0) {
    NODELET_INFO("accuracy: no labeled frame with truth in the last period (%lu frames so far)",
                 static_cast<unsigned long>(frames_total_));
    return;
  }
  uint64_t correct = 0, all = 0;
  for (int k = 0; k < core::kNumClasses; ++k) {
    for (int p = 0; p < core::kNumClasses; ++p) {
      all += window_.confusion()[k][p];
      if (k == p) correct += window_.confusion()[k][p];
    }
  }
  std::ostringstream s;
  s.precision(3);
  s << std::fixed << "accuracy over " << frames_window_ << " frames: pixels " << (all ? double(correct) / all : 0.0)
    << " | recall";
  std_msgs::Float64MultiArray out;
  out.data.push_back(all ? double(correct) / all : 0.0);
  double min_precision = 1.0;
  for (int k : core::trainableClasses()) {
    const double r = window_.recall(k);
    s << " " << core::className(k) << " " << r;
    out.data.push_back(r);
    const double p = window_.precision(k);
    if (std::isfinite(p)) min_precision = std::min(min_precision, p);
  }
  s << " | min precision " << min_precision << " | fitness (eq. 6) " << window_.fitness(core::trainableClasses());
  out.data.push_back(min_precision);
  NODELET_INFO("%s", s.str().c_str());
  accuracy_pub_.publish(out);
  window_.clear();
  frames_window_ = 0;
}

}  // namespace act_color

PLUGINLIB_EXPORT_CLASS(act_color::AccuracyMonitorNodelet, nodelet::Nodelet)
