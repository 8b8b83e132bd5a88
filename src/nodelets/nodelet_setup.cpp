#include "act_color/ros/nodelet_setup.hpp"

#include <algorithm>
#include <exception>
#include <initializer_list>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

namespace act_color {
namespace ros_conversions {

bool wallThrottle(const std::string& key, double period_s) {
  static std::mutex mutex;
  static std::map<std::string, double> last;
  const double now = ros::WallTime::now().toSec();
  std::lock_guard<std::mutex> lock(mutex);
  if (last.size() > 1000) last.clear();  // keys are kinds of messages; never grows without bound
  auto it = last.find(key);
  if (it != last.end() && now - it->second < period_s && now >= it->second) return false;
  last[key] = now;
  return true;
}

std::string keyOf(const std::string& message) { return message.substr(0, message.find_first_of("0123456789(")); }

std::unique_ptr<diagnostic_updater::Updater> makeDiagnostics(
    ros::NodeHandle& nh, ros::NodeHandle& pnh, const std::string& node_name, const std::string& task,
    const std::function<void(diagnostic_updater::DiagnosticStatusWrapper&)>& diagnose, ros::WallTimer* timer) {
  auto updater = std::make_unique<diagnostic_updater::Updater>(nh, pnh, node_name);
  updater->setHardwareID("act_color");
  updater->add(task, diagnose);
  diagnostic_updater::Updater* raw = updater.get();
  // force_update: Updater::update() waits for ROS time to pass its period.
  *timer = nh.createWallTimer(ros::WallDuration(1.0), [raw](const ros::WallTimerEvent&) { raw->force_update(); });
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

void BackgroundTask::start(std::function<void()> work, std::function<void(const std::string&)> on_error) {
  wait();
  thread_ = std::thread([work = std::move(work), on_error = std::move(on_error)] {
    try {
      work();
    } catch (const std::exception& e) {
      on_error(e.what());
    } catch (...) {
      on_error("unknown exception");
    }
  });
}

core::Calibration loadCalibrationParam(const ros::NodeHandle& pnh, PoseSource* pose_source, std::string* path) {
  std::string error;
  if (!readParam(pnh, "calibration", path, &error)) throw std::runtime_error(error);
  if (path->empty()) throw std::runtime_error("parameter ~calibration (path of the calibration file) is not set");
  core::Calibration calibration;
  try {
    calibration = core::loadCalibration(*path);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("bad calibration: ") + e.what());
  }
  pose_source->setFieldBounds(core::PoseBounds(calibration.field));
  return calibration;
}

namespace {

const char* typeName(XmlRpc::XmlRpcValue::Type type) {
  switch (type) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return "a boolean";
    case XmlRpc::XmlRpcValue::TypeInt:
      return "an integer";
    case XmlRpc::XmlRpcValue::TypeDouble:
      return "a number";
    case XmlRpc::XmlRpcValue::TypeString:
      return "a string";
    case XmlRpc::XmlRpcValue::TypeArray:
      return "a list";
    case XmlRpc::XmlRpcValue::TypeStruct:
      return "a dictionary";
    default:
      return "of no known type";
  }
}

bool wrongType(const std::string& name, XmlRpc::XmlRpcValue& value, const char* expected, std::string* error) {
  std::ostringstream s;
  s << "parameter ~" << name << " must be " << expected << ", is ";
  if (value.getType() == XmlRpc::XmlRpcValue::TypeString) {
    s << "'" << static_cast<std::string&>(value) << "'";
  } else {
    value.write(s);
  }
  s << " (" << typeName(value.getType()) << ")";
  *error = s.str();
  return false;
}

// ~name read as T when set (true, *value unchanged, when it is not); `accepts` says which XmlRpc
// types stand for a T.
template <class T, class Cast>
bool readTyped(const ros::NodeHandle& nh, const std::string& name,
               std::initializer_list<XmlRpc::XmlRpcValue::Type> accepts, const char* expected, Cast cast, T* value,
               std::string* error) {
  XmlRpc::XmlRpcValue v;
  if (!nh.hasParam(name) || !nh.getParam(name, v)) return true;
  if (std::find(accepts.begin(), accepts.end(), v.getType()) == accepts.end()) {
    return wrongType(name, v, expected, error);
  }
  *value = cast(v);
  return true;
}

}  // namespace

bool readParam(const ros::NodeHandle& nh, const std::string& name, double* value, std::string* error) {
  return readTyped(
      nh, name, {XmlRpc::XmlRpcValue::TypeDouble, XmlRpc::XmlRpcValue::TypeInt}, "a number",
      [](XmlRpc::XmlRpcValue& v) {
        return v.getType() == XmlRpc::XmlRpcValue::TypeInt ? static_cast<double>(static_cast<int>(v))
                                                           : static_cast<double>(v);
      },
      value, error);
}

bool readParam(const ros::NodeHandle& nh, const std::string& name, int* value, std::string* error) {
  return readTyped(
      nh, name, {XmlRpc::XmlRpcValue::TypeInt}, "an integer",
      [](XmlRpc::XmlRpcValue& v) { return static_cast<int>(v); }, value, error);
}

bool readParam(const ros::NodeHandle& nh, const std::string& name, bool* value, std::string* error) {
  return readTyped(
      nh, name, {XmlRpc::XmlRpcValue::TypeBoolean}, "true or false",
      [](XmlRpc::XmlRpcValue& v) { return static_cast<bool>(v); }, value, error);
}

bool readParam(const ros::NodeHandle& nh, const std::string& name, std::string* value, std::string* error) {
  return readTyped(
      nh, name, {XmlRpc::XmlRpcValue::TypeString}, "a string",
      [](XmlRpc::XmlRpcValue& v) { return static_cast<std::string&>(v); }, value, error);
}

}  // namespace ros_conversions
}  // namespace act_color
