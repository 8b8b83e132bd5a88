#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include <algorithm>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "act_color/core/calibration.hpp"
#include "act_color/ros/pose_source.hpp"

// Runs `statement` (a log call) at most once per `period` seconds of wall time at this place:
// rosconsole's *_THROTTLE runs on ROS time, so with a stopped /clock (a paused bag) it prints once
// and then never, and after the clock jumps back it stays silent until the clock has caught up.
//   ACT_WALL_THROTTLE(5.0, NODELET_WARN("image rejected: %s", why.c_str()));
#define ACT_WALL_THROTTLE(period, ...)                                                                   \
  do {                                                                                                   \
    static const std::string act_throttle_key_ = std::string(__FILE__) + ":" + std::to_string(__LINE__); \
    if (::act_color::ros_conversions::wallThrottle(act_throttle_key_, (period))) {                       \
      __VA_ARGS__;                                                                                       \
    }                                                                                                    \
  } while (false)

namespace act_color {
namespace ros_conversions {

// A wall-time throttle per key (thread-safe): true at most once per `period_s` for each key, so
// that one kind of bad input does not hide another. Keys are call sites (ACT_WALL_THROTTLE) or kinds
// of messages, e.g. a message's text up to its first number (keyOf).
bool wallThrottle(const std::string& key, double period_s);
std::string keyOf(const std::string& message);

// A nodelet's diagnostics: an updater (hardware id "act_color") with one task, published every
// second of wall time by *timer, so that they go on while /clock stops or jumps back.
std::unique_ptr<diagnostic_updater::Updater> makeDiagnostics(
    ros::NodeHandle& nh, ros::NodeHandle& pnh, const std::string& node_name, const std::string& task,
    const std::function<void(diagnostic_updater::DiagnosticStatusWrapper&)>& diagnose, ros::WallTimer* timer);

// Runs a nodelet's configuration step; an exception is an error too. Empty when it succeeded,
// else the reason. A nodelet that fails stays loaded and harmless: one that throws or exits takes
// its whole manager with it.
std::string runConfigure(const std::function<bool(std::string*)>& configure);

// Work that may take long (a large calibration file, the camera model of a large image) off the
// nodelet manager's load path: onInit returns at once and the manager goes on loading the other
// nodelets while `work` runs on a thread of its own. `work` reports its own errors (an exception
// is caught and passed to `on_error`). The owner calls wait() first in its destructor, before the
// members the work uses go.
class BackgroundTask {
 public:
  BackgroundTask() = default;
  BackgroundTask(const BackgroundTask&) = delete;
  BackgroundTask& operator=(const BackgroundTask&) = delete;
  ~BackgroundTask() { wait(); }
  void start(std::function<void()> work, std::function<void(const std::string&)> on_error);
  void wait() {
    if (thread_.joinable()) thread_.join();
  }

 private:
  std::thread thread_;
};

// The calibration file named by ~calibration (its path in *path); the pose source then refuses
// poses more than a metre off its carpet (a localization failure, not a place to train at).
// Throws std::runtime_error with the reason.
core::Calibration loadCalibrationParam(const ros::NodeHandle& pnh, PoseSource* pose_source, std::string* path);

// ~name in its real type: unchanged and true when it is not set; false with a reason naming the
// parameter and its value as given when it has another type (`white_filter: 'false'`, `zeta: abc`:
// rosparam's own getParam would fall back to the default silently). An integer is a double too.
bool readParam(const ros::NodeHandle& nh, const std::string& name, double* value, std::string* error);
bool readParam(const ros::NodeHandle& nh, const std::string& name, int* value, std::string* error);
bool readParam(const ros::NodeHandle& nh, const std::string& name, bool* value, std::string* error);
bool readParam(const ros::NodeHandle& nh, const std::string& name, std::string* value, std::string* error);

// A nodelet's records of the last `window_s` seconds of wall time, for diagnostics. R has a
// member `ros::WallTime at`.
template <class R>
class RecentWindow {
 public:
  explicit RecentWindow(double window_s) : window_s_(window_s) {}
  void add(const R& r) {
    items_.push_back(r);
    trim(r.at);
  }
  void trim(const ros::WallTime& now) {
    while (!items_.empty() && (now - items_.front().at).toSec() > window_s_) items_.pop_front();
  }
  void clear() { items_.clear(); }
  size_t size() const { return items_.size(); }
  typename std::deque<R>::const_iterator begin() const { return items_.begin(); }
  typename std::deque<R>::const_iterator end() const { return items_.end(); }
  // Records per second over the span they cover; 0 with fewer than two.
  double rateHz() const {
    if (items_.size() < 2) return 0.0;
    return (items_.size() - 1) / std::max((items_.back().at - items_.front().at).toSec(), 1e-3);
  }
  double seconds() const { return window_s_; }

 private:
  double window_s_;
  std::deque<R> items_;
};

// 100 * part / whole; 0 when whole is 0.
inline double percent(double part, double whole) { return whole > 0 ? 100.0 * part / whole : 0.0; }

// Notices a stamp going back by more than a second (a bag played again, `rosbag play -l`, a
// restarted simulation): what depends on time must then start afresh.
class TimeJumpDetector {
 public:
  static constexpr double kJumpBackS = 1.0;
  // True when `stamp` is more than kJumpBackS before the latest stamp seen (it becomes the latest).
  bool jumpedBack(const ros::Time& stamp) {
    const bool jumped = !latest_.isZero() && stamp + ros::Duration(kJumpBackS) < latest_;
    if (jumped || stamp > latest_) latest_ = stamp;
    return jumped;
  }
  void reset() { latest_ = ros::Time(); }
  const ros::Time& latest() const { return latest_; }

 private:
  ros::Time latest_;
};

}  // namespace ros_conversions
}  // namespace act_color
