// act_replay end to end, without a master: scenario bags written by act_make_scenarios, replayed
// through runReplay() and the act_replay executable.
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "act_color/ColorLut.h"
#include "act_color/core/calibration.hpp"
#include "act_color/ros/bag_replay.hpp"
#include "act_color/ros/conversions.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scene_family.hpp"
#include "tool_test_util.hpp"

using act_color::ros_layer::ReplayError;
using act_color::ros_layer::ReplayOptions;
using act_color::ros_layer::runReplay;
namespace sim = act_color::sim;

namespace {

const std::string kCalibration = std::string(ACT_SOURCE_DIR) + "/config/calibration/msl_2007_580.yaml";

std::string tempDir() { return act_color_tool_test::tempDir("act_replay_test"); }

// The small scenario bag, written once per test run.
std::string scenarioBag(const std::string& name) {
  const std::string bag = tempDir() + "/" + name + "_small.bag";
  if (!std::ifstream(bag)) {
    const std::string command = std::string(ACT_TOOLS_DIR) + "/act_make_scenarios --calibration " + kCalibration +
                                " --scenario " + name + " --length small --output-dir " + tempDir() + " > /dev/null";
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
  }
  return bag;
}

using act_color_tool_test::readText;

// Runs a shell command with stdout and stderr into *output; returns its exit status.
int run(const std::string& command, std::string* output) {
  const std::string file = tempDir() + "/command_output.txt";
  const int status = std::system((command + " > " + file + " 2>&1").c_str());
  *output = readText(file);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// Changes an image or truth message of the copy; false drops it.
using Mutation = std::function<bool(const std::string& topic, size_t frame, sensor_msgs::Image& image)>;

// The first `frames` frames of `in` (every message stamped at or before the last of their
// images), uncompressed, with `mutate` applied to each image and truth message (`frame`: the
// image's index). With images_last, every image is written after all other messages, so that the
// last chunks of the file hold images only.
void copyBag(const std::string& in, const std::string& out, size_t frames, const Mutation& mutate,
             bool images_last = false) {
  rosbag::Bag input(in);
  std::vector<ros::Time> image_times;
  for (const auto& m : rosbag::View(input, rosbag::TopicQuery("/omni/image_raw"))) image_times.push_back(m.getTime());
  ASSERT_GE(image_times.size(), frames);
  const ros::Time last = image_times[frames - 1];
  rosbag::Bag output(out, rosbag::bagmode::Write);
  auto frameOf = [&](const ros::Time& t) {
    return static_cast<size_t>(std::lower_bound(image_times.begin(), image_times.end(), t) - image_times.begin());
  };
  for (int pass = 0; pass < (images_last ? 2 : 1); ++pass) {
    for (const auto& m : rosbag::View(input, ros::TIME_MIN, last)) {
      const bool is_image = m.getTopic() == "/omni/image_raw";
      if (images_last && is_image != (pass == 1)) continue;
      if (is_image || m.getTopic() == "/omni/labels_truth") {
        auto image = m.instantiate<sensor_msgs::Image>();
        if (mutate(m.getTopic(), frameOf(m.getTime()), *image)) output.write(m.getTopic(), m.getTime(), image);
      } else {
        output.write(m.getTopic(), m.getTime(), m);
      }
    }
  }
}

const Mutation kUnchanged = [](const std::string&, size_t, sensor_msgs::Image&) { return true; };

// The stamp of image `frame` as act_replay prints it.
std::string imageStamp(const std::string& bag, size_t frame) {
  rosbag::Bag input(bag);
  size_t i = 0;
  for (const auto& m : rosbag::View(input, rosbag::TopicQuery("/omni/image_raw"))) {
    if (i++ == frame) {
      std::ostringstream s;
      s << m.instantiate<sensor_msgs::Image>()->header.stamp;
      return s.str();
    }
  }
  return "no such frame";
}

bool exists(const std::string& path) { return std::filesystem::exists(path); }

ReplayOptions options(const std::string& in, const std::string& out) {
  ReplayOptions o;
  o.input_bag = in;
  o.calibration = kCalibration;
  o.output_bag = out;
  o.progress = false;
  return o;
}

}  // namespace

TEST(ActReplay, LabelsEveryFrameStampedAsItsImage) {
  const std::string in = scenarioBag("static_darkening");
  const std::string out = tempDir() + "/labels.bag";
  std::ostringstream log;
  const auto result = runReplay(options(in, out), log);
  EXPECT_EQ(result.images, 32u);
  EXPECT_EQ(result.trained, 32u);
  EXPECT_EQ(result.with_truth, 32u);

  rosbag::Bag input(in), output(out);
  std::vector<ros::Time> image_stamps, label_stamps, lut_stamps;
  for (const auto& m : rosbag::View(input, rosbag::TopicQuery("/omni/image_raw"))) {
    image_stamps.push_back(m.instantiate<sensor_msgs::Image>()->header.stamp);
  }
  for (const auto& m : rosbag::View(output, rosbag::TopicQuery("/segmentation/labels"))) {
    const auto labels = m.instantiate<sensor_msgs::Image>();
    EXPECT_EQ(labels->encoding, "mono8");
    EXPECT_EQ(labels->width, 580u);
    label_stamps.push_back(labels->header.stamp);
  }
  uint64_t last_revision = 0;
  for (const auto& m : rosbag::View(output, rosbag::TopicQuery("/act/color_lut"))) {
    const auto lut = m.instantiate<act_color::ColorLut>();
    EXPECT_EQ(lut->bits_per_channel, 6);
    EXPECT_EQ(lut->table.size(), 262144u);
    EXPECT_GT(lut->revision, last_revision);
    last_revision = lut->revision;
    lut_stamps.push_back(lut->header.stamp);
  }
  EXPECT_EQ(label_stamps, image_stamps);
  EXPECT_EQ(lut_stamps, image_stamps);
}

TEST(ActReplay, ReachesTheAccuracyOfIssueThreeAfterDarkening) {
  std::ostringstream log;
  const auto result = runReplay(options(scenarioBag("static_darkening"), tempDir() + "/dark.bag"), log);
  const auto adapted = result.evaluation.adapted();
  for (int k : {act_color::core::kGreen, act_color::core::kWhite}) {
    EXPECT_GE(adapted.recall(k), 0.90) << act_color::core::className(k);
  }
  for (int k : {act_color::core::kYellow, act_color::core::kBlue, act_color::core::kBlack}) {
    EXPECT_GE(adapted.recall(k), 0.80) << act_color::core::className(k);
  }
  for (int k : act_color::core::trainableClasses()) {
    EXPECT_GE(adapted.precision(k), 0.80) << act_color::core::className(k);
  }
  const auto segments = result.evaluation.segments();
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_EQ(segments[1].event, "darken");
  // Light compensation: green recovers in the first cycle after the darkening.
  EXPECT_LE(segments[1].settle_cycles[act_color::core::kGreen], 2);
  EXPECT_GE(segments[1].settle_cycles[act_color::core::kGreen], 1);
}

TEST(ActReplay, AWrongPoseDoesNotSpoilTheTable) {
  std::ostringstream log;
  const auto result = runReplay(options(scenarioBag("wrong_pose"), tempDir() + "/wrong.bag"), log);
  // Every third frame from frame 2 is told the wrong pose: those are refused (pose_check), the
  // others train.
  EXPECT_GE(result.pose_contradicted, 6u);
  EXPECT_LE(result.pose_contradicted, 10u);
  const auto adapted = result.evaluation.adapted();
  EXPECT_GE(adapted.recall(act_color::core::kGreen), 0.95);
  EXPECT_GE(adapted.recall(act_color::core::kWhite), 0.90);
  for (int k : {act_color::core::kYellow, act_color::core::kBlue, act_color::core::kBlack}) {
    EXPECT_GE(adapted.recall(k), 0.80) << act_color::core::className(k);
    EXPECT_GE(adapted.precision(k), 0.80) << act_color::core::className(k);
  }
}

TEST(ActReplay, SameInputSameOutputBytes) {
  const std::string in = scenarioBag("static_darkening");
  const std::string tool = std::string(ACT_TOOLS_DIR) + "/act_replay --no-progress --calibration " + kCalibration +
                           " --bag " + in + " --output ";
  ASSERT_EQ(std::system((tool + tempDir() + "/a.bag > /dev/null").c_str()), 0);
  ASSERT_EQ(std::system((tool + tempDir() + "/b.bag > /dev/null").c_str()), 0);
  const std::string a = readText(tempDir() + "/a.bag");
  EXPECT_GT(a.size(), 1000000u);
  EXPECT_TRUE(a == readText(tempDir() + "/b.bag"));
  // Another seed gives other random start pixels, hence another table.
  ASSERT_EQ(std::system((tool + tempDir() + "/c.bag --seed 7 > /dev/null").c_str()), 0);
  EXPECT_FALSE(a == readText(tempDir() + "/c.bag"));
}

TEST(ActReplay, ClearErrorsForUnusableInput) {
  std::ostringstream log;
  const std::string in = scenarioBag("static_darkening");
  auto errorOf = [&](const ReplayOptions& o) -> std::string {
    try {
      runReplay(o, log);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "";
  };
  ReplayOptions o = options(in, tempDir() + "/x.bag");
  o.image_topic = "/camera/missing";
  EXPECT_NE(errorOf(o).find("no messages on the image topic /camera/missing"), std::string::npos);
  EXPECT_NE(errorOf(o).find("/omni/image_raw"), std::string::npos);  // lists what the bag has
  o = options(in, tempDir() + "/x.bag");
  o.pose_topic = "/omni/image_raw";
  EXPECT_NE(errorOf(o).find("has type sensor_msgs/Image"), std::string::npos);
  const std::string junk = tempDir() + "/junk.bag";
  std::ofstream(junk) << "this is not a bag";
  EXPECT_NE(errorOf(options(junk, tempDir() + "/x.bag")).find("cannot be read as a bag: not a rosbag file"),
            std::string::npos);
  EXPECT_NE(errorOf(options(tempDir() + "/missing.bag", tempDir() + "/x.bag")).find("cannot be opened"),
            std::string::npos);
  EXPECT_NE(errorOf(options(in, in)).find("is the input bag"), std::string::npos);
  o = options(in, tempDir() + "/x.bag");
  o.calibration = "/nonexistent.yaml";
  EXPECT_NE(errorOf(o).find("/nonexistent.yaml"), std::string::npos);
  // --png: the folder is made if missing; one that cannot be (under a file) is an error up front.
  o = options(in, tempDir() + "/x.bag");
  o.png_dir = tempDir() + "/replay_png/nested";
  o.png_every = 16;
  EXPECT_EQ(errorOf(o), "");
  EXPECT_TRUE(exists(o.png_dir + "/frame_00000.png"));
  EXPECT_TRUE(exists(o.png_dir + "/frame_00016.png"));
  o.png_dir = junk + "/png";
  EXPECT_NE(errorOf(o).find("--png: " + junk + "/png: cannot make the folder"), std::string::npos) << errorOf(o);
  // The executable: usage errors exit 2, unusable input 1.
  const std::string tool = std::string(ACT_TOOLS_DIR) + "/act_replay";
  EXPECT_EQ(WEXITSTATUS(std::system((tool + " --bag " + in + " 2> /dev/null").c_str())), 2);
  // Numbers read whole and in range (they wrapped or were clamped silently: --seed -1, --png-every 0).
  const std::string required = " --bag " + in + " --calibration " + kCalibration + " --output " + tempDir() + "/x.bag ";
  for (const auto& [option, said] : std::vector<std::pair<std::string, std::string>>{
           {"--seed -1", "--seed: '-1' is not an integer in [0, 4294967295]"},
           {"--png-every 0", "--png-every: '0' is not an integer in [1, 1000000000]"},
           {"--lut-every -1", "--lut-every: '-1' is not an integer"},
           {"--bootstrap-cycles -5", "--bootstrap-cycles: '-5' is not an integer in [0, 100000]"},
           {"--zeta abc", "--zeta: 'abc' is not a finite number"},
           {"--cluster-stride 99999999999", "--cluster-stride: '99999999999' is not an integer"}}) {
    std::string text;
    EXPECT_EQ(run(tool + required + option, &text), 2) << option;
    EXPECT_NE(text.find(said), std::string::npos) << option << ": " << text;
  }
  EXPECT_EQ(WEXITSTATUS(std::system((tool + " --bag " + junk + " --calibration " + kCalibration + " --output " +
                                     tempDir() + "/x.bag 2> /dev/null")
                                        .c_str())),
            1);
}

TEST(ActReplay, MessageChecksSayWhatIsWrong) {
  using act_color::ros_layer::imageMessageProblem;
  using act_color::ros_layer::truthMessageProblem;
  sensor_msgs::Image image;
  image.encoding = "rgb8";
  image.width = 4;
  image.height = 3;
  image.step = 12;
  image.data.resize(36);
  EXPECT_EQ(imageMessageProblem(image), "");
  image.step = 11;
  EXPECT_EQ(imageMessageProblem(image), "step 11 is less than width 4 * 3 bytes per pixel (rgb8) = 12");
  image.step = 16;
  EXPECT_EQ(imageMessageProblem(image), "data has 36 bytes, less than step 16 * height 3 = 48");
  image.encoding = "yuv422";
  image.width = 5;
  image.step = 10;
  image.data.resize(30);
  EXPECT_EQ(imageMessageProblem(image), "yuv422 image with an odd width 5");
  image.encoding = "mono16";
  EXPECT_NE(imageMessageProblem(image).find("unsupported encoding 'mono16'"), std::string::npos);
  image.encoding = "bgr8";
  image.height = 0;
  EXPECT_EQ(imageMessageProblem(image), "empty image (5x0)");
  // Huge sizes do not overflow the check: 4e9 rows of 4e9 bytes.
  image.width = image.height = image.step = 4000000000u;
  EXPECT_NE(imageMessageProblem(image), "");

  sensor_msgs::Image truth;
  truth.encoding = "mono8";
  truth.width = 4;
  truth.height = 3;
  truth.step = 4;
  truth.data.resize(11);
  EXPECT_EQ(truthMessageProblem(truth, 4, 3), "truth data has 11 bytes, less than step 4 * height 3 = 12");
  truth.data.resize(12);
  EXPECT_EQ(truthMessageProblem(truth, 4, 3), "");
  truth.data[6] = 255;  // not imaged
  EXPECT_EQ(truthMessageProblem(truth, 4, 3), "");
  truth.data[6] = 9;  // no class (it was scored as one)
  EXPECT_EQ(truthMessageProblem(truth, 4, 3), "truth holds 9 at (2, 1), not a class id (0-6, 255 not imaged)");
  truth.data[6] = 0;
  EXPECT_EQ(truthMessageProblem(truth, 4, 4), "truth is 4x3, its image 4x4");
  truth.step = 3;
  EXPECT_EQ(truthMessageProblem(truth, 4, 3), "truth step 3 is less than width 4 * 1 bytes per pixel (mono8) = 4");
  truth.encoding = "8UC1";
  EXPECT_EQ(truthMessageProblem(truth, 4, 3), "truth encoding '8UC1', expected mono8");
}

// A truth image shorter than step * height (issue 15): never read past its data; that frame's
// labels are written, the frame is left out of the metrics and the tool says so. Exit 0: the
// labels are complete.
TEST(ActReplay, ShortTruthIsLeftOutOfTheMetrics) {
  const std::string in = tempDir() + "/short_truth.bag";
  copyBag(scenarioBag("static_darkening"), in, 10, [](const std::string& topic, size_t frame, sensor_msgs::Image& m) {
    if (topic == "/omni/labels_truth" && frame == 3) m.data.resize(m.data.size() / 2);
    return true;
  });
  // The same frames without that truth message: what the metrics must equal.
  const std::string without = tempDir() + "/without_truth_3.bag";
  copyBag(scenarioBag("static_darkening"), without, 10,
          [](const std::string& topic, size_t frame, sensor_msgs::Image&) {
            return !(topic == "/omni/labels_truth" && frame == 3);
          });
  std::ostringstream log;
  const auto result = runReplay(options(in, tempDir() + "/short_truth.out.bag"), log);
  EXPECT_EQ(result.images, 10u);
  EXPECT_EQ(result.trained, 10u);
  EXPECT_EQ(result.with_truth, 9u);
  EXPECT_EQ(result.unusable_truth, 1u);
  EXPECT_EQ(result.truth_left_out, 1u);
  EXPECT_EQ(result.evaluation.frames(), 9u);
  EXPECT_NE(log.str().find("/omni/labels_truth at " + imageStamp(in, 3) +
                           " (frame 3): truth data has 168200 bytes, less than step 580 * height 580 = 336400"),
            std::string::npos)
      << log.str();
  std::ostringstream log_without;
  const auto reference = runReplay(options(without, tempDir() + "/without_truth_3.out.bag"), log_without);
  EXPECT_EQ(reference.with_truth, 9u);
  EXPECT_EQ(result.evaluation.overall().confusion(), reference.evaluation.overall().confusion());
  rosbag::Bag output(tempDir() + "/short_truth.out.bag");
  EXPECT_EQ(rosbag::View(output, rosbag::TopicQuery("/segmentation/labels")).size(), 10u);

  std::string text;
  const std::string tool = std::string(ACT_TOOLS_DIR) + "/act_replay --no-progress --brief --calibration " +
                           kCalibration + " --output " + tempDir() + "/short_truth.tool.bag --bag ";
  EXPECT_EQ(run(tool + in, &text), 0) << text;
  EXPECT_NE(
      text.find("10 frames from " + in + " (10 trained, 0 without a usable pose, 0 unusable images, 9 with truth)"),
      std::string::npos)
      << text;
  EXPECT_NE(text.find("1 of 10 frames with truth left out of the metrics (1 with a truth image that does not fit"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("green"), std::string::npos) << text;

  // No truth image fits (step too small): no metrics at all, said in words, not as numbers.
  const std::string none = tempDir() + "/no_truth_fits.bag";
  copyBag(scenarioBag("static_darkening"), none, 4, [](const std::string& topic, size_t, sensor_msgs::Image& m) {
    if (topic == "/omni/labels_truth") m.step = 100;
    return true;
  });
  EXPECT_EQ(run(tool + none, &text), 0) << text;
  EXPECT_NE(text.find("4 of 4 frames with truth left out of the metrics (4 with a truth image that does not fit"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("truth step 100 is less than width 580"), std::string::npos) << text;
  EXPECT_NE(text.find("no frame with truth on /omni/labels_truth: no metrics"), std::string::npos) << text;
  EXPECT_EQ(text.find("recall"), std::string::npos) << text;
  EXPECT_EQ(text.find("nan"), std::string::npos) << text;
}

// Poses that are no robot's on this field (1000 km off, z NaN): not used, each said why (they
// trained the table at that pose before, without a word).
TEST(ActReplay, PosesOffTheFieldAreNotUsed) {
  const std::string src = scenarioBag("static_darkening"), in = tempDir() + "/far_poses.bag";
  {
    rosbag::Bag input(src);
    std::vector<ros::Time> image_times;
    for (const auto& m : rosbag::View(input, rosbag::TopicQuery("/omni/image_raw"))) image_times.push_back(m.getTime());
    ASSERT_GE(image_times.size(), 6u);
    rosbag::Bag output(in, rosbag::bagmode::Write);
    size_t pose_index = 0;
    for (const auto& m : rosbag::View(input, ros::TIME_MIN, image_times[5])) {
      if (m.getTopic() != "/localization/pose") {
        output.write(m.getTopic(), m.getTime(), m);
        continue;
      }
      auto pose = m.instantiate<geometry_msgs::PoseWithCovarianceStamped>();
      if (pose_index >= 2) pose->pose.pose.position.x = 1e6;           // from the third pose on: far off
      if (pose_index == 1) pose->pose.pose.position.z = std::nan("");  // the second: no height
      ++pose_index;
      output.write(m.getTopic(), m.getTime(), pose);
    }
  }
  std::ostringstream log;
  const auto result = runReplay(options(in, tempDir() + "/far_poses.out.bag"), log);
  EXPECT_EQ(result.images, 6u);
  EXPECT_EQ(result.trained, 1u) << log.str();  // the first pose only
  EXPECT_NE(log.str().find("pose (1e+06, "), std::string::npos) << log.str();
  EXPECT_NE(log.str().find("m is off the field"), std::string::npos) << log.str();
  EXPECT_NE(log.str().find("pose has NaN or infinite values; not used"), std::string::npos) << log.str();
}

// What no robot's pose on the floor is (the nodelets and act_replay take none of it).
TEST(ActReplay, PosesOfNoRobotOnTheFloorAreRefused) {
  geometry_msgs::Pose pose;
  pose.position.x = 1.0;
  pose.orientation.w = 1.0;
  act_color::core::Pose2D out;
  std::string error;
  EXPECT_TRUE(act_color::ros_conversions::pose2D(pose, &out, &error)) << error;
  pose.position.z = 5000.0;
  EXPECT_FALSE(act_color::ros_conversions::pose2D(pose, &out, &error));
  EXPECT_EQ(error, "pose is 5000 m above the floor, a robot's base_link is not");
  pose.position.z = std::nan("");
  EXPECT_FALSE(act_color::ros_conversions::pose2D(pose, &out, &error));
  EXPECT_EQ(error, "pose has NaN or infinite values");
  pose.position.z = 0.0;
  pose.orientation.w = std::cos(0.25);  // rolled by 0.5 rad
  pose.orientation.x = std::sin(0.25);
  EXPECT_FALSE(act_color::ros_conversions::pose2D(pose, &out, &error));
  EXPECT_NE(error.find("tilted"), std::string::npos) << error;
}

// Images whose step is too small or whose data is short: labelled all unknown, not trained, left
// out of the metrics, each named by topic, stamp and what is wrong. Exit 0 while some image is
// usable, 1 when none is.
TEST(ActReplay, ImagesThatDoNotFitTheirStepAreSkipped) {
  const std::string in = tempDir() + "/bad_images.bag";
  copyBag(scenarioBag("static_darkening"), in, 10, [](const std::string& topic, size_t frame, sensor_msgs::Image& m) {
    if (topic == "/omni/image_raw" && frame == 3) m.step = m.width;
    if (topic == "/omni/image_raw" && frame == 5) m.data.resize(1000);
    return true;
  });
  std::ostringstream log;
  const auto result = runReplay(options(in, tempDir() + "/bad_images.out.bag"), log);
  EXPECT_EQ(result.images, 10u);
  EXPECT_EQ(result.unusable_images, 2u);
  EXPECT_EQ(result.trained, 8u);
  EXPECT_EQ(result.with_truth, 8u);
  EXPECT_EQ(result.truth_left_out, 2u);
  EXPECT_EQ(result.unusable_truth, 0u);
  EXPECT_NE(log.str().find("/omni/image_raw at " + imageStamp(in, 3) +
                           " (frame 3): step 580 is less than width 580 * 3 bytes per pixel (rgb8) = 1740"),
            std::string::npos)
      << log.str();
  EXPECT_NE(log.str().find("/omni/image_raw at " + imageStamp(in, 5) +
                           " (frame 5): data has 1000 bytes, less than step 1740 * height 580 = 1009200"),
            std::string::npos)
      << log.str();
  // The skipped frames' labels are there, all unknown.
  rosbag::Bag output(tempDir() + "/bad_images.out.bag");
  size_t i = 0;
  for (const auto& m : rosbag::View(output, rosbag::TopicQuery("/segmentation/labels"))) {
    const auto labels = m.instantiate<sensor_msgs::Image>();
    const size_t unknown = std::count(labels->data.begin(), labels->data.end(), act_color::core::kUnknown);
    if (i == 3 || i == 5) {
      EXPECT_EQ(unknown, labels->data.size()) << "frame " << i;
    } else {
      EXPECT_LT(unknown, labels->data.size() / 2) << "frame " << i;
    }
    ++i;
  }
  EXPECT_EQ(i, 10u);

  std::string text;
  const std::string tool = std::string(ACT_TOOLS_DIR) + "/act_replay --no-progress --brief --calibration " +
                           kCalibration + " --output " + tempDir() + "/bad_images.tool.bag --bag ";
  EXPECT_EQ(run(tool + in, &text), 0) << text;
  EXPECT_NE(text.find("(8 trained, 0 without a usable pose, 2 unusable images, 8 with truth)"), std::string::npos)
      << text;
  EXPECT_NE(text.find("2 of 10 frames with truth left out of the metrics (2 with an unusable image"), std::string::npos)
      << text;
  const std::string all_bad = tempDir() + "/all_bad_images.bag";
  copyBag(scenarioBag("static_darkening"), all_bad, 3, [](const std::string& topic, size_t, sensor_msgs::Image& m) {
    if (topic == "/omni/image_raw") m.step = 7;
    return true;
  });
  EXPECT_EQ(run(tool + all_bad, &text), 1) << text;
  EXPECT_NE(text.find("none of the 3 images of " + all_bad + " is usable"), std::string::npos) << text;
  EXPECT_NE(text.find("no frame with truth"), std::string::npos) << text;
}

// A bag cut short (its index at the end is missing): exit 1, the file named, `rosbag reindex`
// suggested, no output bag; and the suggestion works.
TEST(ActReplay, TruncatedBagSuggestsReindex) {
  const std::string in = tempDir() + "/truncated.bag";
  copyBag(scenarioBag("static_darkening"), in, 10, kUnchanged);
  const auto size = std::filesystem::file_size(in);
  std::filesystem::resize_file(in, size / 2);
  const std::string out = tempDir() + "/truncated.out.bag";
  std::string text;
  const std::string tool = std::string(ACT_TOOLS_DIR) + "/act_replay --no-progress --brief --calibration " +
                           kCalibration + " --output " + out + " --bag " + in;
  EXPECT_EQ(run(tool, &text), 1) << text;
  EXPECT_NE(text.find(in + ": cannot be read as a bag"), std::string::npos) << text;
  EXPECT_NE(text.find("`rosbag reindex " + in + "`"), std::string::npos) << text;
  EXPECT_FALSE(exists(out));
  EXPECT_FALSE(exists(out + ".active"));
  // What the message suggests gives a bag act_replay reads: the frames before the cut.
  ASSERT_EQ(std::system(("PYENV_VERSION=system rosbag reindex -q " + in + " > /dev/null 2>&1").c_str()), 0);
  EXPECT_TRUE(exists(tempDir() + "/truncated.orig.bag"));
  EXPECT_EQ(run(tool, &text), 0) << text;
  EXPECT_EQ(text.find("10 frames from"), std::string::npos) << text;
  EXPECT_NE(text.find("frames from " + in), std::string::npos) << text;
  EXPECT_TRUE(exists(out));
}

// A chunk that cannot be read in the middle of the replay (after labels were written): exit 1,
// the file and the image named, and neither the partial output nor an older OUT.bag left behind.
TEST(ActReplay, CorruptChunkLeavesNoPartialOutput) {
  const std::string in = tempDir() + "/corrupt_chunk.bag";
  copyBag(scenarioBag("static_darkening"), in, 10, kUnchanged, /*images_last=*/true);
  std::string bytes = readText(in);
  const std::string field = "compression=none";
  const size_t last_chunk = bytes.rfind(field);
  ASSERT_NE(last_chunk, std::string::npos);
  bytes.replace(last_chunk, field.size(), "compression=nonf");
  std::ofstream(in, std::ios::binary) << bytes;
  const std::string out = tempDir() + "/corrupt_chunk.out.bag";
  std::ofstream(out) << "an older output";
  std::string text;
  EXPECT_EQ(run(std::string(ACT_TOOLS_DIR) + "/act_replay --no-progress --calibration " + kCalibration + " --output " +
                    out + " --bag " + in,
                &text),
            1)
      << text;
  EXPECT_NE(text.find(in + ": reading failed at frame 9 (Unknown compression: nonf)"), std::string::npos) << text;
  EXPECT_NE(text.find("`rosbag reindex " + in + "`"), std::string::npos) << text;
  EXPECT_NE(text.find(out + " not written (the partial output was removed)"), std::string::npos) << text;
  EXPECT_FALSE(exists(out));
  EXPECT_FALSE(exists(out + ".active"));
}

// act_eval's command line: one family scene, its report on stdout; a family bag and calibration
// from act_make_scenarios --family replay with act_replay like any other bag.
TEST(ActEval, OneSceneReportAndFamilyBag) {
  const std::string out = tempDir() + "/eval.txt";
  const std::string eval = std::string(ACT_TOOLS_DIR) + "/act_eval";
  ASSERT_EQ(std::system((eval + " --seeds 0-0 > " + out + " 2> /dev/null").c_str()), 0);
  std::ifstream in(out);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* needle : {"seeds 0-0 (1 scenes", "defaults", "paper", "ceiling", "F1 below the paper"}) {
    EXPECT_NE(text.find(needle), std::string::npos) << needle << " not in:\n" << text;
  }
  const std::string local = tempDir() + "/eval_local.txt";
  ASSERT_EQ(std::system((eval + " --seeds 0-0 --local-light --per-scene > " + local + " 2> /dev/null").c_str()), 0);
  std::ifstream local_in(local);
  const std::string local_text((std::istreambuf_iterator<char>(local_in)), std::istreambuf_iterator<char>());
  EXPECT_NE(local_text.find("segment 'local:"), std::string::npos) << local_text;
  // --png makes its folder; one that cannot be made is an error before any scene is run.
  const std::string png = tempDir() + "/eval_png/nested";
  ASSERT_EQ(std::system((eval + " --seeds 0-0 --png " + png + " > /dev/null 2>&1").c_str()), 0);
  size_t panels = 0;
  for (const auto& entry : std::filesystem::directory_iterator(png)) {
    panels += entry.path().filename().string().rfind("scene_00000_frame_", 0) == 0;
  }
  EXPECT_GE(panels, 1u);
  const std::string png_error = tempDir() + "/eval_png_error.txt";
  EXPECT_EQ(WEXITSTATUS(std::system((eval + " --seeds 0-0 --png " + out + "/png 2> " + png_error).c_str())), 2);
  std::ifstream png_error_in(png_error);
  const std::string png_error_text((std::istreambuf_iterator<char>(png_error_in)), std::istreambuf_iterator<char>());
  EXPECT_NE(png_error_text.find("--png: " + out + "/png: cannot make the folder"), std::string::npos) << png_error_text;
  EXPECT_EQ(WEXITSTATUS(std::system((eval + " --split nonsense 2> /dev/null").c_str())), 2);
  EXPECT_EQ(WEXITSTATUS(std::system((eval + " --set zeta=-1 2> /dev/null").c_str())), 2);

  const std::string make = std::string(ACT_TOOLS_DIR) + "/act_make_scenarios --family 3 --length small --output-dir " +
                           tempDir() + " > /dev/null";
  ASSERT_EQ(std::system(make.c_str()), 0);
  const std::string replay = std::string(ACT_TOOLS_DIR) + "/act_replay --bag " + tempDir() + "/family_3.bag" +
                             " --calibration " + tempDir() + "/family_3.yaml --output " + tempDir() +
                             "/family_3.out.bag --brief --no-progress > " + tempDir() + "/family_3.txt";
  ASSERT_EQ(std::system(replay.c_str()), 0);
  std::ifstream brief(tempDir() + "/family_3.txt");
  const std::string summary((std::istreambuf_iterator<char>(brief)), std::istreambuf_iterator<char>());
  EXPECT_NE(summary.find("green"), std::string::npos) << summary;
}

// A team's way to its self mask: act_replay --learn-self-mask on a bag of a drive, then the
// calibration given the PNG. Family scene 40: three struts, driving, the light halved halfway.
TEST(ActReplay, LearnsTheSelfMaskFromADriveAndItsStrutsAreBlack) {
  const std::string dir = act_color_tool_test::tempDir("act_replay_self_mask");
  ASSERT_EQ(std::system((std::string(ACT_TOOLS_DIR) + "/act_make_scenarios --family 40 --length small --output-dir " +
                         dir + " > /dev/null")
                            .c_str()),
            0);
  const std::string bag = " --bag " + dir + "/family_40.bag --output " + dir + "/out.bag --brief --no-progress";
  const auto learned = act_color_tool_test::runTool(
      "act_replay", bag + " --calibration " + dir + "/family_40.yaml --learn-self-mask " + dir + "/mask.png", dir);
  ASSERT_EQ(learned.exit_code, 0) << learned.output;
  EXPECT_NE(learned.output.find("self mask learned from 13 poses"), std::string::npos) << learned.output;
  EXPECT_EQ(learned.output.find("fewer than"), std::string::npos) << learned.output;
  // Used while the replay runs, from the frame after the 8th distinct pose, as on the robot.
  EXPECT_NE(learned.output.find("the learned mask was used from frame"), std::string::npos) << learned.output;
  const cv::Mat mask = cv::imread(dir + "/mask.png", cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(mask.cols, 640);
  ASSERT_EQ(mask.rows, 480);
  const sim::FamilyScene scene = sim::makeFamilyScene(40);
  const std::vector<uint8_t> struts = sim::Renderer(scene.calibration, scene.renderer).strutMask();
  ASSERT_EQ(struts.size(), mask.total());
  size_t on = 0, off = 0, strut_pixels = 0;
  for (size_t i = 0; i < struts.size(); ++i) {
    strut_pixels += struts[i];
    (struts[i] ? on : off) += mask.data[i] != 0;
  }
  // Over the field and, as they keep their color from pose to pose, over the hall.
  EXPECT_GT(on, 0.9 * strut_pixels) << on << " of " << strut_pixels;
  EXPECT_LT(off, 0.01 * strut_pixels);

  std::string yaml = act_color_tool_test::readText(dir + "/family_40.yaml");
  const size_t camera = yaml.find("camera:\n");
  ASSERT_NE(camera, std::string::npos);
  yaml.insert(camera + 8, "  self_mask: mask.png\n");
  std::ofstream(dir + "/masked.yaml") << yaml;
  // Black's adapted recall in the brief summary: "  black  all adapt  all adapt".
  auto blackRecallIn = [](const std::string& output) {
    std::istringstream lines(output);
    for (std::string line; std::getline(lines, line);) {
      std::istringstream words(line);
      std::string name;
      double all = 0, adapted = 0;
      if (words >> name >> all >> adapted && name == "black") return adapted;
    }
    ADD_FAILURE() << "no black line in:\n" << output;
    return 0.0;
  };
  auto blackRecall = [&](const std::string& calibration) {
    const auto run = act_color_tool_test::runTool("act_replay", bag + " --calibration " + dir + "/" + calibration, dir);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return blackRecallIn(run.output);
  };
  const double without = blackRecall("family_40.yaml"), with = blackRecall("masked.yaml");
  const double while_learning = blackRecallIn(learned.output);
  std::printf("black recall %.3f without the mask, %.3f while learning it, %.3f with it\n", without, while_learning,
              with);
  EXPECT_GT(with, without + 0.3);
  EXPECT_GT(while_learning, without + 0.2);  // from the 8th of 13 poses on

  // Family scene 0 stands still, then drives: 6 distinct poses, too few to follow the struts over
  // the hall, and the replay says so.
  ASSERT_EQ(std::system((std::string(ACT_TOOLS_DIR) + "/act_make_scenarios --family 0 --length small --output-dir " +
                         dir + " > /dev/null")
                            .c_str()),
            0);
  const auto few = act_color_tool_test::runTool("act_replay",
                                                " --bag " + dir + "/family_0.bag --output " + dir +
                                                    "/out0.bag --brief --no-progress --calibration " + dir +
                                                    "/family_0.yaml --learn-self-mask " + dir + "/mask0.png",
                                                dir);
  ASSERT_EQ(few.exit_code, 0) << few.output;
  EXPECT_NE(few.output.find("self mask learned from 6 poses"), std::string::npos) << few.output;
  EXPECT_NE(few.output.find("fewer than 8 distinct poses"), std::string::npos) << few.output;
  EXPECT_EQ(few.output.find("the learned mask was used"), std::string::npos) << few.output;
}
