// Simulated omnidirectional camera: renders one of the simulator's scenarios in a loop and
// publishes image, truth labels, the localization pose and tf, with the light changing over time.
// For demo.launch and the rostests; no robot and no bag needed.
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <tf2_ros/transform_broadcaster.h>

#include <atomic>
#include <boost/make_shared.hpp>
#include <cmath>
#include <memory>
#include <pluginlib/class_list_macros.hpp>
#include <string>
#include <thread>

#include "act_color/core/calibration.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scenario.hpp"
#include "act_color/sim/tone_curve.hpp"

namespace act_color {

class SimulatedCameraNodelet : public nodelet::Nodelet {
 public:
  ~SimulatedCameraNodelet() override {
    running_ = false;
    if (thread_.joinable()) thread_.join();
  }

 private:
  void onInit() override;
  void run();
  sensor_msgs::ImagePtr toMsg(const cv::Mat& mat, const std::string& encoding, const std_msgs::Header& header) const;

  ros::Publisher image_pub_, truth_pub_, pose_pub_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_broadcaster_;
  core::Calibration calibration_;
  sim::Scenario scenario_;
  double rate_hz_ = 30.0;
  bool loop_ = true;
  int max_frames_ = 0;
  double light_amplitude_ = 0.3;
  // Flicker (issue 15): from frame flicker_start_ on, the last frame of every flicker_period_
  // frames is darkened to flicker_gain_ (2: every other frame; 10: one dark frame in ten); 0: none.
  int flicker_period_ = 0, flicker_start_ = 0;
  double flicker_gain_ = 0.5;
  double light_period_s_ = 20.0;
  double start_delay_s_ = 0.0;
  int wait_image_subscribers_ = 0, wait_truth_subscribers_ = 0;
  std::string field_frame_, base_frame_;
  std::atomic<bool> running_{false};
  std::thread thread_;
};

void SimulatedCameraNodelet::onInit() {
  ros::NodeHandle& nh = getNodeHandle();
  ros::NodeHandle& pnh = getPrivateNodeHandle();
  try {
    const std::string path = pnh.param<std::string>("calibration", "");
    if (path.empty()) throw std::invalid_argument("parameter ~calibration is not set");
    calibration_ = core::loadCalibration(path);
    const std::string name = pnh.param<std::string>("scenario", "driving");
    const std::string length_text = pnh.param<std::string>("length", "full");
    sim::ScenarioLength length;
    if (!sim::parseScenarioLength(length_text, &length))
      throw std::invalid_argument("~length must be small or full, is '" + length_text + "'");
    scenario_ = sim::makeScenario(name, length, calibration_, static_cast<uint32_t>(pnh.param("seed", 1)));
    rate_hz_ = pnh.param("rate", 30.0);
    if (!(rate_hz_ > 0.0 && rate_hz_ <= 1000.0)) throw std::invalid_argument("~rate must be in (0, 1000] Hz");
    loop_ = pnh.param("loop", true);
    max_frames_ = pnh.param("max_frames", 0);
    light_amplitude_ = pnh.param("light_amplitude", 0.3);
    light_period_s_ = pnh.param("light_period", 20.0);
    flicker_period_ = pnh.param("flicker_period", 0);
    flicker_start_ = pnh.param("flicker_start", 0);
    flicker_gain_ = pnh.param("flicker_gain", 0.5);
    if (flicker_period_ < 0 || flicker_period_ == 1 || flicker_start_ < 0 ||
        !(flicker_gain_ > 0.0 && flicker_gain_ <= 4.0))
      throw std::invalid_argument("~flicker_period must be 0 or >= 2, ~flicker_start >= 0, ~flicker_gain in (0, 4]");
    start_delay_s_ = pnh.param("start_delay", 0.0);
    wait_image_subscribers_ = pnh.param("wait_for_image_subscribers", 0);
    wait_truth_subscribers_ = pnh.param("wait_for_truth_subscribers", 0);
    if (!(light_amplitude_ >= 0.0 && light_amplitude_ < 1.0) || !(light_period_s_ > 0.0))
      throw std::invalid_argument("~light_amplitude must be in [0, 1) and ~light_period > 0");
    field_frame_ = pnh.param<std::string>("field_frame", "field");
    base_frame_ = pnh.param<std::string>("base_frame", "base_link");
  } catch (const std::exception& e) {
    NODELET_ERROR("not started: %s", e.what());
    return;
  }
  image_pub_ = nh.advertise<sensor_msgs::Image>("image", 2);
  truth_pub_ = nh.advertise<sensor_msgs::Image>("labels_truth", 2);
  pose_pub_ = nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("pose", 10);
  tf_broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();
  NODELET_INFO("simulating scenario '%s' (%zu frames, %s) at %.1f Hz, light level x (1 +- %.2f) over %.0f s",
               scenario_.name.c_str(), scenario_.frames.size(), loop_ ? "looping" : "once", rate_hz_, light_amplitude_,
               light_period_s_);
  // Rendering takes tens of milliseconds: on an own thread, never on the manager's.
  running_ = true;
  thread_ = std::thread([this] { run(); });
}

sensor_msgs::ImagePtr SimulatedCameraNodelet::toMsg(const cv::Mat& mat, const std::string& encoding,
                                                    const std_msgs::Header& header) const {
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->header = header;
  msg->height = static_cast<uint32_t>(mat.rows);
  msg->width = static_cast<uint32_t>(mat.cols);
  msg->encoding = encoding;
  msg->step = static_cast<uint32_t>(mat.cols * mat.elemSize());
  msg->data.resize(static_cast<size_t>(msg->step) * mat.rows);
  for (int v = 0; v < mat.rows; ++v)
    std::copy(mat.ptr<uint8_t>(v), mat.ptr<uint8_t>(v) + msg->step, msg->data.begin() + size_t{msg->step} * v);
  return msg;
}

void SimulatedCameraNodelet::run() {
  try {
    const sim::Renderer renderer(calibration_);
    const ros::WallTime start = ros::WallTime::now();
    // Starts after ~start_delay and once the expected subscribers are connected, so that no one
    // misses the first frame.
    while (running_ && ros::ok() &&
           ((ros::WallTime::now() - start).toSec() < start_delay_s_ ||
            static_cast<int>(image_pub_.getNumSubscribers()) < wait_image_subscribers_ ||
            static_cast<int>(truth_pub_.getNumSubscribers()) < wait_truth_subscribers_)) {
      ros::WallDuration(0.01).sleep();
    }
    ros::WallRate rate(rate_hz_);
    const ros::WallTime t0 = ros::WallTime::now();
    size_t index = 0;
    int published = 0;
    uint32_t loops = 0;
    while (running_ && ros::ok()) {
      if (index >= scenario_.frames.size()) {
        if (!loop_) break;
        index = 0;
        ++loops;
      }
      if (max_frames_ > 0 && published >= max_frames_) break;
      sim::ScenarioFrame frame = scenario_.frames[index++];
      // Light changing over time on top of the scenario's own.
      const double t = (ros::WallTime::now() - t0).toSec();
      frame.scene.lighting.level *= 1.0 + light_amplitude_ * std::sin(2.0 * M_PI * t / light_period_s_);
      if (flicker_period_ > 0 && published >= flicker_start_ &&
          (published - flicker_start_) % flicker_period_ == flicker_period_ - 1) {
        frame.scene.lighting.transfer =
            frame.scene.lighting.transfer.then(sim::ToneCurve::gain(Eigen::Vector3d::Constant(flicker_gain_)));
      }
      // The first pass is the scenario as act_make_scenarios writes it; later passes get new noise.
      frame.scene.noise_seed += loops * 1000003u;
      const sim::LabeledFrame rendered = renderer.render(frame.scene);

      std_msgs::Header header;
      header.stamp = ros::Time::now();
      header.frame_id = field_frame_;
      auto pose = boost::make_shared<geometry_msgs::PoseWithCovarianceStamped>();
      pose->header = header;
      pose->pose.pose.position.x = frame.told_pose.x_m;
      pose->pose.pose.position.y = frame.told_pose.y_m;
      pose->pose.pose.orientation.z = std::sin(frame.told_pose.theta_rad / 2);
      pose->pose.pose.orientation.w = std::cos(frame.told_pose.theta_rad / 2);
      pose->pose.covariance[0] = pose->pose.covariance[7] = 0.01;
      pose->pose.covariance[35] = 0.003;
      geometry_msgs::TransformStamped tf;
      tf.header = header;
      tf.child_frame_id = base_frame_;
      tf.transform.translation.x = frame.told_pose.x_m;
      tf.transform.translation.y = frame.told_pose.y_m;
      tf.transform.rotation = pose->pose.pose.orientation;
      tf_broadcaster_->sendTransform(tf);
      pose_pub_.publish(boost::shared_ptr<const geometry_msgs::PoseWithCovarianceStamped>(pose));

      header.frame_id = "omni_camera";
      truth_pub_.publish(boost::shared_ptr<const sensor_msgs::Image>(toMsg(rendered.labels, "mono8", header)));
      image_pub_.publish(boost::shared_ptr<const sensor_msgs::Image>(toMsg(rendered.rgb, "rgb8", header)));
      ++published;
      rate.sleep();
    }
    NODELET_INFO("simulation finished after %d frames", published);
  } catch (const std::exception& e) {
    NODELET_ERROR("simulation stopped: %s", e.what());
  }
}

}  // namespace act_color

PLUGINLIB_EXPORT_CLASS(act_color::SimulatedCameraNodelet, nodelet::Nodelet)
