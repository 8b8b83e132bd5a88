// ACT trainer nodelet: one ACT cycle (paper, section 2) per camera image with the robot's pose;
// publishes the trained color table (immutable, shared) and, when someone listens, the image
// classified with it.
#include <cv_bridge/cv_bridge.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <dynamic_reconfigure/server.h>
#include <geometry_msgs/PointStamped.h>
#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <std_msgs/UInt64MultiArray.h>

#include <boost/make_shared.hpp>
#include <chrono>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <pluginlib/class_list_macros.hpp>
#include <sstream>
#include <string>

#include "act_color/ActTrainerConfig.h"
#include "act_color/ColorLut.h"
#include "act_color/FilePath.h"
#include "act_color/core/act_trainer.hpp"
#include "act_color/core/calibration.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/ros/conversions.hpp"
#include "act_color/ros/lut_file.hpp"
#include "act_color/ros/nodelet_setup.hpp"
#include "act_color/ros/pose_source.hpp"

namespace act_color {

class ActTrainerNodelet : public nodelet::Nodelet {
 public:
  ~ActTrainerNodelet() override = default;

 private:
  void onInit() override;
  bool configure(std::string* error);
  void onImage(const sensor_msgs::ImageConstPtr& msg);
  void processImage(const sensor_msgs::ImageConstPtr& msg);
  void trainOn(const sensor_msgs::ImageConstPtr& msg, bool may_hold);
  void publishClassified(const core::ImageView& view, const std_msgs::Header& header);
  void onReconfigure(ActTrainerConfig& config, uint32_t level);
  // The file of a ~save_lut / ~load_lut request: its path or ~lut_file; false (and res filled)
  // when neither is set.
  bool requestPath(const FilePath::Request& req, FilePath::Response& res, std::string* path) const;
  bool onSaveLut(FilePath::Request& req, FilePath::Response& res);
  bool onLoadLut(FilePath::Request& req, FilePath::Response& res);
  bool loadLut(const std::string& path, std::string* message);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle nh_, pnh_;
  std::unique_ptr<image_transport::ImageTransport> it_;
  image_transport::Subscriber image_sub_;
  image_transport::Publisher classified_pub_;
  ros::Publisher lut_pub_, debug_pub_, ball_pub_;
  std::string base_frame_;
  ros::ServiceServer save_srv_, load_srv_;
  std::unique_ptr<dynamic_reconfigure::Server<ActTrainerConfig>> reconfigure_server_;
  boost::recursive_mutex reconfigure_mutex_;
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  ros::Timer diagnostics_timer_;
  ros_conversions::PoseSource pose_source_;

  // Everything below is guarded by mutex_.
  std::mutex mutex_;
  std::string config_error_;  // non-empty: the nodelet could not be configured and does nothing
  std::unique_ptr<core::ActTrainer> trainer_;
  std::unique_ptr<core::Segmenter> segmenter_;
  core::ActParams params_;
  bool params_changed_ = false;
  std::optional<core::Pose2D> initial_pose_;
  int bootstrap_cycles_ = core::kDefaultBootstrapCycles;
  bool bootstrap_at_first_pose_ = false;
  bool has_table_ = false;  // bootstrapped, loaded or trained at least once
  std::string lut_file_;
  bool debug_addresses_ = false;
  cv::Mat labels_, classified_;
  // An image whose pose had not come yet (pose and image of one instant on two connections):
  // trained when the next image comes, before it.
  sensor_msgs::ImageConstPtr held_image_;
  // Statistics for diagnostics.
  uint64_t images_ = 0, cycles_ = 0, skipped_ = 0, rejected_ = 0;
  double last_cycle_ms_ = 0.0, max_cycle_ms_ = 0.0, sum_cycle_ms_ = 0.0;
  std::string last_skip_reason_;
  std::deque<ros::WallTime> arrivals_;
  core::CycleStats last_stats_;
};

void ActTrainerNodelet::onInit() {
  nh_ = getNodeHandle();
  pnh_ = getPrivateNodeHandle();
  updater_ = ros_conversions::makeDiagnostics(
      nh_, pnh_, getName(), "ACT trainer", [this](diagnostic_updater::DiagnosticStatusWrapper& s) { diagnose(s); },
      &diagnostics_timer_);
  const std::string error = ros_conversions::runConfigure([this](std::string* e) { return configure(e); });
  if (!error.empty()) {
    NODELET_ERROR("not started: %s", error.c_str());
    std::lock_guard<std::mutex> lock(mutex_);
    config_error_ = error;
  }
}

bool ActTrainerNodelet::configure(std::string* error) {
  core::Calibration calibration;
  std::string calibration_path;
  if (!ros_conversions::loadCalibrationParam(pnh_, &calibration, &calibration_path, error)) return false;

  core::ActParams params;
  params.eta = pnh_.param("eta", params.eta);
  params.zeta = pnh_.param("zeta", params.zeta);
  params.xi = pnh_.param("xi", params.xi);
  params.sigma_min = pnh_.param("sigma_min", params.sigma_min);
  params.cluster_stride = pnh_.param("cluster_stride", params.cluster_stride);
  params.add_stride = pnh_.param("add_stride", params.add_stride);
  params.remove_stride = pnh_.param("remove_stride", params.remove_stride);
  params.lut_bits = pnh_.param("lut_bits", params.lut_bits);
  params.white_filter = pnh_.param("white_filter", params.white_filter);
  params.seed = static_cast<uint32_t>(pnh_.param("seed", static_cast<int>(params.seed)));
  // Extensions beyond the paper (README, "The algorithm, and beyond the paper").
  params.add_neighbourhood_cells = pnh_.param("add_neighbourhood_cells", params.add_neighbourhood_cells);
  params.light_compensation = pnh_.param("light_compensation", params.light_compensation);
  params.light_change_add_stride = pnh_.param("light_change_add_stride", params.light_change_add_stride);
  params.removal_protect_cycles = pnh_.param("removal_protect_cycles", params.removal_protect_cycles);
  params.robots_train_black = pnh_.param("robots_train_black", params.robots_train_black);
  params.nearest_mean = pnh_.param("nearest_mean", params.nearest_mean);
  params.evidence_removal_ratio = pnh_.param("evidence_removal_ratio", params.evidence_removal_ratio);
  params.ball_training = pnh_.param("ball_training", params.ball_training);
  params.ball_diameter_m = pnh_.param("ball_diameter_m", params.ball_diameter_m);
  // Extensions removed because the randomized scene family showed they did not help (issue 11):
  // a launch file that still sets them is told once instead of being ignored silently.
  for (const char* removed : {"seed_clusters", "robust_clusters"}) {
    if (pnh_.hasParam(removed)) NODELET_WARN("~%s is no longer a parameter (removed in issue 11); ignored", removed);
  }
  try {
    params.validate();
  } catch (const std::exception& e) {
    *error = e.what();
    return false;
  }

  std::vector<double> initial_pose;
  if (pnh_.getParam("initial_pose", initial_pose) && !initial_pose.empty()) {
    core::Pose2D p;
    if (initial_pose.size() != 3 || !(p = core::Pose2D{initial_pose[0], initial_pose[1], initial_pose[2]}).isFinite()) {
      *error = "~initial_pose must be [x_m, y_m, theta_rad] with finite values";
      return false;
    }
    initial_pose_ = p;
  }
  bootstrap_cycles_ = pnh_.param("bootstrap_cycles", core::kDefaultBootstrapCycles);
  bootstrap_at_first_pose_ = pnh_.param("bootstrap_at_first_pose", false);
  if (bootstrap_cycles_ < 1 || bootstrap_cycles_ > 1000) {
    *error = "~bootstrap_cycles must be in [1, 1000], is " + std::to_string(bootstrap_cycles_);
    return false;
  }
  lut_file_ = pnh_.param<std::string>("lut_file", "");
  debug_addresses_ = pnh_.param("debug_lut_addresses", false);
  if (!pose_source_.init(nh_, pnh_, getName(), error)) return false;

  {
    std::lock_guard<std::mutex> lock(mutex_);
    trainer_ = std::make_unique<core::ActTrainer>(calibration, params);
    segmenter_ = std::make_unique<core::Segmenter>(calibration.camera);
    params_ = params;
  }
  const std::string load_path = pnh_.param<std::string>("load_lut", "");
  if (!load_path.empty()) {
    std::string message;
    if (loadLut(load_path, &message)) {
      NODELET_INFO("%s", message.c_str());
    } else {
      NODELET_ERROR("~load_lut: %s; starting without a table", message.c_str());
    }
  }

  // The table is published as an immutable shared message: in the same manager, subscribers get
  // this very object (zero copy).
  lut_pub_ = nh_.advertise<act_color::ColorLut>("color_lut", 2);
  // The ball on the carpet (ActParams::ball_training), in base_link, only when seen.
  ball_pub_ = nh_.advertise<geometry_msgs::PointStamped>("ball", 5);
  base_frame_ = pnh_.param<std::string>("base_frame", "base_link");
  if (debug_addresses_) debug_pub_ = pnh_.advertise<std_msgs::UInt64MultiArray>("published_lut", 100);
  it_ = std::make_unique<image_transport::ImageTransport>(nh_);
  // Classified only while someone listens (checked per image); training needs every image anyway.
  classified_pub_ = it_->advertise("classified", 1);
  save_srv_ = pnh_.advertiseService("save_lut", &ActTrainerNodelet::onSaveLut, this);
  load_srv_ = pnh_.advertiseService("load_lut", &ActTrainerNodelet::onLoadLut, this);

  // Reads eta .. remove_stride from the parameter server and calls onReconfigure once.
  reconfigure_server_ = std::make_unique<dynamic_reconfigure::Server<ActTrainerConfig>>(reconfigure_mutex_, pnh_);
  reconfigure_server_->setCallback([this](ActTrainerConfig& config, uint32_t level) { onReconfigure(config, level); });

  // Training needs every image, whether or not anyone listens to the outputs.
  const image_transport::TransportHints hints("raw", ros::TransportHints(), pnh_);
  image_sub_ = it_->subscribe("image", 2, &ActTrainerNodelet::onImage, this, hints);
  NODELET_INFO("ACT trainer ready: calibration %s (%dx%d), pose from %s, start-up table: %s", calibration_path.c_str(),
               calibration.camera.width, calibration.camera.height,
               pose_source_.mode() == ros_conversions::PoseSource::Mode::kTf ? "tf" : "topic",
               has_table_                 ? "loaded"
               : initial_pose_            ? "bootstrap at ~initial_pose"
               : bootstrap_at_first_pose_ ? "bootstrap at the first localization pose"
                                          : "none (trained online)");
  return true;
}

void ActTrainerNodelet::onImage(const sensor_msgs::ImageConstPtr& msg) {
  try {
    processImage(msg);
  } catch (const std::exception& e) {
    NODELET_ERROR_THROTTLE(5.0, "image stamped %.3f: %s", msg->header.stamp.toSec(), e.what());
  }
}

void ActTrainerNodelet::processImage(const sensor_msgs::ImageConstPtr& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!trainer_) return;
  ++images_;
  arrivals_.push_back(ros::WallTime::now());
  while (arrivals_.size() > 2 && (arrivals_.back() - arrivals_.front()).toSec() > 5.0) arrivals_.pop_front();
  if (held_image_) {
    const sensor_msgs::ImageConstPtr held = held_image_;
    held_image_.reset();
    trainOn(held, false);
  }
  trainOn(msg, pose_source_.mode() == ros_conversions::PoseSource::Mode::kTopic);
}

void ActTrainerNodelet::trainOn(const sensor_msgs::ImageConstPtr& msg, bool may_hold) {
  core::ImageView view;
  std::string error;
  // A view of the shared message: no copy of the image.
  if (!ros_conversions::imageView(*msg, &view, &error)) {
    ++rejected_;
    NODELET_ERROR_THROTTLE(5.0, "image rejected: %s", error.c_str());
    return;
  }
  try {
    trainer_->checkImage(view);
  } catch (const std::invalid_argument& e) {
    ++rejected_;
    NODELET_ERROR_THROTTLE(5.0, "image rejected: %s", e.what());
    return;
  }
  if (params_changed_) {
    trainer_->setParams(params_);
    params_changed_ = false;
  }

  const auto start = std::chrono::steady_clock::now();
  bool trained = false;
  core::Pose2D pose;
  std::string why;
  const bool have_pose = pose_source_.lookup(msg->header.stamp, &pose, &why);
  if (!has_table_ && (initial_pose_ || (bootstrap_at_first_pose_ && have_pose))) {
    // The start-up table (paper, section 2): the first image at a known pose.
    const core::Pose2D start = initial_pose_ ? *initial_pose_ : pose;
    trainer_->bootstrap(view, start, bootstrap_cycles_);
    NODELET_INFO("start-up table trained with %d cycles on the image stamped %.3f at the %s pose (%.2f, %.2f, %.2f)",
                 bootstrap_cycles_, msg->header.stamp.toSec(), initial_pose_ ? "initial" : "first localization",
                 start.x_m, start.y_m, start.theta_rad);
    trained = true;
  } else if (have_pose) {
    last_stats_ = trainer_->cycle(view, pose);
    trained = true;
    if (last_stats_.ball.seen) {
      geometry_msgs::PointStamped ball;
      ball.header.stamp = msg->header.stamp;
      ball.header.frame_id = base_frame_;
      ball.point.x = last_stats_.ball.x_m;
      ball.point.y = last_stats_.ball.y_m;
      ball.point.z = 0.0;  // where it rests on the carpet
      ball_pub_.publish(ball);
    }
  } else if (may_hold) {
    NODELET_WARN_THROTTLE(5.0, "image stamped %.3f: %s; waiting for the next image", msg->header.stamp.toSec(),
                          why.c_str());
    held_image_ = msg;
    return;
  } else {
    ++skipped_;
    last_skip_reason_ = why;
    NODELET_WARN_THROTTLE(5.0, "no training on the image stamped %.3f: %s", msg->header.stamp.toSec(), why.c_str());
  }
  if (trained) {
    has_table_ = true;
    ++cycles_;
    last_cycle_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    sum_cycle_ms_ += last_cycle_ms_;
    max_cycle_ms_ = std::max(max_cycle_ms_, last_cycle_ms_);
  }
  // One table per usable image, stamped with it: "the table trained on frames up to and
  // including t", also when this frame could not train (the segmentation then need not wait).
  if (!has_table_ || trainer_->lut().colorSpace() != core::nativeColorSpace(view.format)) return;
  boost::shared_ptr<const act_color::ColorLut> lut = ros_conversions::toMsg(*trainer_, msg->header);
  lut_pub_.publish(lut);
  if (debug_addresses_) {
    std_msgs::UInt64MultiArray debug;
    debug.data = {msg->header.stamp.toNSec(), reinterpret_cast<uint64_t>(lut.get()), lut->revision};
    debug_pub_.publish(debug);
  }
  if (classified_pub_.getNumSubscribers() > 0) publishClassified(view, msg->header);
}

void ActTrainerNodelet::publishClassified(const core::ImageView& view, const std_msgs::Header& header) {
  segmenter_->classify(trainer_->lut(), view, labels_);
  cv_bridge::CvImage out(header, "rgb8");
  core::colorizeLabels(labels_, out.image);
  classified_pub_.publish(out.toImageMsg());
}

void ActTrainerNodelet::onReconfigure(ActTrainerConfig& config, uint32_t /*level*/) {
  std::lock_guard<std::mutex> lock(mutex_);
  core::ActParams p = params_;
  p.eta = config.eta;
  p.zeta = config.zeta;
  p.xi = config.xi;
  p.sigma_min = config.sigma_min;
  p.cluster_stride = config.cluster_stride;
  p.add_stride = config.add_stride;
  p.remove_stride = config.remove_stride;
  try {
    p.validate();
  } catch (const std::exception& e) {
    NODELET_ERROR_THROTTLE(1.0, "dynamic_reconfigure: %s; not applied, keeping the previous values", e.what());
    // Show what is in effect.
    config.eta = params_.eta;
    config.zeta = params_.zeta;
    config.xi = params_.xi;
    config.sigma_min = params_.sigma_min;
    config.cluster_stride = params_.cluster_stride;
    config.add_stride = params_.add_stride;
    config.remove_stride = params_.remove_stride;
    return;
  }
  params_ = p;
  params_changed_ = true;  // applied by the next image, in the image callback
}

bool ActTrainerNodelet::loadLut(const std::string& path, std::string* message) {
  act_color::ColorLut msg;
  core::ColorLut lut;
  if (!ros_conversions::loadLutFile(path, &msg, message)) return false;
  if (!ros_conversions::fromMsg(msg, &lut, message)) {
    *message = path + ": " + *message;
    return false;
  }
  std::lock_guard<std::mutex> lock(mutex_);
  if (!trainer_) {
    *message = "the nodelet is not configured: " + config_error_;
    return false;
  }
  try {
    trainer_->loadTable(lut);
  } catch (const std::exception& e) {
    *message = path + ": " + e.what();
    return false;
  }
  has_table_ = true;
  *message = "loaded the color table of " + path + " (revision " + std::to_string(msg.revision) + ")";
  return true;
}

bool ActTrainerNodelet::requestPath(const FilePath::Request& req, FilePath::Response& res, std::string* path) const {
  *path = req.path.empty() ? lut_file_ : req.path;
  if (!path->empty()) return true;
  res.success = false;
  res.message = "no path given and ~lut_file is not set";
  return false;
}

bool ActTrainerNodelet::onSaveLut(FilePath::Request& req, FilePath::Response& res) {
  std::string path;
  if (!requestPath(req, res, &path)) return true;
  act_color::ColorLutPtr msg;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!trainer_ || !has_table_) {
      res.success = false;
      res.message = trainer_ ? "no table trained yet" : "the nodelet is not configured: " + config_error_;
      return true;
    }
    std_msgs::Header header;
    header.stamp = ros::Time::now();
    msg = ros_conversions::toMsg(*trainer_, header);
  }
  std::string error;
  res.success = ros_conversions::saveLutFile(*msg, path, &error);
  res.message =
      res.success ? "saved the color table (revision " + std::to_string(msg->revision) + ") to " + path : error;
  if (!res.success) NODELET_ERROR("~save_lut: %s", error.c_str());
  return true;
}

bool ActTrainerNodelet::onLoadLut(FilePath::Request& req, FilePath::Response& res) {
  std::string path;
  if (!requestPath(req, res, &path)) return true;
  res.success = loadLut(path, &res.message);
  if (!res.success) NODELET_ERROR("~load_lut: %s", res.message.c_str());
  return true;
}

void ActTrainerNodelet::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!config_error_.empty() || !trainer_) {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "not configured: " + config_error_);
    return;
  }
  double rate = 0.0;
  if (arrivals_.size() >= 2) {
    const double span = (arrivals_.back() - arrivals_.front()).toSec();
    if (span > 0) rate = (arrivals_.size() - 1) / span;
    if ((ros::WallTime::now() - arrivals_.back()).toSec() > 2.0) rate = 0.0;
  }
  if (images_ == 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no image received yet");
  } else if (rate == 0.0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no image for more than 2 s");
  } else if (!last_skip_reason_.empty() && skipped_ > 0 && cycles_ == 0) {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "not training: " + last_skip_reason_);
  } else {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "training");
  }
  status.add("input rate (Hz)", rate);
  status.add("images", images_);
  status.add("cycles", cycles_);
  status.add("images without training (no pose)", skipped_);
  status.add("images rejected", rejected_);
  status.add("last skip reason", last_skip_reason_);
  status.add("poses rejected", pose_source_.rejected());
  status.add("cycle time last (ms)", last_cycle_ms_);
  status.add("cycle time mean (ms)", cycles_ ? sum_cycle_ms_ / cycles_ : 0.0);
  status.add("cycle time max (ms)", max_cycle_ms_);
  status.add("table revision", trainer_->revision());
  const auto counts = trainer_->lut().cellCounts();
  uint64_t filled = 0;
  for (int k = 1; k < core::kNumClasses; ++k) filled += counts[k];
  status.add("table fill (%)", 100.0 * filled / trainer_->lut().size());
  for (int k = 1; k < core::kNumClasses; ++k) {
    const core::ClassCluster& c = trainer_->clusters()[k];
    std::ostringstream s;
    s.precision(1);
    s << std::fixed << "mean (" << c.mean()[0] << ", " << c.mean()[1] << ", " << c.mean()[2] << ") sigma " << c.sigma()
      << ", " << c.lastSampleCount() << " samples, " << counts[k] << " cells";
    status.add(std::string("cluster ") + core::className(k), s.str());
  }
}

}  // namespace act_color

PLUGINLIB_EXPORT_CLASS(act_color::ActTrainerNodelet, nodelet::Nodelet)
