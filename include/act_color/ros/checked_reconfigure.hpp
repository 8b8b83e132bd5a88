#pragma once

#include <dynamic_reconfigure/Config.h>
#include <dynamic_reconfigure/ConfigDescription.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <ros/ros.h>

#include <functional>
#include <mutex>
#include <string>
#include <utility>

namespace act_color {
namespace ros_conversions {

// A dynamic_reconfigure server (the same topics and service as dynamic_reconfigure::Server, so
// rqt_reconfigure and `dynparam` work) that hands the values to `apply` as they were typed:
// dynamic_reconfigure::Server clamps them to the .cfg's ranges first, so a value out of range
// would be applied as the nearest bound without a word. Here `apply` validates the values in their
// real type and range and refuses them with a reason; the values in effect stay and are what the
// client is answered and what parameter_updates shows.
template <class Config>
class CheckedReconfigure {
 public:
  // True: applied. False: refused, *error says why (named parameter, value as typed).
  using Apply = std::function<bool(const Config& requested, std::string* error)>;
  using Refused = std::function<void(const std::string& error)>;

  // `in_effect`: the values the node runs with (validated at start-up); published at once.
  CheckedReconfigure(const ros::NodeHandle& nh, const Config& in_effect, Apply apply, Refused refused)
      : nh_(nh), config_(in_effect), apply_(std::move(apply)), refused_(std::move(refused)) {
    descriptions_pub_ = nh_.advertise<dynamic_reconfigure::ConfigDescription>("parameter_descriptions", 1, true);
    descriptions_pub_.publish(Config::__getDescriptionMessage__());
    updates_pub_ = nh_.advertise<dynamic_reconfigure::Config>("parameter_updates", 1, true);
    publishInEffect();
    service_ = nh_.advertiseService("set_parameters", &CheckedReconfigure::onSet, this);
  }

  Config inEffect() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return config_;
  }

 private:
  bool onSet(dynamic_reconfigure::Reconfigure::Request& req, dynamic_reconfigure::Reconfigure::Response& res) {
    std::lock_guard<std::mutex> lock(mutex_);
    Config requested = config_;
    requested.__fromMessage__(req.config);  // not clamped
    std::string error;
    bool applied = false;
    try {
      applied = apply_(requested, &error);
    } catch (const std::exception& e) {
      error = e.what();
    }
    if (applied) {
      config_ = requested;
    } else {
      refused_(error.empty() ? std::string("refused") : error);
    }
    config_.__toMessage__(res.config);
    publishInEffect();
    return true;
  }

  void publishInEffect() {
    config_.__toServer__(nh_);
    dynamic_reconfigure::Config msg;
    config_.__toMessage__(msg);
    updates_pub_.publish(msg);
  }

  ros::NodeHandle nh_;
  mutable std::mutex mutex_;
  Config config_;
  Apply apply_;
  Refused refused_;
  ros::Publisher descriptions_pub_, updates_pub_;
  ros::ServiceServer service_;
};

}  // namespace ros_conversions
}  // namespace act_color
