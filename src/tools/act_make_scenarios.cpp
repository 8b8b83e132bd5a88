// Writes the simulator's scenarios as bags in the contract's topics, with truth, no ROS master needed:
//   act_make_scenarios --calibration CAL.yaml --scenario NAME|all --length small|full --output-dir DIR
//                      [--seed N] [--png DIR] [--compression none|lz4|bz2]
//   act_make_scenarios --family SEED --length small|full --output-dir DIR [--png DIR] [--compression ...]
//     writes the randomized family's scene SEED as family_SEED.bag and its calibration family_SEED.yaml
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <ros/time.h>
#include <rosbag/bag.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>
#include <tf2_msgs/TFMessage.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <string>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scenario.hpp"
#include "act_color/sim/scene_family.hpp"

namespace {

using act_color::core::Pose2D;
namespace sim = act_color::sim;

constexpr int kExitBadArguments = 2;
// All bags start at the same fixed time (RoboCup 2007, Atlanta), 30 Hz.
const ros::Time kStartTime(1183300000, 0);

const char* const kUsage =
    "usage: act_make_scenarios --calibration CAL.yaml --scenario NAME|all --length small|full\n"
    "                          --output-dir DIR [--seed N] [--png DIR] [--compression none|lz4|bz2]\n"
    "       act_make_scenarios --family SEED --length small|full --output-dir DIR [--png DIR]\n"
    "                          [--compression none|lz4|bz2]\n";

int badArguments(const std::string& message) {
  std::cerr << "act_make_scenarios: " << message << "\n" << kUsage;
  return kExitBadArguments;
}

sensor_msgs::Image toImage(const cv::Mat& mat, const std::string& encoding, const std_msgs::Header& header) {
  sensor_msgs::Image image;
  image.header = header;
  image.height = static_cast<uint32_t>(mat.rows);
  image.width = static_cast<uint32_t>(mat.cols);
  image.encoding = encoding;
  image.is_bigendian = 0;
  image.step = static_cast<uint32_t>(mat.cols * mat.elemSize());
  image.data.resize(static_cast<size_t>(image.step) * mat.rows);
  for (int v = 0; v < mat.rows; ++v) {
    std::copy(mat.ptr<uint8_t>(v), mat.ptr<uint8_t>(v) + image.step,
              image.data.begin() + static_cast<size_t>(v) * image.step);
  }
  return image;
}

geometry_msgs::Pose toPose(const Pose2D& pose) {
  geometry_msgs::Pose p;
  p.position.x = pose.x_m;
  p.position.y = pose.y_m;
  p.position.z = 0.0;
  p.orientation.x = 0.0;
  p.orientation.y = 0.0;
  p.orientation.z = std::sin(pose.theta_rad / 2);
  p.orientation.w = std::cos(pose.theta_rad / 2);
  return p;
}

geometry_msgs::PoseWithCovarianceStamped toPoseMsg(const Pose2D& pose, const ros::Time& stamp, double sigma_xy_m,
                                                   double sigma_theta_rad) {
  geometry_msgs::PoseWithCovarianceStamped msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = "field";
  msg.pose.pose = toPose(pose);
  msg.pose.covariance[0] = msg.pose.covariance[7] = sigma_xy_m * sigma_xy_m;
  msg.pose.covariance[35] = sigma_theta_rad * sigma_theta_rad;
  return msg;
}

void writePng(const std::string& path, const cv::Mat& rgb) {
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  if (!cv::imwrite(path, bgr)) throw std::runtime_error("cannot write " + path);
}

}  // namespace

int main(int argc, char** argv) {
  std::map<std::string, std::string> args;
  static const std::vector<std::string> kOptions = {"--calibration", "--scenario", "--length",      "--output-dir",
                                                    "--seed",        "--png",      "--compression", "--family"};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "-h" || a == "--help") {
      std::cout << kUsage;
      return 0;
    }
    if (std::find(kOptions.begin(), kOptions.end(), a) == kOptions.end())
      return badArguments("unknown argument '" + a + "'");
    if (i + 1 >= argc) return badArguments(a + " needs a value");
    if (args.count(a)) return badArguments(a + " given twice");
    args[a] = argv[++i];
  }
  const bool family = args.count("--family") > 0;
  if (family) {
    // The family scene brings its own camera and field, and its seed is the scene.
    for (const char* other : {"--calibration", "--scenario", "--seed"}) {
      if (args.count(other)) return badArguments(std::string("--family and ") + other + " exclude each other");
    }
  }
  for (const char* required : {"--calibration", "--scenario", "--length", "--output-dir"}) {
    if (family && (std::string(required) == "--calibration" || std::string(required) == "--scenario")) continue;
    if (!args.count(required)) return badArguments(std::string("missing ") + required);
  }
  sim::ScenarioLength length;
  if (!sim::parseScenarioLength(args["--length"], &length)) {
    return badArguments("--length must be small or full, is '" + args["--length"] + "'");
  }
  std::vector<std::string> names;
  if (family) {
    // One scene, named after its seed.
  } else if (args["--scenario"] == "all") {
    names = sim::scenarioNames();
  } else {
    const auto& known = sim::scenarioNames();
    if (std::find(known.begin(), known.end(), args["--scenario"]) == known.end()) {
      std::string list;
      for (const auto& n : known) list += n + ", ";
      return badArguments("unknown scenario '" + args["--scenario"] + "' (known: " + list + "or all)");
    }
    names = {args["--scenario"]};
  }
  uint32_t seed = 1;
  const char* const seed_option = family ? "--family" : "--seed";
  if (args.count(seed_option)) {
    const std::string& text = args[seed_option];
    char* end = nullptr;
    const unsigned long value = std::strtoul(text.c_str(), &end, 10);
    if (text.empty() || text[0] == '-' || *end != '\0' || value > 0xFFFFFFFFul) {
      return badArguments(std::string(seed_option) + " must be an integer in [0, 4294967295], is '" + text + "'");
    }
    seed = static_cast<uint32_t>(value);
  }
  rosbag::compression::CompressionType compression = rosbag::compression::LZ4;
  if (args.count("--compression")) {
    const std::string& c = args["--compression"];
    if (c == "none") {
      compression = rosbag::compression::Uncompressed;
    } else if (c == "lz4") {
      compression = rosbag::compression::LZ4;
    } else if (c == "bz2") {
      compression = rosbag::compression::BZ2;
    } else {
      return badArguments("--compression must be none, lz4 or bz2, is '" + c + "'");
    }
  }
  act_color::core::Calibration calibration;
  if (!family) {
    try {
      calibration = act_color::core::loadCalibration(args["--calibration"]);
    } catch (const std::exception& e) {
      return badArguments(std::string("bad calibration: ") + e.what());
    }
  }

  try {
    const std::filesystem::path out_dir(args["--output-dir"]);
    std::filesystem::create_directories(out_dir);
    std::filesystem::path png_dir;
    if (args.count("--png")) {
      png_dir = args["--png"];
      std::filesystem::create_directories(png_dir);
    }
    ros::Time::init();
    const std::string length_name = length == sim::ScenarioLength::kSmall ? "small" : "full";
    // What to write: a file stem, the scenario and the renderer of its camera and hall.
    struct Job {
      std::string stem;
      sim::Scenario scenario;
      std::shared_ptr<const sim::Renderer> renderer;
    };
    std::vector<Job> jobs;
    if (family) {
      const sim::FamilyScene scene = sim::makeFamilyScene(seed, length);
      const std::string stem = "family_" + std::to_string(seed);
      const std::string yaml_path = (out_dir / (stem + ".yaml")).string();
      std::ofstream yaml(yaml_path);
      yaml << "# " << scene.summary << "\n" << act_color::core::toYaml(scene.calibration);
      if (!yaml.flush()) throw std::runtime_error("cannot write " + yaml_path);
      std::printf("%s\nwrote %s\n", scene.summary.c_str(), yaml_path.c_str());
      jobs.push_back({stem, scene.scenario, std::make_shared<const sim::Renderer>(scene.calibration, scene.renderer)});
    } else {
      const auto renderer = std::make_shared<const sim::Renderer>(calibration);
      for (const std::string& name : names) {
        jobs.push_back({name + "_" + length_name, sim::makeScenario(name, length, calibration, seed), renderer});
      }
    }
    for (const Job& job : jobs) {
      const sim::Scenario& scenario = job.scenario;
      const sim::Renderer& renderer = *job.renderer;
      const std::string path = (out_dir / (job.stem + ".bag")).string();
      rosbag::Bag bag(path, rosbag::bagmode::Write);
      bag.setCompression(compression);
      std::string event_list;
      std::set<std::string> png_events;
      double render_ms = 0.0;
      for (size_t i = 0; i < scenario.frames.size(); ++i) {
        const sim::ScenarioFrame& frame = scenario.frames[i];
        const ros::Time stamp =
            kStartTime + ros::Duration().fromNSec(static_cast<int64_t>(i) * 1000000000LL /
                                                  static_cast<int64_t>(std::lround(scenario.frame_rate_hz)));
        const auto start = std::chrono::steady_clock::now();
        const sim::LabeledFrame rendered = renderer.render(frame.scene);
        render_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();

        std_msgs::Header header;
        header.stamp = stamp;
        header.seq = static_cast<uint32_t>(i);
        header.frame_id = "omni_camera";
        bag.write("/omni/image_raw", stamp, toImage(rendered.rgb, "rgb8", header));
        bag.write("/omni/labels_truth", stamp, toImage(rendered.labels, "mono8", header));
        bag.write("/localization/pose", stamp, toPoseMsg(frame.told_pose, stamp, 0.05, 0.03));
        bag.write("/omni/pose_truth", stamp, toPoseMsg(frame.scene.robot_pose, stamp, 0.0, 0.0));
        tf2_msgs::TFMessage tf;
        geometry_msgs::TransformStamped transform;
        transform.header.stamp = stamp;
        transform.header.frame_id = "field";
        transform.child_frame_id = "base_link";
        const geometry_msgs::Pose told = toPose(frame.told_pose);
        transform.transform.translation.x = told.position.x;
        transform.transform.translation.y = told.position.y;
        transform.transform.translation.z = told.position.z;
        transform.transform.rotation = told.orientation;
        tf.transforms.push_back(transform);
        bag.write("/tf", stamp, tf);
        for (const std::string& event : frame.events) {
          std_msgs::String msg;
          msg.data = event;
          bag.write("/scenario/events", stamp, msg);
          if (event_list.size() < 200) event_list += (event_list.empty() ? "" : " ") + event + "@" + std::to_string(i);
        }
        // The first frame, and the first frame of each kind of event.
        bool first_of_event = false;
        for (const std::string& event : frame.events) first_of_event |= png_events.insert(event).second;
        if (!png_dir.empty() && (i == 0 || first_of_event)) {
          const std::string stem = (png_dir / (job.stem + "_" + std::to_string(i))).string();
          writePng(stem + "_image.png", rendered.rgb);
          cv::Mat colored;
          act_color::core::colorizeLabels(rendered.labels, colored);
          writePng(stem + "_truth.png", colored);
        }
      }
      bag.close();
      std::printf("wrote %s: %zu frames at %.0f Hz, %.1f ms/frame rendering, events: %s\n", path.c_str(),
                  scenario.frames.size(), scenario.frame_rate_hz,
                  render_ms / std::max<size_t>(1, scenario.frames.size()),
                  event_list.empty() ? "none" : event_list.c_str());
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::cerr << "act_make_scenarios: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
