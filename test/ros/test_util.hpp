#pragma once

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <nodelet/NodeletLoad.h>
#include <nodelet/NodeletUnload.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <boost/make_shared.hpp>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "act_color/core/metrics.hpp"
#include "act_color/core/types.hpp"

namespace act_color_test {

// Collects state from subscriber callbacks and lets the test wait for a condition on it with a
// deadline (no bare sleeps): callbacks call notify() after changing the state under mutex().
class Waiter {
 public:
  std::mutex& mutex() { return mutex_; }
  void notify() { cv_.notify_all(); }
  // True when `done` became true before `timeout_s` (wall time) passed; `done` runs under mutex().
  bool waitFor(double timeout_s, const std::function<bool()>& done) {
    std::unique_lock<std::mutex> lock(mutex_);
    const auto deadline =
        std::chrono::steady_clock::now() +
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(timeout_s));
    // Re-checks at least every 100 ms as well, for conditions that depend on time.
    while (!done()) {
      if (std::chrono::steady_clock::now() >= deadline) return false;
      const std::chrono::steady_clock::time_point next =
          std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
      cv_.wait_until(lock, std::min(deadline, next));
    }
    return true;
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
};

// Recall and precision of each trainable class (in core::trainableClasses() order) at least the
// given values; classes beyond the lists are not checked.
inline void expectPerClassAtLeast(const act_color::core::ClassificationMetrics& metrics,
                                  const std::vector<double>& min_recall, const std::vector<double>& min_precision) {
  const auto& classes = act_color::core::trainableClasses();
  for (size_t i = 0; i < classes.size() && i < min_recall.size() && i < min_precision.size(); ++i) {
    const int k = classes[i];
    EXPECT_GE(metrics.recall(k), min_recall[i]) << "recall of " << act_color::core::className(k);
    EXPECT_GE(metrics.precision(k), min_precision[i]) << "precision of " << act_color::core::className(k);
  }
}

// An image message holding a copy of `mat`.
inline sensor_msgs::ImagePtr makeImage(const cv::Mat& mat, const std::string& encoding, const ros::Time& stamp) {
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->header.stamp = stamp;
  msg->header.frame_id = "omni_camera";
  msg->height = mat.rows;
  msg->width = mat.cols;
  msg->encoding = encoding;
  msg->step = static_cast<uint32_t>(mat.cols * mat.elemSize());
  msg->data.assign(mat.datastart, mat.dataend);
  return msg;
}

// A localization message (frame field) for a planar pose.
inline geometry_msgs::PoseWithCovarianceStamped makePose(const act_color::core::Pose2D& p, const ros::Time& stamp) {
  geometry_msgs::PoseWithCovarianceStamped msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = "field";
  msg.pose.pose.position.x = p.x_m;
  msg.pose.pose.position.y = p.y_m;
  msg.pose.pose.orientation.z = std::sin(p.theta_rad / 2);
  msg.pose.pose.orientation.w = std::cos(p.theta_rad / 2);
  return msg;
}

// A nodelet of `type` loaded as `name` into the nodelet manager `manager` (its node name) through
// the manager's service, as `rosrun nodelet nodelet load` does; false when the call or the load fails.
inline bool loadNodelet(const std::string& manager, const std::string& name, const std::string& type) {
  nodelet::NodeletLoad srv;
  srv.request.name = name;
  srv.request.type = type;
  return ros::service::call(manager + "/load_nodelet", srv) && srv.response.success;
}

// The nodelet `name` unloaded from `manager`; false when the call or the unload fails.
inline bool unloadNodelet(const std::string& manager, const std::string& name) {
  nodelet::NodeletUnload srv;
  srv.request.name = name;
  return ros::service::call(manager + "/unload_nodelet", srv) && srv.response.success;
}

}  // namespace act_color_test
