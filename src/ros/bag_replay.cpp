#include "act_color/ros/bag_replay.hpp"

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <ros/exception.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include "act_color/core/file_io.hpp"
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
  if (!cv::imwrite(path, out)) throw ReplayError(path + ": cannot be written");
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

// A message of the bag as T; instantiate() gives null for another definition (md5sum) of the type.
template <class T>
boost::shared_ptr<T> instantiate(const rosbag::MessageInstance& m, const std::string& path) {
  boost::shared_ptr<T> msg = m.instantiate<T>();
  if (!msg) {
    throw ReplayError(path + ": a message on " + m.getTopic() + " is a " + m.getDataType() +
                      " of another definition (md5sum " + m.getMD5Sum() + ", expected " +
                      ros::message_traits::MD5Sum<T>::value() + ")");
  }
  return msg;
}

std::string where(const std::string& topic, const ros::Time& stamp, size_t frame) {
  std::ostringstream s;
  s << topic << " at " << stamp << " (frame " << frame << ")";
  return s.str();
}

// What to do about a bag that rosbag cannot read: most often one cut short (the recorder killed,
// the disk full), whose index at the end of the file is missing.
std::string reindexHint(const std::string& path) {
  const std::filesystem::path p(path);
  const std::string backup = (p.parent_path() / p.stem()).string() + ".orig" + p.extension().string();
  return "it is truncated or corrupt; a bag cut short (a recording that was killed, a full disk) is usually recovered "
         "with `rosbag reindex " +
         path + "` (which keeps the original as " + backup + ")";
}

// rosbag's own magic line: tells "not a bag at all" from a damaged bag.
bool startsLikeABag(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  char head[9] = {};
  file.read(head, sizeof(head));
  return file && std::string(head, sizeof(head)) == "#ROSBAG V";
}

// The output bag: written as PATH.active and renamed to PATH by commit(), removed when the replay
// fails, so that no half-written bag is left looking complete.
class OutputBag {
 public:
  explicit OutputBag(const std::string& path) : path_(path), active_(path + ".active") {
    std::remove(path_.c_str());  // an older OUT.bag would look like this run's result
    try {
      bag_.open(active_, rosbag::bagmode::Write);
    } catch (const rosbag::BagException& e) {
      throw ReplayError(path_ + ": cannot be written: " + e.what());
    }
  }
  OutputBag(const OutputBag&) = delete;
  OutputBag& operator=(const OutputBag&) = delete;
  ~OutputBag() {
    if (committed_) return;
    try {
      bag_.close();
    } catch (const std::exception&) {
      // Removed below anyway.
    }
    std::remove(active_.c_str());
  }
  rosbag::Bag& bag() { return bag_; }
  void commit() {
    try {
      bag_.close();
    } catch (const rosbag::BagException& e) {
      throw ReplayError(path_ + ": cannot be written: " + e.what());
    }
    if (std::rename(active_.c_str(), path_.c_str()) != 0) {
      throw ReplayError(path_ + ": cannot be written: renaming " + active_ + " failed: " + std::strerror(errno));
    }
    committed_ = true;
  }

 private:
  std::string path_, active_;
  rosbag::Bag bag_;
  bool committed_ = false;
};

}  // namespace

std::string truthMessageProblem(const sensor_msgs::Image& truth, uint32_t width, uint32_t height) {
  if (truth.encoding != "mono8") return "truth encoding '" + truth.encoding + "', expected mono8";
  if (truth.width != width || truth.height != height) {
    return "truth is " + std::to_string(truth.width) + "x" + std::to_string(truth.height) + ", its image " +
           std::to_string(width) + "x" + std::to_string(height);
  }
  const std::string problem = ros_conversions::imageLayoutProblem(truth, 1);
  if (!problem.empty()) return "truth " + problem;
  // Class ids of the contract only (0-6, 255 not imaged): another value is no truth.
  for (uint32_t v = 0; v < height; ++v) {
    const uint8_t* row = truth.data.data() + static_cast<size_t>(v) * truth.step;
    for (uint32_t u = 0; u < width; ++u) {
      if (row[u] >= core::kNumClasses && row[u] != core::kNotImaged) {
        return "truth holds " + std::to_string(row[u]) + " at (" + std::to_string(u) + ", " + std::to_string(v) +
               "), not a class id (0-6, 255 not imaged)";
      }
    }
  }
  return "";
}

namespace {

// The replay proper; runReplay() turns rosbag's and the deserializer's exceptions into ReplayError.
// *writing_output: a partial output bag exists (and is removed when this throws); *frame: the
// image being read.
ReplayResult replay(const ReplayOptions& options, const core::Calibration& calibration, rosbag::Bag& in,
                    std::ostream& log, bool* writing_output, size_t* frame) {
  const std::string& path = options.input_bag;
  const size_t image_count = countTopic(in, options.image_topic, "sensor_msgs/Image", path);
  if (image_count == 0) {
    throw ReplayError(path + ": no messages on the image topic " + options.image_topic +
                      "; topics in the bag: " + topicList(in));
  }
  if (countTopic(in, options.pose_topic, "geometry_msgs/PoseWithCovarianceStamped", path) == 0) {
    throw ReplayError(path + ": no messages on the pose topic " + options.pose_topic +
                      "; topics in the bag: " + topicList(in));
  }
  countTopic(in, options.truth_topic, "sensor_msgs/Image", path);
  countTopic(in, options.events_topic, "std_msgs/String", path);

  auto warn = [&log](size_t seen_before, const char* kind, const std::string& message) {
    constexpr size_t kShown = 5;
    if (seen_before < kShown) log << "act_replay: warning: " << message << "\n";
    if (seen_before + 1 == kShown) log << "act_replay: further " << kind << " are only counted\n";
  };

  // Poses by stamp (small), truth and events indexed by stamp and read when needed. A pose that is
  // no robot's on this field (NaN, tilted, off the field and its margin, as the nodelets check) is
  // not used, and said why.
  const core::PoseBounds bounds(calibration.field);
  std::vector<StampedPose> poses;
  size_t unusable_poses = 0;
  for (const rosbag::MessageInstance& m : rosbag::View(in, rosbag::TopicQuery(options.pose_topic))) {
    const auto msg = instantiate<geometry_msgs::PoseWithCovarianceStamped>(m, path);
    StampedPose p{msg->header.stamp, false, {}};
    std::string error;
    p.valid = ros_conversions::pose2D(msg->pose.pose, &p.pose, &error);
    if (p.valid) p.valid = bounds.contains(p.pose.x_m, p.pose.y_m, &error);
    if (!p.valid) {
      std::ostringstream at;
      at << options.pose_topic << " at " << p.stamp << ": " << error << "; not used";
      warn(unusable_poses++, "unusable poses", at.str());
    }
    poses.push_back(p);
  }
  std::stable_sort(poses.begin(), poses.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
  std::map<ros::Time, rosbag::MessageInstance> truth_by_stamp;
  for (const rosbag::MessageInstance& m : rosbag::View(in, rosbag::TopicQuery(options.truth_topic))) {
    const auto header = instantiate<sensor_msgs::Image>(m, path)->header;
    truth_by_stamp.emplace(header.stamp, m);
  }
  std::vector<std::pair<ros::Time, std::string>> events;
  for (const rosbag::MessageInstance& m : rosbag::View(in, rosbag::TopicQuery(options.events_topic))) {
    events.emplace_back(m.getTime(), instantiate<std_msgs::String>(m, path)->data);
  }

  OutputBag out(options.output_bag);
  *writing_output = true;

  core::ActTrainer trainer(calibration, options.params);
  auto segmenter = std::make_unique<const core::Segmenter>(calibration.camera);
  // --learn-self-mask: learned and used from the next frame on as the trainer's ~learn_self_mask
  // does (core::SelfMaskHandOver), so that a replay gives the figures of the robot.
  std::unique_ptr<core::SelfMaskLearner> self_mask;
  std::unique_ptr<core::SelfMaskHandOver> hand_over;
  if (!options.self_mask_png.empty()) {
    self_mask = std::make_unique<core::SelfMaskLearner>(calibration);
    hand_over = std::make_unique<core::SelfMaskHandOver>(calibration);
  }
  ReplayResult result;
  result.evaluation = core::RunEvaluation(options.adapt_frames);
  cv::Mat labels(calibration.camera.height, calibration.camera.width, CV_8UC1);
  bool bootstrapped = false;
  size_t next_event = 0;
  auto last_progress = std::chrono::steady_clock::now();
  // The first few of each kind in full, then only counted (the summary has the totals).
  for (const rosbag::MessageInstance& m : rosbag::View(in, rosbag::TopicQuery(options.image_topic))) {
    *frame = result.images;
    const auto image = instantiate<sensor_msgs::Image>(m, path);
    const ros::Time stamp = image->header.stamp;
    while (next_event < events.size() && events[next_event].first <= stamp) {
      result.evaluation.markEvent(events[next_event++].second);
    }
    // The pose nearest in time at or before the image.
    auto after = std::upper_bound(poses.begin(), poses.end(), stamp,
                                  [](const ros::Time& t, const StampedPose& p) { return t < p.stamp; });
    const StampedPose* pose = after == poses.begin() ? nullptr : &*(after - 1);

    // Nothing of the message is read before it has been checked against itself.
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
      warn(result.unusable_images++, "unusable images",
           where(options.image_topic, stamp, result.images) + ": " + error +
               "; labelled all unknown, not trained, left out of the metrics");
      labels.setTo(core::kUnknown);
    } else {
      core::CycleStats stats;  // sees no ball without a cycle
      if (pose && pose->valid) {
        if (!bootstrapped) {
          trainer.bootstrap(view, pose->pose, std::max(0, options.bootstrap_cycles - 1));
          bootstrapped = true;
        }
        stats = trainer.cycle(view, pose->pose);
        result.pose_contradicted += stats.pose_contradicted;
        ++result.trained;
        if (self_mask) self_mask->add(view, pose->pose, trainer.lut());
      } else {
        ++result.without_pose;
      }
      segmenter->classify(trainer.lut(), view, labels);
      trainer.unlabelBeyondCarpet(labels);
      trainer.labelBall(stats, labels);
      if (hand_over) {
        if (std::optional<core::Calibration> masked = hand_over->next(*self_mask)) {
          trainer.replaceModel(core::ExpectedClassModel(*masked));
          segmenter = std::make_unique<const core::Segmenter>(masked->camera);
          if (result.self_masks_used++ == 0) result.self_mask_first_frame = result.images + 1;
          result.self_mask_used_pixels = hand_over->pixels();
        }
      }
    }
    out.bag().write("/segmentation/labels", m.getTime(), ros_conversions::labelsToMsg(labels, image->header));
    if (result.images % options.lut_every == 0) {
      std_msgs::Header header = image->header;
      out.bag().write("/act/color_lut", m.getTime(), ros_conversions::toMsg(trainer, header));
    }
    const auto truth_it = truth_by_stamp.find(stamp);
    sensor_msgs::ImageConstPtr truth;
    cv::Mat truth_mat;
    if (truth_it != truth_by_stamp.end()) {
      truth = instantiate<sensor_msgs::Image>(truth_it->second, path);
      const std::string problem = truthMessageProblem(*truth, image->width, image->height);
      if (!problem.empty()) {
        ++result.truth_left_out;
        warn(result.unusable_truth++, "unusable truth images",
             where(options.truth_topic, stamp, result.images) + ": " + problem +
                 "; the frame's labels are written, the frame is left out of the metrics");
      } else if (!usable) {
        ++result.truth_left_out;
      } else {
        // Checked above: step and data cover height rows of width bytes.
        truth_mat =
            cv::Mat(truth->height, truth->width, CV_8UC1, const_cast<uint8_t*>(truth->data.data()), truth->step);
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
  out.commit();
  *writing_output = false;
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

}  // namespace

ReplayResult runReplay(const ReplayOptions& options, std::ostream& log) {
  const core::Calibration calibration = core::loadCalibration(options.calibration);
  if (options.lut_every == 0) throw ReplayError("--lut-every must be at least 1");
  std::error_code ec;
  if (std::string error; !options.png_dir.empty() && !core::makeFolder(options.png_dir, &error)) {
    throw ReplayError("--png: " + error);
  }
  if (std::filesystem::equivalent(options.input_bag, options.output_bag, ec)) {
    throw ReplayError(options.output_bag + ": is the input bag; choose another --output");
  }
  const std::string& path = options.input_bag;
  if (!std::ifstream(path)) throw ReplayError(path + ": cannot be opened: " + std::strerror(errno));
  rosbag::Bag in;
  try {
    in.open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    if (!startsLikeABag(path)) throw ReplayError(path + ": cannot be read as a bag: not a rosbag file");
    throw ReplayError(path + ": cannot be read as a bag (" + e.what() + "): " + reindexHint(path));
  }
  bool writing_output = false;
  size_t frame = 0;
  // The partial output bag has been removed by the time these run.
  const std::string not_written = "; " + options.output_bag + " not written (the partial output was removed)";
  try {
    return replay(options, calibration, in, log, &writing_output, &frame);
  } catch (const ros::Exception& e) {
    // rosbag::BagException (a chunk or record that cannot be read), or the deserializer running
    // past a message's end: the file is damaged.
    std::string message = path + ": reading failed";
    if (writing_output) message += " at frame " + std::to_string(frame);
    message += " (" + std::string(e.what()) + "): " + reindexHint(path);
    throw ReplayError(writing_output ? message + not_written : message);
  } catch (const std::exception& e) {
    if (!writing_output) throw;
    throw ReplayError(e.what() + not_written);
  }
}

}  // namespace ros_layer
}  // namespace act_color
