#include "act_color/ros/pose_source.hpp"

#include <geometry_msgs/TransformStamped.h>

#include <algorithm>
#include <sstream>

#include "act_color/ros/conversions.hpp"
#include "act_color/ros/nodelet_setup.hpp"

namespace act_color {
namespace ros_conversions {
namespace {
// About 3 s of poses at 60 Hz: enough to find the pose of a frame that waited in a queue.
constexpr size_t kMaxPoses = 200;
}  // namespace

bool PoseSource::init(ros::NodeHandle& nh, ros::NodeHandle& pnh, const std::string& name, std::string* error) {
  name_ = name;
  std::string source = "topic";
  if (!readParam(pnh, "pose_source", &source, error) || !readParam(pnh, "max_pose_age", &max_age_s_, error) ||
      !readParam(pnh, "field_frame", &field_frame_, error) || !readParam(pnh, "base_frame", &base_frame_, error)) {
    return false;
  }
  if (!(max_age_s_ > 0.0 && max_age_s_ <= 60.0)) {
    *error = "parameter ~max_pose_age must be in (0, 60] s, is " + std::to_string(max_age_s_);
    return false;
  }
  if (source == "topic") {
    mode_ = Mode::kTopic;
    sub_ = nh.subscribe("pose", 20, &PoseSource::onPose, this);
  } else if (source == "tf") {
    mode_ = Mode::kTf;
    tf_buffer_ = std::make_unique<tf2_ros::Buffer>(ros::Duration(10.0));
    // No own thread: tf messages are handled by the nodelet's callback queue.
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_, nh, false);
  } else {
    *error = "~pose_source must be 'topic' or 'tf', is '" + source + "'";
    return false;
  }
  return true;
}

void PoseSource::onPose(const geometry_msgs::PoseWithCovarianceStampedConstPtr& msg) {
  core::Pose2D pose;
  std::string error;
  std::lock_guard<std::mutex> lock(mutex_);
  ++received_;
  if (!pose2D(msg->pose.pose, &pose, &error) || !plausible(pose, &error)) {
    ++rejected_;
    last_rejection_ = "pose stamped " + std::to_string(msg->header.stamp.toSec()) + " rejected: " + error;
    if (wallThrottle(name_ + keyOf(error), 5.0)) ROS_ERROR("%s: %s", name_.c_str(), last_rejection_.c_str());
    return;
  }
  if (!msg->header.frame_id.empty() && msg->header.frame_id != field_frame_ &&
      msg->header.frame_id != "/" + field_frame_) {
    ++rejected_;
    last_rejection_ = "pose in frame '" + msg->header.frame_id + "' rejected: expected '" + field_frame_ + "'";
    // Throttled per nodelet (a throttle per call site is one for every nodelet in the manager: the
    // segmentation's rejection went unsaid behind the trainer's).
    if (wallThrottle(name_ + " frame", 5.0)) ROS_ERROR("%s: %s", name_.c_str(), last_rejection_.c_str());
    return;
  }
  if (!newest_stamp_.isZero() && msg->header.stamp + ros::Duration(TimeJumpDetector::kJumpBackS) < newest_stamp_) {
    // A new replay of a bag: the poses of the old run would be taken for this one's.
    ROS_WARN("%s: pose stamps jumped back from %.3f to %.3f: forgetting the %zu poses before", name_.c_str(),
             newest_stamp_.toSec(), msg->header.stamp.toSec(), poses_.size());
    poses_.clear();
    newest_stamp_ = ros::Time();
    ++time_jumps_;
  }
  if (msg->header.stamp > newest_stamp_) newest_stamp_ = msg->header.stamp;
  poses_.emplace_back(msg->header.stamp, pose);
  while (poses_.size() > kMaxPoses) poses_.pop_front();
}

bool PoseSource::lookup(const ros::Time& stamp, core::Pose2D* pose, std::string* why) {
  if (mode_ == Mode::kTf) {
    try {
      // Zero timeout: never waits for tf here (the caller holds the image, mayStillCome()).
      const geometry_msgs::TransformStamped t = tf_buffer_->lookupTransform(field_frame_, base_frame_, stamp);
      geometry_msgs::Pose p;
      p.position.x = t.transform.translation.x;
      p.position.y = t.transform.translation.y;
      p.position.z = t.transform.translation.z;
      p.orientation = t.transform.rotation;
      return pose2D(p, pose, why) && plausible(*pose, why);
    } catch (const std::exception& e) {
      *why = std::string("no tf ") + field_frame_ + " -> " + base_frame_ + " at the image stamp: " + e.what();
      return false;
    }
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (poses_.empty()) {
    *why = "no pose received yet";
    return false;
  }
  const std::pair<ros::Time, core::Pose2D>* best = nullptr;
  for (const auto& p : poses_) {
    if (p.first <= stamp && (best == nullptr || p.first >= best->first)) best = &p;
  }
  if (best == nullptr) {
    std::ostringstream s;
    s << "no pose at or before the image stamp " << stamp.toSec() << " (oldest pose: " << poses_.front().first.toSec()
      << ")";
    *why = s.str();
    return false;
  }
  const double age = (stamp - best->first).toSec();
  if (age > max_age_s_) {
    std::ostringstream s;
    s << "the latest pose before the image is " << age << " s old (~max_pose_age " << max_age_s_ << " s)";
    *why = s.str();
    return false;
  }
  *pose = best->second;
  return true;
}

bool PoseSource::mayStillCome(const ros::Time& stamp) const {
  if (mode_ == Mode::kTf) {
    try {
      // The newest transform there is: a later one for `stamp` may still come while it is older.
      const geometry_msgs::TransformStamped t = tf_buffer_->lookupTransform(field_frame_, base_frame_, ros::Time(0));
      return t.header.stamp < stamp;
    } catch (const std::exception&) {
      return true;  // no transform yet at all
    }
  }
  std::lock_guard<std::mutex> lock(mutex_);
  return newest_stamp_ < stamp;
}

void PoseSource::forgetNewerThan(const ros::Time& stamp) {
  std::lock_guard<std::mutex> lock(mutex_);
  poses_.erase(std::remove_if(poses_.begin(), poses_.end(), [&](const auto& p) { return p.first > stamp; }),
               poses_.end());
  newest_stamp_ = ros::Time();
  for (const auto& p : poses_) newest_stamp_ = std::max(newest_stamp_, p.first);
  if (tf_buffer_) {
    try {
      if (tf_buffer_->lookupTransform(field_frame_, base_frame_, ros::Time(0)).header.stamp > stamp)
        tf_buffer_->clear();
    } catch (const std::exception&) {
      // nothing there to forget
    }
  }
}

void PoseSource::setFieldBounds(const core::PoseBounds& bounds) {
  std::lock_guard<std::mutex> lock(mutex_);
  bounds_ = bounds;
}

bool PoseSource::plausible(const core::Pose2D& pose, std::string* why) const {
  return bounds_.contains(pose.x_m, pose.y_m, why);
}

void PoseSource::setMaxAge(double max_age_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  max_age_s_ = max_age_s;
}

uint64_t PoseSource::timeJumps() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return time_jumps_;
}

uint64_t PoseSource::received() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return received_;
}
uint64_t PoseSource::rejected() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return rejected_;
}
std::string PoseSource::lastRejection() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_rejection_;
}

}  // namespace ros_conversions
}  // namespace act_color
