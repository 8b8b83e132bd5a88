// Bad inputs (no pose yet, wrong encoding, wrong image size, NaN pose) give a throttled error or
// warning and no crash: the manager keeps running and a good frame afterwards is trained and
// segmented as usual.
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/Image.h>

#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "act_color/ColorLut.h"
#include "act_color/core/calibration.hpp"
#include "act_color/core/expected_class_model.hpp"
#include "act_color/sim/flat_painter.hpp"
#include "test_util.hpp"

namespace {

namespace core = act_color::core;

using act_color_test::makeImage;
using act_color_test::makePose;

class BadInputs : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string path = ros::NodeHandle("~").param<std::string>("calibration", "");
    model_ = std::make_unique<core::ExpectedClassModel>(core::loadCalibration(path));
    image_pub_ = nh_.advertise<sensor_msgs::Image>("/omni/image_raw", 50);
    pose_pub_ = nh_.advertise<geometry_msgs::PoseWithCovarianceStamped>("/localization/pose", 50);
    // A learned self mask as the trainer sends it with ~learn_self_mask (off here).
    self_mask_pub_ = nh_.advertise<sensor_msgs::Image>("/act/self_mask", 50);
    log_sub_ = nh_.subscribe<rosgraph_msgs::Log>("/rosout", 1000, [this](const rosgraph_msgs::LogConstPtr& m) {
      if (m->name != "/act_manager") return;
      std::lock_guard<std::mutex> lock(waiter_.mutex());
      logs_.push_back(m);
      waiter_.notify();
    });
    labels_sub_ =
        nh_.subscribe<sensor_msgs::Image>("/segmentation/labels", 50, [this](const sensor_msgs::ImageConstPtr& m) {
          std::lock_guard<std::mutex> lock(waiter_.mutex());
          labels_[m->header.stamp] = m;
          waiter_.notify();
        });
    lut_sub_ = nh_.subscribe<act_color::ColorLut>("/act/color_lut", 50, [this](const act_color::ColorLutConstPtr& m) {
      std::lock_guard<std::mutex> lock(waiter_.mutex());
      luts_[m->header.stamp] = m;
      waiter_.notify();
    });
    spinner_.start();
    // roscpp counts one subscriber per process: the manager.
    ASSERT_TRUE(waiter_.waitFor(30.0,
                                [this] {
                                  return image_pub_.getNumSubscribers() >= 1 && pose_pub_.getNumSubscribers() >= 1 &&
                                         self_mask_pub_.getNumSubscribers() >= 1 &&
                                         labels_sub_.getNumPublishers() >= 1 && lut_sub_.getNumPublishers() >= 1 &&
                                         log_sub_.getNumPublishers() >= 1;
                                }))
        << "the nodelets did not connect: image subscribers " << image_pub_.getNumSubscribers() << ", pose subscribers "
        << pose_pub_.getNumSubscribers() << ", labels publishers " << labels_sub_.getNumPublishers()
        << ", table publishers " << lut_sub_.getNumPublishers() << ", /rosout publishers "
        << log_sub_.getNumPublishers();
  }

  // Log messages of the manager at `level` or above containing `text`.
  int countLogs(uint8_t level, const std::string& text) {
    int n = 0;
    for (const auto& m : logs_) n += (m->level >= level && m->msg.find(text) != std::string::npos) ? 1 : 0;
    return n;
  }
  bool waitForLog(uint8_t level, const std::string& text) {
    return waiter_.waitFor(10.0, [&] { return countLogs(level, text) > 0; });
  }

  ros::NodeHandle nh_;
  ros::AsyncSpinner spinner_{2};
  std::unique_ptr<core::ExpectedClassModel> model_;
  ros::Publisher image_pub_, pose_pub_, self_mask_pub_;
  ros::Subscriber log_sub_, labels_sub_, lut_sub_;
  act_color_test::Waiter waiter_;
  std::vector<rosgraph_msgs::LogConstPtr> logs_;
  std::map<ros::Time, sensor_msgs::ImageConstPtr> labels_;
  std::map<ros::Time, act_color::ColorLutConstPtr> luts_;
};

TEST_F(BadInputs, ThrottledErrorsNoCrashStillWorking) {
  const core::Pose2D pose{-1.5, 1.0, 0.4};
  const act_color::sim::LabeledFrame frame = act_color::sim::paintFlatFrame(*model_, pose, 1.0, 3);
  const int kRepeats = 20;

  // 1. An image before any pose: no training (warning), labels all unknown after ~max_wait.
  // The segmentation may subscribe a moment after the trainer: repeat until labels come.
  ros::Time t_no_pose;
  size_t no_pose_frames = 0;
  bool labeled = false;
  for (int attempt = 0; attempt < 10 && !labeled; ++attempt) {
    t_no_pose = ros::Time::now();
    image_pub_.publish(makeImage(frame.rgb, "rgb8", t_no_pose));
    ++no_pose_frames;
    labeled = waiter_.waitFor(3.0, [&] { return labels_.count(t_no_pose) > 0; });
  }
  ASSERT_TRUE(labeled) << "no labels without a pose";
  EXPECT_TRUE(waitForLog(rosgraph_msgs::Log::WARN, "no pose received yet"));
  {
    std::lock_guard<std::mutex> lock(waiter_.mutex());
    const auto& l = labels_[t_no_pose];
    EXPECT_EQ(l->encoding, "mono8");
    EXPECT_EQ(std::count(l->data.begin(), l->data.end(), core::kUnknown), static_cast<long>(l->data.size()));
  }

  // 2. Wrong encoding, 3. wrong size, 4. NaN pose: many of each, fast.
  cv::Mat mono(frame.rgb.rows, frame.rgb.cols, CV_8UC1, cv::Scalar(100));
  cv::Mat small(100, 100, CV_8UC3, cv::Scalar(30, 120, 30));
  core::Pose2D nan_pose = pose;
  nan_pose.x_m = std::numeric_limits<double>::quiet_NaN();
  // 5. Implausible poses (issue 15): 50 m off the field, rolled 90 degrees.
  const core::Pose2D far_pose{50.0, 0.0, 0.0};
  geometry_msgs::PoseWithCovarianceStamped rolled = makePose(pose, ros::Time::now());
  rolled.pose.pose.orientation.x = std::sqrt(0.5);
  rolled.pose.pose.orientation.y = 0.0;
  rolled.pose.pose.orientation.z = 0.0;
  rolled.pose.pose.orientation.w = std::sqrt(0.5);
  // 6. A self mask of another size than the calibration's (the segmentation keeps its own).
  cv::Mat small_mask(100, 100, CV_8UC1, cv::Scalar(255));
  for (int i = 0; i < kRepeats; ++i) {
    self_mask_pub_.publish(makeImage(small_mask, "mono8", ros::Time::now()));
    image_pub_.publish(makeImage(mono, "mono8", ros::Time::now()));
    image_pub_.publish(makeImage(small, "rgb8", ros::Time::now()));
    pose_pub_.publish(makePose(nan_pose, ros::Time::now()));
    pose_pub_.publish(makePose(far_pose, ros::Time::now()));
    rolled.header.stamp = ros::Time::now();
    pose_pub_.publish(rolled);
  }
  EXPECT_TRUE(waitForLog(rosgraph_msgs::Log::ERROR, "unsupported encoding 'mono8'"));
  EXPECT_TRUE(waitForLog(rosgraph_msgs::Log::ERROR, "image is 100x100 px"));
  EXPECT_TRUE(waitForLog(rosgraph_msgs::Log::ERROR, "NaN"));
  EXPECT_TRUE(waitForLog(rosgraph_msgs::Log::ERROR, "is off the field"));
  EXPECT_TRUE(waitForLog(rosgraph_msgs::Log::ERROR, "tilted by 90"));
  EXPECT_TRUE(waitForLog(rosgraph_msgs::Log::ERROR, "the trainer's self mask is not used: image is 100x100 px"));

  // 7. Still alive and working: a good pose and image are trained and segmented. Pose and image
  // come on different connections, so the image may overtake its pose: then the trainer holds it
  // until the next image (README, act_trainer) and its table comes one frame later. Good frames
  // are sent until a table stamped with any of them has come.
  std::vector<ros::Time> good_stamps;
  ros::Time t_trained;
  size_t good_frames = 0;
  auto sendGood = [&] {
    const ros::Time t = ros::Time::now();
    pose_pub_.publish(makePose(pose, t));
    image_pub_.publish(makeImage(frame.rgb, "rgb8", t));
    ++good_frames;
    return t;
  };
  bool trained = false;
  for (int attempt = 0; attempt < 10 && !trained; ++attempt) {
    const ros::Time t = sendGood();
    good_stamps.push_back(t);
    ASSERT_TRUE(waiter_.waitFor(20.0, [&] { return labels_.count(t) > 0; }))
        << "no labels for a good frame after the bad inputs";
    trained = waiter_.waitFor(2.0, [&] {
      for (const ros::Time& g : good_stamps) {
        if (luts_.count(g) > 0) {
          t_trained = g;
          return true;
        }
      }
      return false;
    });
  }
  ASSERT_TRUE(trained) << "no table trained on a good frame after the bad inputs";
  // One more good frame: a trained table exists now, so its labels come from one.
  const ros::Time t_good = sendGood();
  ASSERT_TRUE(waiter_.waitFor(20.0, [&] { return labels_.count(t_good) > 0; })) << "no labels for the last good frame";

  std::lock_guard<std::mutex> lock(waiter_.mutex());
  // The bad frames got no labels; the good one is mostly right.
  EXPECT_LE(labels_.size(), no_pose_frames + good_frames);
  EXPECT_GE(labels_.size(), 1 + good_frames);
  const auto& l = labels_[t_good];
  size_t correct = 0, imaged = 0;
  for (size_t i = 0; i < l->data.size(); ++i) {
    const uint8_t truth = frame.labels.data[i];
    if (truth == core::kNotImaged) continue;
    ++imaged;
    correct += l->data[i] == truth ? 1 : 0;
  }
  const double accuracy = static_cast<double>(correct) / imaged;
  std::printf("good frame after the bad inputs: pixel accuracy %.3f, table revision %lu\n", accuracy,
              static_cast<unsigned long>(luts_[t_trained]->revision));
  EXPECT_GT(accuracy, 0.8);
  // Throttled: one message per call site and throttle period, not one per bad input.
  const int encoding_errors = countLogs(rosgraph_msgs::Log::ERROR, "unsupported encoding");
  const int mask_errors = countLogs(rosgraph_msgs::Log::ERROR, "self mask is not used");
  const int size_errors = countLogs(rosgraph_msgs::Log::ERROR, "100x100") - mask_errors;
  const int nan_errors = countLogs(rosgraph_msgs::Log::ERROR, "NaN");
  std::printf("log messages for %d bad inputs each: encoding %d, size %d, NaN pose %d, self mask %d\n", kRepeats,
              encoding_errors, size_errors, nan_errors, mask_errors);
  EXPECT_LE(encoding_errors, 2);  // trainer and segmentation, once each
  EXPECT_LE(size_errors, 2);
  EXPECT_LE(mask_errors, 1);
  EXPECT_LE(nan_errors, 2);  // one pose source per nodelet, shared throttle
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_bad_inputs");
  return RUN_ALL_TESTS();
}
