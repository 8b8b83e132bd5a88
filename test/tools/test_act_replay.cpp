// act_replay end to end, without a master: scenario bags written by act_make_scenarios, replayed
// through runReplay() and the act_replay executable.
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include "act_color/ColorLut.h"
#include "act_color/core/calibration.hpp"
#include "act_color/ros/bag_replay.hpp"

using act_color::ros_layer::ReplayError;
using act_color::ros_layer::ReplayOptions;
using act_color::ros_layer::runReplay;

namespace {

const std::string kCalibration = std::string(ACT_SOURCE_DIR) + "/config/calibration/msl_2007_580.yaml";

std::string tempDir() {
  static std::string dir;
  if (dir.empty()) {
    char pattern[] = "/tmp/act_replay_test_XXXXXX";
    dir = mkdtemp(pattern);
  }
  return dir;
}

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

std::string readBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

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
  const std::string a = readBytes(tempDir() + "/a.bag");
  EXPECT_GT(a.size(), 1000000u);
  EXPECT_TRUE(a == readBytes(tempDir() + "/b.bag"));
  // Another seed gives other random start pixels, hence another table.
  ASSERT_EQ(std::system((tool + tempDir() + "/c.bag --seed 7 > /dev/null").c_str()), 0);
  EXPECT_FALSE(a == readBytes(tempDir() + "/c.bag"));
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
  EXPECT_NE(errorOf(options(junk, tempDir() + "/x.bag")).find("cannot be read as a bag"), std::string::npos);
  o = options(in, tempDir() + "/x.bag");
  o.calibration = "/nonexistent.yaml";
  EXPECT_NE(errorOf(o).find("/nonexistent.yaml"), std::string::npos);
  // The executable: usage errors exit 2, unusable input 1.
  const std::string tool = std::string(ACT_TOOLS_DIR) + "/act_replay";
  EXPECT_EQ(WEXITSTATUS(std::system((tool + " --bag " + in + " 2> /dev/null").c_str())), 2);
  EXPECT_EQ(WEXITSTATUS(std::system((tool + " --bag " + junk + " --calibration " + kCalibration + " --output " +
                                     tempDir() + "/x.bag 2> /dev/null")
                                        .c_str())),
            1);
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
