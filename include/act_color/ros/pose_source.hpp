#pragma once

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <deque>
#include <memory>
#include <mutex>
#include <string>

#include "act_color/core/calibration.hpp"
#include "act_color/core/types.hpp"

namespace act_color {
namespace ros_conversions {

// The pose of base_link in field at an image's stamp, from the localization topic (the latest
// pose at or before the stamp) or from tf (field -> base_link at the stamp). Never blocks: a caller
// whose pose is not there yet asks mayStillCome() and tries again later (the trainer holds such an
// image up to ~tf_timeout). Thread-safe.
class PoseSource {
 public:
  enum class Mode { kTopic, kTf };

  // Reads ~pose_source ("topic" or "tf"), ~max_pose_age, ~field_frame, ~base_frame; subscribes to
  // "pose" in `nh` or listens to tf. False with a reason for a bad ~pose_source. `name` prefixes
  // the throttled errors about rejected poses.
  bool init(ros::NodeHandle& nh, ros::NodeHandle& pnh, const std::string& name, std::string* error);

  // False with a reason (no pose yet, none before the stamp, too old, tf unavailable).
  bool lookup(const ros::Time& stamp, core::Pose2D* pose, std::string* why);
  // After a failed lookup: true while the pose for `stamp` may still arrive (no pose or transform
  // stamped at or after it has come yet).
  bool mayStillCome(const ros::Time& stamp) const;
  // After time jumped back: forgets the poses stamped after `stamp` (the old run's) and, in tf
  // mode, tf's buffer when it holds such transforms.
  void forgetNewerThan(const ros::Time& stamp);
  void setMaxAge(double max_age_s);
  // Poses outside these bounds (the carpet plus a margin, core::PoseBounds) are rejected.
  void setFieldBounds(const core::PoseBounds& bounds);
  // Times the pose stamps jumped back by more than a second (a new replay); reset() was called.
  uint64_t timeJumps() const;

  Mode mode() const { return mode_; }
  // Poses received and rejected (NaN, non-planar) so far.
  uint64_t received() const;
  uint64_t rejected() const;
  // A message for the last rejected pose; empty when none.
  std::string lastRejection() const;
  // False with a reason for a pose off the field (the calibration's, with its margin).
  bool plausible(const core::Pose2D& pose, std::string* why) const;

 private:
  void onPose(const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg);

  Mode mode_ = Mode::kTopic;
  std::string name_;
  double max_age_s_ = 1.0;
  core::PoseBounds bounds_;  // everywhere until the calibration is loaded
  std::string field_frame_ = "field";
  std::string base_frame_ = "base_link";
  ros::Subscriber sub_;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;

  mutable std::mutex mutex_;
  std::deque<std::pair<ros::Time, core::Pose2D>> poses_;  // in arrival order
  uint64_t received_ = 0;
  uint64_t rejected_ = 0;
  uint64_t time_jumps_ = 0;
  ros::Time newest_stamp_;
  std::string last_rejection_;
};

}  // namespace ros_conversions
}  // namespace act_color
