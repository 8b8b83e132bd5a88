// ACT trainer nodelet: one ACT cycle (paper, section 2) per camera image with the robot's pose;
// publishes the trained color table (immutable, shared) and, when someone listens, the image
// classified with it.
#include <cv_bridge/cv_bridge.h>
#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PointStamped.h>
#include <geometry_msgs/PoseStamped.h>
#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <std_msgs/UInt64MultiArray.h>
#include <visualization_msgs/MarkerArray.h>

#include <boost/make_shared.hpp>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <pluginlib/class_list_macros.hpp>
#include <sstream>
#include <string>
#include <thread>

#include "act_color/ActTrainerConfig.h"
#include "act_color/ColorLut.h"
#include "act_color/FilePath.h"
#include "act_color/core/act_trainer.hpp"
#include "act_color/core/calibration.hpp"
#include "act_color/core/lut_image.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/ros/checked_reconfigure.hpp"
#include "act_color/ros/conversions.hpp"
#include "act_color/ros/lut_file.hpp"
#include "act_color/ros/nodelet_setup.hpp"
#include "act_color/ros/pose_source.hpp"
#include "act_color/ros/self_mask_worker.hpp"

namespace act_color {

class ActTrainerNodelet : public nodelet::Nodelet {
 public:
  ~ActTrainerNodelet() override;

 private:
  // What became of an image (diagnostics).
  // kContradicted: the cycle ran, but the table contradicted the pose and nothing was trained
  // (ActParams::pose_check).
  enum class Outcome { kTrained, kStartup, kNoPose, kRejected, kContradicted };
  struct Pending {
    sensor_msgs::ImageConstPtr image;
    ros::WallTime arrival;
  };
  struct Record {
    ros::WallTime at;
    Outcome outcome;
    double cycle_ms;    // the ACT cycle (or the start-up training), 0 when not trained
    double latency_ms;  // image stamp to its table's publication (ROS time), -1 when none
  };

  void onInit() override;
  // The parameters, topics, services and timers, on the manager's load path (fast); the
  // calibration and what is built from it follow in loadCalibration, on loader_'s thread.
  bool configure(std::string* error);
  void loadCalibration(const core::ActParams& params, const std::string& load_path);
  // Why there is no trainer: the calibration is still loading, or the reason it failed.
  std::string notReady() const;
  // The nodelet could not be configured: it stays loaded and does nothing, saying why.
  void notStarted(const std::string& error);
  bool readParams(core::ActParams* params, std::string* error);
  void onImage(const sensor_msgs::ImageConstPtr& msg);
  // Trains the waiting images in order, as far as their poses have come (or waited ~tf_timeout).
  void drain();
  // False: the image waits for its pose (may_wait and the pose may still come).
  bool trainOn(const sensor_msgs::ImageConstPtr& msg, bool may_wait);
  // ~learn_self_mask: the mask the worker learned, once it is new, used from this image on (the
  // trainer's camera model, /act/classified) and published (latched) for the segmentation.
  void useLearnedSelfMask(const std_msgs::Header& header);
  // `trained`: this image's cycle, when it trained (its ball is labelled in /act/classified).
  void publishOutputs(const core::ImageView& view, const sensor_msgs::ImageConstPtr& msg, bool have_pose,
                      const core::Pose2D& pose, const core::CycleStats* trained);
  void onTimeJump(const ros::Time& from, const ros::Time& to);
  // The table as slices of its color cube (core::renderLutSlices), when someone listens.
  void publishTableImage();
  // The field model in rviz's 3-D view: line markings, carpet, goals (field frame, latched).
  void publishFieldMarkers(const core::FieldModel& field);
  void record(Outcome outcome, double cycle_ms, double latency_ms);
  bool applyConfig(const ActTrainerConfig& config, std::string* error);
  ActTrainerConfig configInEffect() const;
  // The file of a ~save_lut / ~load_lut request: its path or ~lut_file; false (and res filled)
  // when neither is set.
  bool requestPath(const FilePath::Request& req, FilePath::Response& res, std::string* path) const;
  bool onSaveLut(FilePath::Request& req, FilePath::Response& res);
  bool onLoadLut(FilePath::Request& req, FilePath::Response& res);
  // ~save_self_mask: the own robot's pixels learned so far (~learn_self_mask) as a PNG inside
  // ~lut_dir, for the calibration's camera.self_mask.
  bool onSaveSelfMask(FilePath::Request& req, FilePath::Response& res);
  // A table file: saveLut = prepareSave (the table and ~lut_dir, under the lock) + writeTable (the
  // file inside ~lut_dir and its I/O: every file system call); loadLut = loadPath + readTable (the
  // file I/O alone) + installTable (under the lock). The services run the I/O parts with a timeout.
  struct LoadedTable {
    act_color::ColorLut msg;
    core::ColorLut lut;
    std::vector<core::ActTrainer::SavedCluster> clusters;
  };
  bool saveLut(const std::string& path, std::string* message);
  bool prepareSave(act_color::ColorLutPtr* msg, std::string* lut_dir, std::string* message) const;
  static bool writeTable(const act_color::ColorLut& msg, const std::string& lut_dir, const std::string& requested,
                         std::string* message);
  bool loadLut(const std::string& path, std::string* message);
  std::string loadPath(const std::string& requested) const;
  static bool readTable(const std::string& path, LoadedTable* table, std::string* message);
  bool installTable(const std::string& path, const LoadedTable& table, std::string* message);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle nh_, pnh_;
  std::unique_ptr<image_transport::ImageTransport> it_;
  image_transport::Subscriber image_sub_;
  image_transport::Publisher classified_pub_, expected_pub_;
  ros::Publisher lut_pub_, lut_throttled_pub_, debug_pub_, ball_pub_, pose_pub_, table_image_pub_, field_pub_,
      self_mask_pub_;
  std::string base_frame_, field_frame_;
  // The services' file I/O runs on a queue and thread of its own: a slow or stuck file system never
  // holds up training (the image callbacks' queue). The queue is declared before the servers on
  // it: a server removes its callbacks from the queue when it goes (unloading the nodelet crashed
  // the manager when the queue went first).
  ros::CallbackQueue io_queue_;
  std::unique_ptr<ros::AsyncSpinner> io_spinner_;
  ros::ServiceServer save_srv_, load_srv_, save_self_mask_srv_;
  std::unique_ptr<ros_conversions::CheckedReconfigure<ActTrainerConfig>> reconfigure_;
  std::unique_ptr<diagnostic_updater::Updater> updater_;
  ros::WallTimer diagnostics_timer_, drain_timer_, table_image_timer_;
  ros_conversions::PoseSource pose_source_;

  // Everything below is guarded by mutex_.
  mutable std::mutex mutex_;
  std::string config_error_;  // non-empty: the nodelet could not be configured and does nothing
  // No trainer yet and no error: the calibration is being loaded (trainer_ follows).
  bool loading() const { return !trainer_ && config_error_.empty(); }
  std::unique_ptr<core::ActTrainer> trainer_;
  std::unique_ptr<core::Segmenter> segmenter_;
  core::ActParams params_;
  bool params_changed_ = false;
  std::optional<core::Pose2D> initial_pose_;
  int bootstrap_cycles_ = core::kDefaultBootstrapCycles;
  bool bootstrap_at_first_pose_ = false;
  bool has_table_ = false;  // bootstrapped, loaded or trained at least once
  std::string lut_file_;
  std::string lut_dir_;                             // saves only inside it
  std::optional<core::PixelFormat> camera_format_;  // of the last usable image
  bool save_on_shutdown_ = false;
  bool learn_self_mask_ = false;
  // ~learn_self_mask: made with the trainer (loadCalibration), fed by trainOn.
  std::shared_ptr<ros_conversions::SelfMaskWorker> self_mask_;
  int self_masks_used_ = 0;      // masks the worker handed over (useLearnedSelfMask)
  size_t self_mask_pixels_ = 0;  // in the one in use
  int self_mask_poses_ = 0;      // the distinct poses it was learned from
  bool reset_on_time_jump_ = false;
  bool debug_addresses_ = false;
  double max_pose_age_s_ = 1.0;
  double tf_timeout_s_ = 0.1;
  int publish_lut_every_ = 1;
  double lut_throttled_period_s_ = 1.0;
  ros::WallTime last_throttled_;
  uint64_t publishable_ = 0;  // images whose table could be published
  uint64_t table_image_revision_ = 0;
  std::string table_image_frame_;
  cv::Mat labels_, classified_, expected_;
  // Images waiting for their pose (pose and image of one instant come on two connections), in
  // order; at most kMaxPending.
  static constexpr size_t kMaxPending = 30;
  std::deque<Pending> pending_;
  ros_conversions::TimeJumpDetector image_time_;
  // Statistics for diagnostics: totals since the start (or the last time jump) ...
  uint64_t images_ = 0, cycles_ = 0, skipped_ = 0, rejected_ = 0, contradicted_ = 0, time_jumps_ = 0;
  double startup_ms_ = 0.0;
  std::string last_skip_reason_, last_reject_reason_;
  core::CycleStats last_stats_;
  // ... and the last seconds.
  static constexpr double kWindowS = 5.0;
  static constexpr double kFillWindowS = 30.0;
  ros_conversions::RecentWindow<Record> window_{kWindowS};
  std::deque<std::pair<ros::WallTime, uint64_t>> fill_history_;  // filled cells, once per diagnostics
  ros::WallTime last_image_;
  ros_conversions::BackgroundTask loader_;
};

ActTrainerNodelet::~ActTrainerNodelet() {
  // A calibration still loading finishes first (its size is bounded, see core::loadCalibration).
  loader_.wait();
  // No service call may run into a half-destroyed nodelet.
  if (io_spinner_) io_spinner_->stop();
  save_srv_.shutdown();
  load_srv_.shutdown();
  save_self_mask_srv_.shutdown();
  // ~save_on_shutdown: the table of this run survives the robot's restart. Never throws.
  try {
    std::string path, message;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!save_on_shutdown_ || !has_table_ || !trainer_) return;
      path = lut_file_;
    }
    if (saveLut(path, &message)) {
      NODELET_INFO("at shutdown: %s", message.c_str());
    } else {
      NODELET_ERROR("at shutdown: ~save_on_shutdown: %s", message.c_str());
    }
  } catch (const std::exception& e) {
    NODELET_ERROR("at shutdown: the table was not saved: %s", e.what());
  }
}

void ActTrainerNodelet::onInit() {
  nh_ = getNodeHandle();
  pnh_ = getPrivateNodeHandle();
  updater_ = ros_conversions::makeDiagnostics(
      nh_, pnh_, getName(), "ACT trainer", [this](diagnostic_updater::DiagnosticStatusWrapper& s) { diagnose(s); },
      &diagnostics_timer_);
  const std::string error = ros_conversions::runConfigure([this](std::string* e) { return configure(e); });
  if (!error.empty()) notStarted(error);
}

void ActTrainerNodelet::notStarted(const std::string& error) {
  NODELET_ERROR("not started: %s", error.c_str());
  std::lock_guard<std::mutex> lock(mutex_);
  config_error_ = error;
}

bool ActTrainerNodelet::readParams(core::ActParams* params, std::string* error) {
  using ros_conversions::readParam;
  core::ActParams& p = *params;
  int seed = static_cast<int>(p.seed);
  const bool read = readParam(pnh_, "eta", &p.eta, error) && readParam(pnh_, "zeta", &p.zeta, error) &&
                    readParam(pnh_, "xi", &p.xi, error) && readParam(pnh_, "sigma_min", &p.sigma_min, error) &&
                    readParam(pnh_, "cluster_stride", &p.cluster_stride, error) &&
                    readParam(pnh_, "add_stride", &p.add_stride, error) &&
                    readParam(pnh_, "remove_stride", &p.remove_stride, error) &&
                    readParam(pnh_, "lut_bits", &p.lut_bits, error) &&
                    readParam(pnh_, "white_filter", &p.white_filter, error) && readParam(pnh_, "seed", &seed, error) &&
                    // Extensions beyond the paper (README, "The algorithm, and beyond the paper").
                    readParam(pnh_, "add_neighbourhood_cells", &p.add_neighbourhood_cells, error) &&
                    readParam(pnh_, "light_compensation", &p.light_compensation, error) &&
                    readParam(pnh_, "light_change_add_stride", &p.light_change_add_stride, error) &&
                    readParam(pnh_, "removal_protect_cycles", &p.removal_protect_cycles, error) &&
                    readParam(pnh_, "robot_height_m", &p.robot_height_m, error) &&
                    readParam(pnh_, "robots_train_black", &p.robots_train_black, error) &&
                    readParam(pnh_, "nearest_mean", &p.nearest_mean, error) &&
                    readParam(pnh_, "evidence_removal_ratio", &p.evidence_removal_ratio, error) &&
                    readParam(pnh_, "learned_boundary", &p.learned_boundary, error) &&
                    readParam(pnh_, "lattice_sampling", &p.lattice_sampling, error) &&
                    readParam(pnh_, "pose_check", &p.pose_check, error) &&
                    readParam(pnh_, "ball_training", &p.ball_training, error) &&
                    readParam(pnh_, "ball_diameter_m", &p.ball_diameter_m, error) &&
                    readParam(pnh_, "carpet_edge", &p.carpet_edge, error);
  if (!read) return false;
  if (seed < 0) {
    *error = "parameter ~seed must be >= 0, is " + std::to_string(seed);
    return false;
  }
  p.seed = static_cast<uint32_t>(seed);
  try {
    p.validate();
  } catch (const std::exception& e) {
    *error = e.what();
    return false;
  }
  return true;
}

bool ActTrainerNodelet::configure(std::string* error) {
  using ros_conversions::readParam;
  core::ActParams params;
  if (!readParams(&params, error)) return false;
  // Extensions removed because the randomized scene family showed they did not help (issue 11):
  // a launch file that still sets them is told once instead of being ignored silently.
  for (const char* removed : {"seed_clusters", "robust_clusters"}) {
    if (pnh_.hasParam(removed)) NODELET_WARN("~%s is no longer a parameter (removed in issue 11); ignored", removed);
  }

  std::vector<double> initial_pose;
  if (pnh_.hasParam("initial_pose") && !pnh_.getParam("initial_pose", initial_pose)) {
    *error = "~initial_pose must be a list [x_m, y_m, theta_rad] of numbers, or [] for none";
    return false;
  }
  if (!initial_pose.empty()) {
    core::Pose2D p;
    if (initial_pose.size() != 3 || !(p = core::Pose2D{initial_pose[0], initial_pose[1], initial_pose[2]}).isFinite()) {
      *error = "~initial_pose must be [x_m, y_m, theta_rad] with finite values";
      return false;
    }
    initial_pose_ = p;
  }
  int bootstrap_cycles = core::kDefaultBootstrapCycles;
  bool bootstrap_at_first_pose = false, save_on_shutdown = false, reset_on_time_jump = false, debug = false,
       learn_self_mask = false;
  double tf_timeout = tf_timeout_s_, throttled_period = lut_throttled_period_s_, max_pose_age = max_pose_age_s_;
  int publish_every = publish_lut_every_;
  std::string lut_file, load_path, lut_dir, base_frame = "base_link", field_frame = "field";
  if (!readParam(pnh_, "bootstrap_cycles", &bootstrap_cycles, error) ||
      !readParam(pnh_, "bootstrap_at_first_pose", &bootstrap_at_first_pose, error) ||
      !readParam(pnh_, "lut_file", &lut_file, error) || !readParam(pnh_, "load_lut", &load_path, error) ||
      !readParam(pnh_, "lut_dir", &lut_dir, error) || !readParam(pnh_, "save_on_shutdown", &save_on_shutdown, error) ||
      !readParam(pnh_, "learn_self_mask", &learn_self_mask, error) ||
      !readParam(pnh_, "reset_on_time_jump", &reset_on_time_jump, error) ||
      !readParam(pnh_, "tf_timeout", &tf_timeout, error) || !readParam(pnh_, "max_pose_age", &max_pose_age, error) ||
      !readParam(pnh_, "publish_lut_every", &publish_every, error) ||
      !readParam(pnh_, "lut_throttled_period", &throttled_period, error) ||
      !readParam(pnh_, "debug_lut_addresses", &debug, error) || !readParam(pnh_, "base_frame", &base_frame, error) ||
      !readParam(pnh_, "field_frame", &field_frame, error)) {
    return false;
  }
  ActTrainerConfig node_config;
  node_config.tf_timeout = tf_timeout;
  node_config.max_pose_age = max_pose_age;
  node_config.publish_lut_every = publish_every;
  node_config.lut_throttled_period = throttled_period;
  if (bootstrap_cycles < 1 || bootstrap_cycles > 1000) {
    *error = "parameter ~bootstrap_cycles must be in [1, 1000], is " + std::to_string(bootstrap_cycles);
    return false;
  }
  if (lut_dir.empty()) {
    // $ROS_HOME/act_color, as ROS puts its own files.
    const char* ros_home = std::getenv("ROS_HOME");
    const char* home = std::getenv("HOME");
    lut_dir = ros_home ? std::string(ros_home) + "/act_color" : std::string(home ? home : "/tmp") + "/.ros/act_color";
  }
  if (save_on_shutdown && lut_file.empty()) {
    *error = "~save_on_shutdown needs ~lut_file (the file to save to)";
    return false;
  }
  if (!pose_source_.init(nh_, pnh_, getName(), error)) return false;

  {
    std::lock_guard<std::mutex> lock(mutex_);
    params_ = params;
    bootstrap_cycles_ = bootstrap_cycles;
    bootstrap_at_first_pose_ = bootstrap_at_first_pose;
    lut_file_ = lut_file;
    lut_dir_ = lut_dir;
    save_on_shutdown_ = save_on_shutdown;
    learn_self_mask_ = learn_self_mask;
    reset_on_time_jump_ = reset_on_time_jump;
    debug_addresses_ = debug;
    base_frame_ = base_frame;
    field_frame_ = field_frame;
  }
  // The node's own run-time parameters, checked as dynamic_reconfigure would check them.
  {
    ActTrainerConfig c = configInEffect();
    c.tf_timeout = node_config.tf_timeout;
    c.max_pose_age = node_config.max_pose_age;
    c.publish_lut_every = node_config.publish_lut_every;
    c.lut_throttled_period = node_config.lut_throttled_period;
    if (!applyConfig(c, error)) return false;
  }

  // The table is published as an immutable shared message: in the same manager, subscribers get
  // this very object (zero copy).
  lut_pub_ = nh_.advertise<act_color::ColorLut>("color_lut", 2);
  // The same tables, at most one per ~lut_throttled_period: for rviz, rosbag record and anything
  // off-process, which would otherwise carry the whole table with every image.
  lut_throttled_pub_ = nh_.advertise<act_color::ColorLut>("color_lut_throttled", 1, true);
  // The ball on the carpet (ActParams::ball_training), in base_link, only when seen.
  ball_pub_ = nh_.advertise<geometry_msgs::PointStamped>("ball", 5);
  // The pose each frame was trained with, for rviz's 3-D view (field frame).
  pose_pub_ = nh_.advertise<geometry_msgs::PoseStamped>("trained_pose", 2);
  if (debug_addresses_) debug_pub_ = pnh_.advertise<std_msgs::UInt64MultiArray>("published_lut", 100);
  it_ = std::make_unique<image_transport::ImageTransport>(nh_);
  // Classified only while someone listens (checked per image); training needs every image anyway.
  classified_pub_ = it_->advertise("classified", 1);
  // The camera image with the classes the field model expects at the pose (what ACT trains with).
  expected_pub_ = it_->advertise("expected", 1);
  // For people: the table as slices of its color cube (latched, at most once a second) and the
  // field model in the 3-D view.
  table_image_pub_ = nh_.advertise<sensor_msgs::Image>("table_image", 1, true);
  // ~learn_self_mask: the own robot's pixels in use (mono8, 255 = own robot), for the segmentation.
  self_mask_pub_ = nh_.advertise<sensor_msgs::Image>("self_mask", 1, true);
  table_image_timer_ = nh_.createWallTimer(ros::WallDuration(1.0), [this](const ros::WallTimerEvent&) {
    try {
      publishTableImage();
    } catch (const std::exception& e) {
      ACT_WALL_THROTTLE(5.0, NODELET_ERROR("table image: %s", e.what()));
    }
  });
  field_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("field_markers", 1, true);
  {
    ros::NodeHandle io(pnh_);
    io.setCallbackQueue(&io_queue_);
    save_srv_ = io.advertiseService("save_lut", &ActTrainerNodelet::onSaveLut, this);
    load_srv_ = io.advertiseService("load_lut", &ActTrainerNodelet::onLoadLut, this);
    save_self_mask_srv_ = io.advertiseService("save_self_mask", &ActTrainerNodelet::onSaveSelfMask, this);
    io_spinner_ = std::make_unique<ros::AsyncSpinner>(1, &io_queue_);
    io_spinner_->start();
  }
  reconfigure_ = std::make_unique<ros_conversions::CheckedReconfigure<ActTrainerConfig>>(
      pnh_, configInEffect(), [this](const ActTrainerConfig& c, std::string* e) { return applyConfig(c, e); },
      [this](const std::string& e) {
        ACT_WALL_THROTTLE(0.2,
                          NODELET_ERROR("dynamic_reconfigure: %s; not applied, the previous values stay", e.c_str()));
      });
  // Images whose pose had not come yet are tried again as tf or the pose arrives.
  drain_timer_ = nh_.createWallTimer(ros::WallDuration(0.01), [this](const ros::WallTimerEvent&) {
    try {
      std::lock_guard<std::mutex> lock(mutex_);
      drain();
    } catch (const std::exception& e) {
      ACT_WALL_THROTTLE(5.0, NODELET_ERROR("%s", e.what()));
    }
  });

  // Training needs every image, whether or not anyone listens to the outputs.
  const image_transport::TransportHints hints("raw", ros::TransportHints(), pnh_);
  // A few frames of slack (as the segmentation): a slow cycle, or a busy machine replaying a bag,
  // does not drop frames at once.
  image_sub_ = it_->subscribe("image", 5, &ActTrainerNodelet::onImage, this, hints);
  loader_.start([this, params, load_path] { loadCalibration(params, load_path); },
                [this](const std::string& e) { notStarted(e); });
  return true;
}

void ActTrainerNodelet::loadCalibration(const core::ActParams& params, const std::string& load_path) {
  std::string calibration_path;
  const core::Calibration calibration = ros_conversions::loadCalibrationParam(pnh_, &pose_source_, &calibration_path);
  std::string off_field;
  if (initial_pose_ && !pose_source_.plausible(*initial_pose_, &off_field)) {
    throw std::runtime_error("~initial_pose: " + off_field);
  }
  // The camera model of every pixel: the part that grows with the image.
  auto trainer = std::make_unique<core::ActTrainer>(calibration, params);
  auto segmenter = std::make_unique<core::Segmenter>(calibration.camera);
  bool learn_self_mask = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    learn_self_mask = learn_self_mask_;
  }
  auto self_mask = learn_self_mask ? std::make_shared<ros_conversions::SelfMaskWorker>(calibration) : nullptr;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    trainer_ = std::move(trainer);
    segmenter_ = std::move(segmenter);
    self_mask_ = std::move(self_mask);
    params_changed_ = true;  // ~dynamic_reconfigure may have changed them while loading
  }
  if (!load_path.empty()) {
    std::string message;
    if (loadLut(load_path, &message)) {
      NODELET_INFO("%s", message.c_str());
    } else {
      NODELET_ERROR("~load_lut: %s; starting without a table", message.c_str());
    }
  }
  publishFieldMarkers(core::FieldModel(calibration.field));
  bool has_table = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    has_table = has_table_;
  }
  NODELET_INFO(
      "ACT trainer ready: calibration %s (%dx%d), pose from %s, start-up table: %s%s", calibration_path.c_str(),
      calibration.camera.width, calibration.camera.height,
      pose_source_.mode() == ros_conversions::PoseSource::Mode::kTf ? "tf" : "topic",
      has_table                  ? "loaded"
      : initial_pose_            ? "bootstrap at ~initial_pose"
      : bootstrap_at_first_pose_ ? "bootstrap at the first localization pose"
                                 : "none (trained online)",
      learn_self_mask ? "; learning the own robot's pixels (~learn_self_mask; ~save_self_mask saves them)" : "");
}

std::string ActTrainerNodelet::notReady() const {
  if (loading()) return "the calibration is still loading";
  return "the nodelet is not configured: " + config_error_;
}

ActTrainerConfig ActTrainerNodelet::configInEffect() const {
  std::lock_guard<std::mutex> lock(mutex_);
  ActTrainerConfig c = ActTrainerConfig::__getDefault__();
  const core::ActParams& p = params_;
  c.eta = p.eta;
  c.zeta = p.zeta;
  c.xi = p.xi;
  c.sigma_min = p.sigma_min;
  c.cluster_stride = p.cluster_stride;
  c.add_stride = p.add_stride;
  c.remove_stride = p.remove_stride;
  c.white_filter = p.white_filter;
  c.add_neighbourhood_cells = p.add_neighbourhood_cells;
  c.light_compensation = p.light_compensation;
  c.light_change_add_stride = p.light_change_add_stride;
  c.removal_protect_cycles = p.removal_protect_cycles;
  c.robot_height_m = p.robot_height_m;
  c.robots_train_black = p.robots_train_black;
  c.nearest_mean = p.nearest_mean;
  c.evidence_removal_ratio = p.evidence_removal_ratio;
  c.learned_boundary = p.learned_boundary;
  c.lattice_sampling = p.lattice_sampling;
  c.pose_check = p.pose_check;
  c.ball_training = p.ball_training;
  c.ball_diameter_m = p.ball_diameter_m;
  c.carpet_edge = p.carpet_edge;
  c.max_pose_age = max_pose_age_s_;
  c.tf_timeout = tf_timeout_s_;
  c.publish_lut_every = publish_lut_every_;
  c.lut_throttled_period = lut_throttled_period_s_;
  return c;
}

bool ActTrainerNodelet::applyConfig(const ActTrainerConfig& c, std::string* error) {
  std::lock_guard<std::mutex> lock(mutex_);
  core::ActParams p = params_;
  p.eta = c.eta;
  p.zeta = c.zeta;
  p.xi = c.xi;
  p.sigma_min = c.sigma_min;
  p.cluster_stride = c.cluster_stride;
  p.add_stride = c.add_stride;
  p.remove_stride = c.remove_stride;
  p.white_filter = c.white_filter;
  p.add_neighbourhood_cells = c.add_neighbourhood_cells;
  p.light_compensation = c.light_compensation;
  p.light_change_add_stride = c.light_change_add_stride;
  p.removal_protect_cycles = c.removal_protect_cycles;
  p.robot_height_m = c.robot_height_m;
  p.robots_train_black = c.robots_train_black;
  p.nearest_mean = c.nearest_mean;
  p.evidence_removal_ratio = c.evidence_removal_ratio;
  p.learned_boundary = c.learned_boundary;
  p.lattice_sampling = c.lattice_sampling;
  p.pose_check = c.pose_check;
  p.ball_training = c.ball_training;
  p.ball_diameter_m = c.ball_diameter_m;
  p.carpet_edge = c.carpet_edge;
  try {
    p.validate();
  } catch (const std::exception& e) {
    *error = e.what();
    return false;
  }
  auto outside = [&](const char* name, double value, double lo, double hi, bool lo_open) {
    try {
      core::requireParameterRange(name, value, lo, hi, lo_open);
      return false;
    } catch (const std::invalid_argument& e) {
      *error = e.what();
      return true;
    }
  };
  if (outside("max_pose_age", c.max_pose_age, 0.0, 60.0, true) ||
      outside("tf_timeout", c.tf_timeout, 0.0, 5.0, false) ||
      outside("publish_lut_every", c.publish_lut_every, 1, 1000, false) ||
      outside("lut_throttled_period", c.lut_throttled_period, 0.0, 3600.0, false)) {
    return false;
  }
  // ActTrainer::setParams keeps what did not change (the table, the generator, the ball detector).
  params_changed_ = true;
  params_ = p;  // applied by the next image, in the image callback
  max_pose_age_s_ = c.max_pose_age;
  pose_source_.setMaxAge(c.max_pose_age);
  tf_timeout_s_ = c.tf_timeout;
  publish_lut_every_ = c.publish_lut_every;
  lut_throttled_period_s_ = c.lut_throttled_period;
  return true;
}

void ActTrainerNodelet::onImage(const sensor_msgs::ImageConstPtr& msg) {
  try {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!trainer_ && !loading()) return;
    const ros::Time before = image_time_.latest();
    if (image_time_.jumpedBack(msg->header.stamp)) onTimeJump(before, msg->header.stamp);
    ++images_;
    last_image_ = ros::WallTime::now();
    pending_.push_back({msg, last_image_});
    if (!trainer_) {
      // Images wait for the calibration as they wait for their pose, the oldest dropped.
      if (pending_.size() > kMaxPending) pending_.pop_front();
      ACT_WALL_THROTTLE(2.0, NODELET_INFO("image waits: the calibration is still loading"));
      return;
    }
    drain();
  } catch (const std::exception& e) {
    ACT_WALL_THROTTLE(5.0, NODELET_ERROR("image stamped %.3f: %s", msg->header.stamp.toSec(), e.what()));
  }
}

void ActTrainerNodelet::drain() {
  if (!trainer_) return;  // the calibration is still loading
  while (!pending_.empty()) {
    const Pending& front = pending_.front();
    const bool may_wait =
        pending_.size() <= kMaxPending && (ros::WallTime::now() - front.arrival).toSec() < tf_timeout_s_;
    if (!trainOn(front.image, may_wait)) return;  // its pose may still come: later images wait behind it
    pending_.pop_front();
  }
}

void ActTrainerNodelet::onTimeJump(const ros::Time& from, const ros::Time& to) {
  ++time_jumps_;
  NODELET_WARN(
      "time jumped back from %.3f to %.3f (a new replay?): poses, waiting images and statistics start "
      "afresh; the color table is %s",
      from.toSec(), to.toSec(), reset_on_time_jump_ ? "reset (~reset_on_time_jump)" : "kept");
  pose_source_.forgetNewerThan(to + ros::Duration(ros_conversions::TimeJumpDetector::kJumpBackS));
  pending_.clear();
  window_.clear();
  fill_history_.clear();
  images_ = cycles_ = skipped_ = rejected_ = contradicted_ = 0;
  last_skip_reason_.clear();
  last_reject_reason_.clear();
  if (reset_on_time_jump_) {
    trainer_->reset(trainer_->lut().colorSpace());
    has_table_ = false;  // trained again from the start (~initial_pose, the first pose or online)
  }
}

void ActTrainerNodelet::useLearnedSelfMask(const std_msgs::Header& header) {
  std::unique_ptr<ros_conversions::SelfMaskWorker::LearnedModel> learned = self_mask_->takeLearnedModel();
  if (!learned) return;
  const auto start = std::chrono::steady_clock::now();
  segmenter_ = std::make_unique<core::Segmenter>(learned->model.camera().calibration());
  auto mask = boost::make_shared<sensor_msgs::Image>();
  mask->data = core::selfMaskImage(learned->model.camera().calibration());
  trainer_->replaceModel(std::move(learned->model));
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  ++self_masks_used_;
  self_mask_pixels_ = learned->pixels;
  self_mask_poses_ = learned->poses;
  mask->header = header;
  mask->encoding = "mono8";
  mask->width = static_cast<uint32_t>(trainer_->model().camera().width());
  mask->height = static_cast<uint32_t>(trainer_->model().camera().height());
  mask->step = mask->width;
  self_mask_pub_.publish(mask);
  NODELET_INFO(
      "the own robot's pixels learned from %d distinct poses (%zu px) are used from the image stamped %.3f on "
      "(taken over in %.1f ms; ~save_self_mask saves them for the calibration)",
      learned->poses, learned->pixels, header.stamp.toSec(), ms);
}

void ActTrainerNodelet::record(Outcome outcome, double cycle_ms, double latency_ms) {
  const ros::WallTime now = ros::WallTime::now();
  window_.add({now, outcome, cycle_ms, latency_ms});
}

bool ActTrainerNodelet::trainOn(const sensor_msgs::ImageConstPtr& msg, bool may_wait) {
  core::ImageView view;
  std::string error;
  // A view of the shared message: no copy of the image.
  // Two throttled messages: one kind of bad image does not hide the other.
  if (!ros_conversions::imageView(*msg, &view, &error)) {
    ACT_WALL_THROTTLE(5.0, NODELET_ERROR("image rejected: %s", error.c_str()));
  } else {
    try {
      trainer_->checkImage(view);
    } catch (const std::invalid_argument& e) {
      error = e.what();
      ACT_WALL_THROTTLE(5.0, NODELET_ERROR("image rejected: %s", error.c_str()));
    }
  }
  if (!error.empty()) {
    ++rejected_;
    last_reject_reason_ = error;
    record(Outcome::kRejected, 0.0, -1.0);
    return true;
  }
  camera_format_ = view.format;

  core::Pose2D pose;
  std::string why;
  const bool have_pose = pose_source_.lookup(msg->header.stamp, &pose, &why);
  const bool startup = !has_table_ && (initial_pose_ || (bootstrap_at_first_pose_ && have_pose));
  if (!have_pose && !startup && may_wait && pose_source_.mayStillCome(msg->header.stamp)) return false;
  // Said when it happens (the cycle below starts the table afresh), not while the image waits.
  if (has_table_ && have_pose && trainer_->lut().colorSpace() != core::nativeColorSpace(view.format)) {
    ACT_WALL_THROTTLE(5.0, NODELET_ERROR("the color table is %s but the camera sends %s: the table starts afresh",
                                         trainer_->lut().colorSpace() == core::ColorSpace::kYuv ? "YUV" : "RGB",
                                         msg->encoding.c_str()));
  }
  if (params_changed_) {
    trainer_->setParams(params_);
    params_changed_ = false;
  }

  const auto start = std::chrono::steady_clock::now();
  Outcome outcome = Outcome::kNoPose;
  if (startup) {
    // The start-up table (paper, section 2): the first image at a known pose.
    const core::Pose2D at = initial_pose_ ? *initial_pose_ : pose;
    trainer_->bootstrap(view, at, bootstrap_cycles_);
    NODELET_INFO("start-up table trained with %d cycles on the image stamped %.3f at the %s pose (%.2f, %.2f, %.2f)",
                 bootstrap_cycles_, msg->header.stamp.toSec(), initial_pose_ ? "initial" : "first localization", at.x_m,
                 at.y_m, at.theta_rad);
    outcome = Outcome::kStartup;
  } else if (have_pose) {
    if (self_mask_) useLearnedSelfMask(msg->header);
    last_stats_ = trainer_->cycle(view, pose);
    outcome = last_stats_.pose_contradicted ? Outcome::kContradicted : Outcome::kTrained;
    // The table after this frame's cycle classifies the frame for the self mask (as act_replay's).
    if (self_mask_ && outcome == Outcome::kTrained) self_mask_->offer(msg, pose, trainer_->lut());
    if (last_stats_.pose_contradicted) {
      ++contradicted_;
      ACT_WALL_THROTTLE(5.0, NODELET_WARN("no training on the image stamped %.3f: %.0f%% of its samples contradict the "
                                          "color table at the pose (%.2f, %.2f, %.2f); is the localization wrong?",
                                          msg->header.stamp.toSec(), 100.0 * last_stats_.contradiction, pose.x_m,
                                          pose.y_m, pose.theta_rad));
    }
    if (last_stats_.ball.seen) {
      geometry_msgs::PointStamped ball;
      ball.header.stamp = msg->header.stamp;
      ball.header.frame_id = base_frame_;
      ball.point.x = last_stats_.ball.x_m;
      ball.point.y = last_stats_.ball.y_m;
      ball.point.z = 0.0;  // where it rests on the carpet
      ball_pub_.publish(ball);
    }
  } else {
    ++skipped_;
    last_skip_reason_ = why;
    ACT_WALL_THROTTLE(
        5.0, NODELET_WARN("no training on the image stamped %.3f: %s", msg->header.stamp.toSec(), why.c_str()));
  }
  const double cycle_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (outcome == Outcome::kStartup) {
    has_table_ = true;
    startup_ms_ = cycle_ms;
  } else if (outcome == Outcome::kTrained || outcome == Outcome::kContradicted) {
    has_table_ = true;
    ++cycles_;
  }
  double latency_ms = -1.0;
  // One table per usable image, stamped with it: "the table trained on frames up to and
  // including t", also when this frame could not train (the segmentation then need not wait).
  if (has_table_ && trainer_->lut().colorSpace() == core::nativeColorSpace(view.format)) {
    publishOutputs(view, msg, have_pose || startup, initial_pose_ && !have_pose ? *initial_pose_ : pose,
                   outcome == Outcome::kTrained ? &last_stats_ : nullptr);
    latency_ms = (ros::Time::now() - msg->header.stamp).toSec() * 1000.0;
  }
  record(outcome, outcome == Outcome::kNoPose ? 0.0 : cycle_ms, latency_ms);
  return true;
}

void ActTrainerNodelet::publishOutputs(const core::ImageView& view, const sensor_msgs::ImageConstPtr& msg,
                                       bool have_pose, const core::Pose2D& pose, const core::CycleStats* trained) {
  const std_msgs::Header& header = msg->header;
  ++publishable_;
  const bool every = (publishable_ - 1) % static_cast<uint64_t>(publish_lut_every_) == 0;
  const ros::WallTime now = ros::WallTime::now();
  const bool throttled = lut_throttled_period_s_ > 0.0 && lut_throttled_pub_.getNumSubscribers() > 0 &&
                         (now - last_throttled_).toSec() >= lut_throttled_period_s_;
  if (every || throttled) {
    boost::shared_ptr<const act_color::ColorLut> lut = ros_conversions::toMsg(*trainer_, header);
    if (every) lut_pub_.publish(lut);
    if (throttled) {
      lut_throttled_pub_.publish(lut);
      last_throttled_ = now;
    }
    if (debug_addresses_ && every) {
      std_msgs::UInt64MultiArray debug;
      debug.data = {header.stamp.toNSec(), reinterpret_cast<uint64_t>(lut.get()), lut->revision};
      debug_pub_.publish(debug);
    }
  }
  if (classified_pub_.getNumSubscribers() > 0) {
    segmenter_->classify(trainer_->lut(), view, labels_);
    trainer_->unlabelBeyondCarpet(labels_);
    if (trained) trainer_->labelBall(*trained, labels_);
    cv_bridge::CvImage out(header, "rgb8");
    core::colorizeLabels(labels_, out.image);
    classified_pub_.publish(out.toImageMsg());
  }
  if (!have_pose) return;
  if (pose_pub_.getNumSubscribers() > 0) {
    geometry_msgs::PoseStamped p;
    p.header.stamp = header.stamp;
    p.header.frame_id = field_frame_;
    p.pose.position.x = pose.x_m;
    p.pose.position.y = pose.y_m;
    p.pose.orientation.z = std::sin(0.5 * pose.theta_rad);
    p.pose.orientation.w = std::cos(0.5 * pose.theta_rad);
    pose_pub_.publish(p);
  }
  if (expected_pub_.getNumSubscribers() > 0) {
    // Half the camera image, half the expected class (eq. 1 applied: white that fails it is grey).
    cv::Mat expected = trainer_->model().expectedLabels(view, pose);
    expected.setTo(core::kUnknown, expected == core::kRejectedWhite);
    core::colorizeLabels(expected, expected_);
    const bool uyvy = view.format == core::PixelFormat::kUyvy;
    const cv::Mat raw(view.height, view.width, uyvy ? CV_8UC2 : CV_8UC3, const_cast<uint8_t*>(view.data), view.step);
    cv::Mat rgb = raw;
    if (uyvy) cv::cvtColor(raw, rgb, cv::COLOR_YUV2RGB_UYVY);
    if (view.format == core::PixelFormat::kBgr8) cv::cvtColor(raw, rgb, cv::COLOR_BGR2RGB);
    cv_bridge::CvImage out(header, "rgb8");
    cv::addWeighted(rgb, 0.5, expected_, 0.5, 0.0, out.image);
    expected_pub_.publish(out.toImageMsg());
  }
}

void ActTrainerNodelet::publishTableImage() {
  if (table_image_pub_.getNumSubscribers() == 0) return;
  cv_bridge::CvImage out;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!trainer_ || !has_table_ || trainer_->revision() == table_image_revision_) return;
    table_image_revision_ = trainer_->revision();
    const core::ColorLut& lut = trainer_->lut();
    out.image = core::renderLutSlices(lut, std::min(16, 1 << lut.bitsPerChannel()),
                                      std::string("ACT table, revision ") + std::to_string(trainer_->revision()));
    out.header.stamp = image_time_.latest();
  }
  out.encoding = "bgr8";
  table_image_pub_.publish(out.toImageMsg());
}

void ActTrainerNodelet::publishFieldMarkers(const core::FieldModel& field) {
  visualization_msgs::MarkerArray markers;
  visualization_msgs::Marker m;
  m.header.frame_id = field_frame_;
  m.ns = "field";
  m.pose.orientation.w = 1.0;
  m.action = visualization_msgs::Marker::ADD;
  auto color = [](int k, double alpha) {
    std_msgs::ColorRGBA c;
    const auto& rgb = core::classPalette()[k];
    c.r = rgb[0] / 255.f;
    c.g = rgb[1] / 255.f;
    c.b = rgb[2] / 255.f;
    c.a = static_cast<float>(alpha);
    return c;
  };
  // The carpet, the field plus its margin.
  const core::FieldCalibration& f = field.calibration();
  m.id = 0;
  m.type = visualization_msgs::Marker::CUBE;
  m.scale.x = f.length_m + 2 * f.margin_m;
  m.scale.y = f.width_m + 2 * f.margin_m;
  m.scale.z = 0.01;
  m.pose.position.z = -0.01;
  m.color = color(core::kGreen, 0.6);
  markers.markers.push_back(m);
  // The markings, sampled every 4 cm from the field model itself (arcs and lab-field variants
  // included).
  m.id = 1;
  m.type = visualization_msgs::Marker::POINTS;
  m.pose.position.z = 0.0;
  m.scale.x = m.scale.y = 0.05;
  m.color = color(core::kWhite, 1.0);
  const double step = 0.04;
  for (double x = -field.halfLength() - f.margin_m; x <= field.halfLength() + f.margin_m; x += step) {
    for (double y = -field.halfWidth() - f.margin_m; y <= field.halfWidth() + f.margin_m; y += step) {
      if (!field.isLine(x, y)) continue;
      geometry_msgs::Point p;
      p.x = x;
      p.y = y;
      m.points.push_back(p);
    }
  }
  markers.markers.push_back(m);
  m.points.clear();
  // The goals as the boxes the expected-class model uses.
  int id = 2;
  for (core::ColorClass goal : {core::kYellow, core::kBlue}) {
    Eigen::Vector3d lo, hi;
    field.goalBox(goal, &lo, &hi);
    m.id = id++;
    m.type = visualization_msgs::Marker::CUBE;
    m.pose.position.x = 0.5 * (lo.x() + hi.x());
    m.pose.position.y = 0.5 * (lo.y() + hi.y());
    m.pose.position.z = 0.5 * (lo.z() + hi.z());
    m.scale.x = hi.x() - lo.x();
    m.scale.y = hi.y() - lo.y();
    m.scale.z = hi.z() - lo.z();
    m.color = color(goal, 0.8);
    markers.markers.push_back(m);
  }
  field_pub_.publish(markers);
}

bool ActTrainerNodelet::prepareSave(act_color::ColorLutPtr* msg, std::string* lut_dir, std::string* message) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!trainer_ || !has_table_) {
    *message = trainer_ ? "no table trained yet" : notReady();
    return false;
  }
  std_msgs::Header header;
  header.stamp = image_time_.latest();
  *msg = ros_conversions::toMsg(*trainer_, header);
  *lut_dir = lut_dir_;
  return true;
}

bool ActTrainerNodelet::writeTable(const act_color::ColorLut& msg, const std::string& lut_dir,
                                   const std::string& requested, std::string* message) {
  std::string path;
  if (!ros_conversions::lutPathInside(lut_dir, requested, &path, message)) return false;
  if (!ros_conversions::saveLutFile(msg, path, message)) return false;
  *message = "saved the color table (revision " + std::to_string(msg.revision) + ") and its clusters to " + path;
  return true;
}

bool ActTrainerNodelet::saveLut(const std::string& requested, std::string* message) {
  act_color::ColorLutPtr msg;
  std::string lut_dir;
  return prepareSave(&msg, &lut_dir, message) && writeTable(*msg, lut_dir, requested, message);
}

std::string ActTrainerNodelet::loadPath(const std::string& requested) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return !requested.empty() && requested[0] != '/' ? lut_dir_ + "/" + requested : requested;  // relative: in ~lut_dir
}

bool ActTrainerNodelet::readTable(const std::string& path, LoadedTable* table, std::string* message) {
  if (!ros_conversions::loadLutFile(path, &table->msg, message)) return false;
  if (!ros_conversions::fromMsg(table->msg, &table->lut, &table->clusters, message)) {
    *message = path + ": " + *message;
    return false;
  }
  return true;
}

bool ActTrainerNodelet::loadLut(const std::string& requested, std::string* message) {
  const std::string path = loadPath(requested);
  LoadedTable table;
  return readTable(path, &table, message) && installTable(path, table, message);
}

bool ActTrainerNodelet::installTable(const std::string& path, const LoadedTable& table, std::string* message) {
  const core::ColorLut& lut = table.lut;
  const act_color::ColorLut& msg = table.msg;
  const auto& clusters = table.clusters;
  std::lock_guard<std::mutex> lock(mutex_);
  if (!trainer_) {
    *message = notReady();
    return false;
  }
  if (camera_format_ && lut.colorSpace() != core::nativeColorSpace(*camera_format_)) {
    *message = path + ": the table is " + (lut.colorSpace() == core::ColorSpace::kYuv ? "YUV" : "RGB") +
               ", the camera sends " + core::encodingName(*camera_format_) + ": not loaded";
    return false;
  }
  try {
    trainer_->restore(lut, clusters, msg.revision);
  } catch (const std::exception& e) {
    *message = path + ": " + e.what();
    return false;
  }
  has_table_ = true;
  *message = "loaded the color table of " + path + " (revision " + std::to_string(msg.revision) + ", " +
             std::to_string(clusters.size()) + " clusters)";
  return true;
}

bool ActTrainerNodelet::requestPath(const FilePath::Request& req, FilePath::Response& res, std::string* path) const {
  std::lock_guard<std::mutex> lock(mutex_);
  *path = req.path.empty() ? lut_file_ : req.path;
  if (!path->empty()) return true;
  res.success = false;
  res.message = "no path given and ~lut_file is not set";
  return false;
}

namespace {

// Runs `io` on a thread of its own and waits at most `timeout_s`: a file system that hangs (a dead
// network mount) leaves the service answering, the I/O thread going on alone (so `io` holds what
// it uses, not the nodelet).
bool withTimeout(const std::function<bool(std::string*)>& io, double timeout_s, std::string* message) {
  struct Shared {
    std::mutex mutex;
    std::condition_variable done_cv;
    bool done = false, ok = false;
    std::string message;
  };
  auto shared = std::make_shared<Shared>();
  std::thread([shared, io] {
    std::string m;
    bool ok = false;
    try {
      ok = io(&m);
    } catch (const std::exception& e) {
      m = e.what();
    }
    std::lock_guard<std::mutex> lock(shared->mutex);
    shared->ok = ok;
    shared->message = m;
    shared->done = true;
    shared->done_cv.notify_all();
  }).detach();
  std::unique_lock<std::mutex> lock(shared->mutex);
  if (!shared->done_cv.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] { return shared->done; })) {
    *message = "the file operation did not finish within " + std::to_string(static_cast<int>(timeout_s)) +
               " s (a hanging file system?); it goes on in the background";
    return false;
  }
  *message = shared->message;
  return shared->ok;
}

constexpr double kFileTimeoutS = 5.0;

}  // namespace

bool ActTrainerNodelet::onSaveLut(FilePath::Request& req, FilePath::Response& res) {
  std::string path;
  if (!requestPath(req, res, &path)) return true;
  act_color::ColorLutPtr msg;
  std::string lut_dir;
  // Every file system call (the folder's checks too) on the I/O thread, without the lock: it
  // touches nothing of the nodelet, which may be gone when a hanging file system lets it finish.
  res.success = prepareSave(&msg, &lut_dir, &res.message) &&
                withTimeout([msg, lut_dir, path](std::string* m) { return writeTable(*msg, lut_dir, path, m); },
                            kFileTimeoutS, &res.message);
  if (!res.success) NODELET_ERROR("~save_lut: %s", res.message.c_str());
  return true;
}

bool ActTrainerNodelet::onLoadLut(FilePath::Request& req, FilePath::Response& res) {
  std::string path;
  if (!requestPath(req, res, &path)) return true;
  const std::string file = loadPath(path);
  auto table = std::make_shared<LoadedTable>();
  res.success = withTimeout([table, file](std::string* m) { return readTable(file, table.get(), m); }, kFileTimeoutS,
                            &res.message) &&
                installTable(file, *table, &res.message);
  if (!res.success) NODELET_ERROR("~load_lut: %s", res.message.c_str());
  return true;
}

bool ActTrainerNodelet::onSaveSelfMask(FilePath::Request& req, FilePath::Response& res) {
  std::shared_ptr<ros_conversions::SelfMaskWorker> worker;
  std::string lut_dir;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    worker = self_mask_;
    lut_dir = lut_dir_;
    res.success = false;
    if (!learn_self_mask_) {
      res.message = "~learn_self_mask is off: nothing is learned";
    } else if (!trainer_) {
      res.message = notReady();
    }
  }
  if (worker) {
    int poses = 0;
    size_t headings = 0;
    const core::CameraCalibration camera = worker->learned(&poses, &headings);
    if (poses == 0) {
      res.message = "no frame counted yet: the self mask is learned from trained frames at distinct poses";
      const std::string error = worker->progress().last_error;
      if (!error.empty()) res.message += " (the last one failed: " + error + ")";
    } else {
      const std::string requested = req.path.empty() ? "self_mask.png" : req.path;
      std::shared_ptr<const std::vector<uint8_t>> png;
      try {
        png = std::make_shared<const std::vector<uint8_t>>(core::encodeSelfMask(camera));
      } catch (const std::exception& e) {
        res.message = e.what();
      }
      auto shared_path = std::make_shared<std::string>();
      res.success = png && withTimeout(
                               [png, lut_dir, requested, shared_path](std::string* m) {
                                 return ros_conversions::lutPathInside(lut_dir, requested, shared_path.get(), m) &&
                                        ros_conversions::savePngFile(*png, *shared_path, m);
                               },
                               kFileTimeoutS, &res.message);
      if (res.success) {
        size_t pixels = 0;
        for (uint8_t m : camera.self_mask) pixels += m;
        std::ostringstream m;
        m.precision(3);
        m << "saved the self mask learned from " << poses << " distinct poses (" << pixels << " pixels, "
          << 100.0 * static_cast<double>(pixels) / static_cast<double>(camera.self_mask.size()) << "% of the image) to "
          << *shared_path << ": set 'self_mask: " << *shared_path << "' in the calibration's camera section";
        m << "; the poses faced " << headings << " of " << core::SelfMaskLearner::kHeadingSectors << " directions";
        if (poses < core::SelfMaskLearner::kMinPosesForConstancy) {
          m << "; fewer than " << core::SelfMaskLearner::kMinPosesForConstancy
            << " distinct poses, so struts are not yet followed over the hall: drive and turn on, then save again";
        } else if (headings < core::SelfMaskLearner::kMinHeadingSectors) {
          m << "; fewer than " << core::SelfMaskLearner::kMinHeadingSectors
            << ", so struts over the hall alone are not looked for yet: turn on, then save again";
        }
        res.message = m.str();
      }
    }
  }
  if (res.success) {
    NODELET_INFO("~save_self_mask: %s", res.message.c_str());
  } else {
    NODELET_ERROR("~save_self_mask: %s", res.message.c_str());
  }
  return true;
}

void ActTrainerNodelet::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  std::lock_guard<std::mutex> lock(mutex_);
  if (loading()) {
    status.summary(DiagnosticStatus::WARN, "loading the calibration");
    status.add("images waiting", pending_.size());
    return;
  }
  if (!config_error_.empty() || !trainer_) {
    status.summary(DiagnosticStatus::ERROR, "not configured: " + config_error_);
    return;
  }
  const ros::WallTime now = ros::WallTime::now();
  window_.trim(now);
  size_t trained = 0, no_pose = 0, rejected = 0, contradicted = 0, cycles = 0, latencies = 0;
  double sum_ms = 0, max_ms = 0, sum_latency = 0, max_latency = 0;
  for (const Record& r : window_) {
    if (r.outcome == Outcome::kRejected) ++rejected;
    if (r.outcome == Outcome::kNoPose) ++no_pose;
    if (r.outcome == Outcome::kContradicted) ++contradicted;
    if (r.outcome == Outcome::kTrained || r.outcome == Outcome::kStartup) ++trained;
    if (r.outcome == Outcome::kTrained || r.outcome == Outcome::kContradicted) {  // the start-up training apart
      ++cycles;
      sum_ms += r.cycle_ms;
      max_ms = std::max(max_ms, r.cycle_ms);
    }
    if (r.latency_ms >= 0) {
      ++latencies;
      sum_latency += r.latency_ms;
      max_latency = std::max(max_latency, r.latency_ms);
    }
  }
  const size_t n = window_.size();
  const double since_image = last_image_.isZero() ? -1.0 : (now - last_image_).toSec();
  const auto counts = trainer_->lut().cellCounts();
  const uint64_t filled = trainer_->lut().mappedCells();
  fill_history_.emplace_back(now, filled);
  while (!fill_history_.empty() && (now - fill_history_.front().first).toSec() > kFillWindowS) {
    fill_history_.pop_front();
  }
  uint64_t max_filled = 0;
  for (const auto& f : fill_history_) max_filled = std::max(max_filled, f.second);
  using ros_conversions::percent;
  const double fill_percent = percent(filled, trainer_->lut().size());

  status.summary(DiagnosticStatus::OK, "training");
  std::ostringstream m;
  m.precision(3);
  if (images_ == 0) {
    status.summary(DiagnosticStatus::WARN, "no image received yet");
  } else if (since_image > 2.0) {
    m << "no image for " << since_image << " s (input stale)";
    status.summary(DiagnosticStatus::WARN, m.str());
  } else if (n > 0 && rejected == n) {
    status.summary(DiagnosticStatus::ERROR, "every image rejected: " + last_reject_reason_);
  } else {
    if (rejected > 0) {
      m << rejected << " of " << n << " images in " << kWindowS << " s rejected: " << last_reject_reason_;
      status.mergeSummary(DiagnosticStatus::WARN, m.str());
      m.str("");
    }
    if (contradicted > 0) {
      m << "the pose contradicted the color table in " << contradicted << " of " << n << " images in " << kWindowS
        << " s (no training on them): is the localization wrong?";
      status.mergeSummary(DiagnosticStatus::WARN, m.str());
      m.str("");
    }
    if (n > rejected + contradicted && trained == 0) {
      status.mergeSummary(DiagnosticStatus::ERROR, "not training: " + last_skip_reason_);
    } else if (no_pose > 0 && trained < 0.9 * (n - rejected)) {
      m << "only " << percent(trained, n - rejected) << "% of the images trained: " << last_skip_reason_;
      status.mergeSummary(DiagnosticStatus::WARN, m.str());
      m.str("");
    }
  }
  if (has_table_ && filled == 0) {
    status.mergeSummary(DiagnosticStatus::ERROR, "the color table is empty");
  } else if (max_filled > 0 && 2 * filled < max_filled) {
    m << "the color table shrank from " << percent(max_filled, trainer_->lut().size()) << "% to " << fill_percent
      << "% of its cells in " << kFillWindowS << " s";
    status.mergeSummary(DiagnosticStatus::WARN, m.str());
  }
  status.add("input rate (Hz)", window_.rateHz());
  status.add("trained (%, last 5 s)", percent(trained, n));
  status.add("rejected (%, last 5 s)", percent(rejected, n));
  status.add("without pose (%, last 5 s)", percent(no_pose, n));
  status.add("pose contradicted by the table (%, last 5 s)", percent(contradicted, n));
  status.add("cycle time mean (ms, last 5 s)", cycles ? sum_ms / cycles : 0.0);
  status.add("cycle time max (ms, last 5 s)", max_ms);
  status.add("start-up training (ms)", startup_ms_);
  status.add("latency image stamp to table mean (ms, last 5 s)", latencies ? sum_latency / latencies : 0.0);
  status.add("latency image stamp to table max (ms, last 5 s)", max_latency);
  status.add("images", images_);
  status.add("cycles", cycles_);
  status.add("images without training (no pose)", skipped_);
  status.add("images rejected", rejected_);
  status.add("images not trained (pose contradicted by the table)", contradicted_);
  status.add("images waiting for their pose", pending_.size());
  status.add("last skip reason", last_skip_reason_);
  status.add("last rejection", last_reject_reason_);
  status.add("poses rejected", pose_source_.rejected());
  status.add("time jumps back", time_jumps_);
  if (self_mask_) {
    const ros_conversions::SelfMaskWorker::Progress p = self_mask_->progress();
    status.add("self mask learned from (distinct poses)", p.poses);
    status.add("self mask: directions faced (of " + std::to_string(core::SelfMaskLearner::kHeadingSectors) + ")",
               p.headings);
    status.add("self mask: last pose counted in (ms, own thread)", p.last_ms);
    if (!p.last_error.empty()) status.add("self mask: last frame not counted", p.last_error);
    status.add("self mask in use (pixels)", self_mask_pixels_);
    status.add("self mask in use: learned from (distinct poses)", self_mask_poses_);
    status.add("self masks used so far", self_masks_used_);
  }
  status.add("table revision", trainer_->revision());
  status.add("table fill (%)", fill_percent);
  const bool yellow_absent = trainer_->goalAbsent(core::kYellow), blue_absent = trainer_->goalAbsent(core::kBlue);
  status.add("goals taken as absent (colored like the lines)", yellow_absent && blue_absent ? "yellow, blue"
                                                               : yellow_absent              ? "yellow"
                                                               : blue_absent                ? "blue"
                                                                                            : "none");
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
