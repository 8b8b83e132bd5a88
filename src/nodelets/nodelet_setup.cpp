#include "act_color/ros/nodelet_setup.hpp"

#include <exception>

namespace act_color {
namespace ros_conversions {

std::unique_ptr<diagnostic_updater::Updater> makeDiagnostics(
    ros::NodeHandle& nh, ros::NodeHandle& pnh, const std::string& node_name, const std::string& task,
    const std::function<void(diagnostic_updater::DiagnosticStatusWrapper&)>& diagnose, ros::Timer* timer) {
  auto updater = std::make_unique<diagnostic_updater::Updater>(nh, pnh, node_name);
  updater->setHardwareID("act_color");
  updater->add(task, diagnose);
  diagnostic_updater::Updater* raw = updater.get();
  *timer = nh.createTimer(ros::Duration(1.0), [raw](const ros::TimerEvent&) { raw->update(); });
  return updater;
}

std::string runConfigure(const std::function<bool(std::string*)>& configure) {
  std::string error;
  try {
    if (configure(&error)) return "";
  } catch (const std::exception& e) {
    error = e.what();
  }
  return error.empty() ? "configuration failed" : error;
}

bool loadCalibrationParam(const ros::NodeHandle& pnh, core::Calibration* calibration, std::string* path,
                          std::string* error) {
  *path = pnh.param<std::string>("calibration", "");
  if (path->empty()) {
    *error = "parameter ~calibration (path of the calibration file) is not set";
    return false;
  }
  try {
    *calibration = core::loadCalibration(*path);
  } catch (const std::exception& e) {
    *error = std::string("bad calibration: ") + e.what();
    return false;
  }
  return true;
}

}  // namespace ros_conversions
}  // namespace act_color
