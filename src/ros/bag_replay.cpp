#include "act_color/ros/bag_replay.hpp"

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <vector>

#include "act_color/core/omni_camera_model.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/core/self_mask_learner.hpp"
#include "act_color/ros/conversions.hpp"

namespace act_color {
namespace ros_layer {
namespace {

struct StampedPose {
  ros::Time stamp;
  bool valid;
  core::Pose2D pose;
};

// input | classified | truth (when there is one), written as PNG.
void writeSideBySide(const std::string& path, const sensor_msgs::Image& image, const cv::Mat& labels,
                     const cv::Mat* truth) {
  cv::Mat rgb;  // BGR for imwrite
  if (image.encoding == "rgb8" || image.encoding == "bgr8") {
    const cv::Mat in(image.height, image.width, CV_8UC3, const_cast<uint8_t*>(image.data.data()), image.step);
    if (image.encoding == "rgb8") {
      cv::cvtColor(in, rgb, cv::COLOR_RGB2BGR);
    } else {
      in.copyTo(rgb);
    }
  } else {
    const cv::Mat in(image.height, image.width, CV_8UC2, const_cast<uint8_t*>(image.data.data()), image.step);
    cv::cvtColor(in, rgb, cv::COLOR_YUV2BGR_UYVY);
  }
  std::vector<cv::Mat> panels = {rgb};
  for (const cv::Mat* l : {&labels, truth}) {
    if (!l) continue;
    cv::Mat colored;
    core::colorizeLabels(*l, colored);
    cv::cvtColor(colored, colored, cv::COLOR_RGB2BGR);
    panels.push_back(colored);
  }
  cv::Mat out;
  cv::hconcat(panels, out);
  cv::imwrite(path, out);
}

std::string topicList(const rosbag::Bag& bag) {
  rosbag::View all(bag);
  std::set<std::string> topics;
  for (const rosbag::ConnectionInfo* c : all.getConnections()) topics.insert(c->topic + " (" + c->datatype + ")");
  std::string out;
  for (const auto& t : topics) out += (out.empty() ? "" : ", ") + t;
  return out.empty() ? "none" : out;
}

// Checks that `topic` holds messages of `type`; returns their number (0 when absent).
size_t countTopic(const rosbag::Bag& bag, const std::string& topic, const std::string& type, const std::string& path) {
  rosbag::View view(bag, rosbag::TopicQuery(topic));
  for (const rosbag::ConnectionInfo* c : view.getConnections()) {
    if (c->datatype != type) {
      throw ReplayError(path + ": topic " + topic + " has type " + c->datatype + ", expected " + type);
    }
  }
  return view.size();
}

}  // namespace

ReplayResult runReplay(const ReplayOptions& options, std::ostream& log) {
  const core::Calibration calibration = core::loadCalibration(options.calibration);
  if (options.lut_every == 0) throw ReplayError("--lut-every must be at least 1");
  rosbag::Bag in;
  try {
    in.open(options.input_bag, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw ReplayError(options.input_bag + ": cannot be read as a bag: " + e.what());
  }
  const size_t image_count = countTopic(in, options.image_topic, "sensor_msgs/Image", options.input_bag);
  if (image_count == 0) {
    throw ReplayError(options.input_bag + ": no messages on the image topic " + options.image_topic +
                      "; topics in the bag: " + topicList(in));
  }
  if (countTopic(in, options.pose_topic, "geometry_msgs/PoseWithCovarianceStamped", options.input_bag) == 0) {
    throw ReplayError(options.input_bag + ": no messages on the pose topic " + options.pose_topic +
                      "; topics in the bag: " + topicList(in));
  }
  countTopic(in, options.truth_topic, "sensor_msgs/Image", options.input_bag);
  countTopic(in, options.events_topic, "std_msgs/String", options.input_bag);

  // Poses by stamp (small), truth and events indexed by stamp and read when needed.
  std::vector<StampedPose> poses;
  for (const rosbag::MessageInstance& m : rosbag::View(in, rosbag::TopicQuery(options.pose_topic))) {
    const auto msg = m.instantiate<geometry_msgs::PoseWithCovarianceStamped>();
    StampedPose p{msg->header.stamp, false, {}};
    std::string error;
    p.valid = ros_conversions::pose2D(msg->pose.pose, &p.pose, &error);
    poses.push_back(p);
  }
  std::stable_sort(poses.begin(), poses.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
  std::map<ros::Time, rosbag::MessageInstance> truth_by_stamp;
  for (const rosbag::MessageInstance& m : rosbag::View(in, rosbag::TopicQuery(options.truth_topic))) {
    const auto header = m.instantiate<sensor_msgs::Image>()->header;
    truth_by_stamp.emplace(header.stamp, m);
  }
  std::vector<std::pair<ros::Time, std::string>> events;
  for (const rosbag::MessageInstance& m : rosbag::View(in, rosbag::TopicQuery(options.events_topic))) {
    events.emplace_back(m.getTime(), m.instantiate<std_msgs::String>()->data);
  }

  rosbag::Bag out;
  try {
    out.open(options.output_bag, rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    throw ReplayError(options.output_bag + ": cannot be written: " + e.what());
  }

  core::ActTrainer trainer(calibration, options.params);
  const core::Segmenter segmenter(calibration.camera);
  std::unique_ptr<core::SelfMaskLearner> self_mask;
  if (!options.self_mask_png.empty()) self_mask = std::make_unique<core::SelfMaskLearner>(calibration);
  ReplayResult result;
  result.evaluation = core::RunEvaluation(options.adapt_frames);
  cv::Mat labels(calibration.camera.height, calibration.camera.width, CV_8UC1);
  bool bootstrapped = false;
  size_t next_event = 0;
  auto last_progress = std::chrono::steady_clock::now();

  for (const rosbag::MessageInstance& m : rosbag::View(in, rosbag::TopicQuery(options.image_topic))) {
    const auto image = m.instantiate<sensor_msgs::Image>();
    const ros::Time stamp = image->header.stamp;
    while (next_event < events.size() && events[next_event].first <= stamp) {
      result.evaluation.markEvent(events[next_event++].second);
    }
    // The pose nearest in time at or before the image.
    auto after = std::upper_bound(poses.begin(), poses.end(), stamp,
                                  [](const ros::Time& t, const StampedPose& p) { return t < p.stamp; });
    const StampedPose* pose = after == poses.begin() ? nullptr : &*(after - 1);

    core::ImageView view;
    std::string error;
    bool usable = ros_conversions::imageView(*image, &view, &error);
    if (usable) {
      try {
        trainer.checkImage(view);
      } catch (const std::invalid_argument& e) {
        error = e.what();
        usable = false;
      }
    }
    if (!usable) {
      if (result.unusable_images++ < 5) log << "act_replay: frame " << result.images << ": " << error << "\n";
      labels.setTo(core::kUnknown);
    } else {
      if (pose && pose->valid) {
        if (!bootstrapped) {
          trainer.bootstrap(view, pose->pose, std::max(0, options.bootstrap_cycles - 1));
          bootstrapped = true;
        }
        trainer.cycle(view, pose->pose);
        ++result.trained;
        if (self_mask) self_mask->add(view, pose->pose, trainer.lut());
      } else {
        ++result.without_pose;
      }
      segmenter.classify(trainer.lut(), view, labels);
    }
    out.write("/segmentation/labels", m.getTime(), ros_conversions::labelsToMsg(labels, image->header));
    if (result.images % options.lut_every == 0) {
      std_msgs::Header header = image->header;
      out.write("/act/color_lut", m.getTime(), ros_conversions::toMsg(trainer, header));
    }
    const auto truth_it = truth_by_stamp.find(stamp);
    cv::Mat truth_mat;
    if (truth_it != truth_by_stamp.end()) {
      const auto truth = truth_it->second.instantiate<sensor_msgs::Image>();
      if (truth->encoding == "mono8" && truth->width == image->width && truth->height == image->height) {
        truth_mat = cv::Mat(truth->height, truth->width, CV_8UC1, truth->data.data(), truth->step).clone();
        result.evaluation.addFrame(labels, truth_mat);
        ++result.with_truth;
      }
    }
    if (!options.png_dir.empty() && usable && result.images % options.png_every == 0) {
      char name[64];
      std::snprintf(name, sizeof(name), "/frame_%05zu.png", result.images);
      writeSideBySide(options.png_dir + name, *image, labels, truth_mat.empty() ? nullptr : &truth_mat);
    }
    ++result.images;
    const auto now = std::chrono::steady_clock::now();
    if (options.progress && now - last_progress > std::chrono::seconds(2)) {
      std::cerr << "act_replay: frame " << result.images << "/" << image_count << "\n";
      last_progress = now;
    }
  }
  out.close();
  if (self_mask) {
    core::CameraCalibration camera = calibration.camera;
    camera.self_mask = self_mask->mask();
    if (camera.self_mask.empty()) throw ReplayError("no frame with a pose: no self mask learned");
    try {
      core::saveSelfMask(camera, options.self_mask_png);
    } catch (const core::CalibrationError& e) {
      throw ReplayError(e.what());
    }
    const core::OmniCameraModel model(calibration.camera);
    size_t imaged = 0, masked = 0;
    for (size_t i = 0; i < camera.self_mask.size(); ++i) {
      if (model.ray(i).region == core::PixelRegion::kNotImaged) continue;
      ++imaged;
      masked += camera.self_mask[i];
    }
    result.self_mask_poses = self_mask->frames();
    result.self_mask_fraction = imaged ? static_cast<double>(masked) / imaged : 0.0;
  }
  if (!options.csv_path.empty()) {
    std::ofstream csv(options.csv_path);
    if (!csv) throw ReplayError(options.csv_path + ": cannot be written");
    csv << result.evaluation.csv();
  }
  return result;
}

}  // namespace ros_layer
}  // namespace act_color
