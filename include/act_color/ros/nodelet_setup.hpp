#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include <functional>
#include <memory>
#include <string>

#include "act_color/core/calibration.hpp"

namespace act_color {
namespace ros_conversions {

// A nodelet's diagnostics: an updater (hardware id "act_color") with one task, updated every
// second by *timer.
std::unique_ptr<diagnostic_updater::Updater> makeDiagnostics(
    ros::NodeHandle& nh, ros::NodeHandle& pnh, const std::string& node_name, const std::string& task,
    const std::function<void(diagnostic_updater::DiagnosticStatusWrapper&)>& diagnose, ros::Timer* timer);

// Runs a nodelet's configuration step; an exception is an error too. Empty when it succeeded,
// else the reason. A nodelet that fails stays loaded and harmless: one that throws or exits takes
// its whole manager with it.
std::string runConfigure(const std::function<bool(std::string*)>& configure);

// The calibration file named by ~calibration (its path in *path). False with the reason.
bool loadCalibrationParam(const ros::NodeHandle& pnh, core::Calibration* calibration, std::string* path,
                          std::string* error);

}  // namespace ros_conversions
}  // namespace act_color
