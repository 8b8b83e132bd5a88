// replay.launch over a small bag at rate 1: labels for every image of the bag (stamped as the
// image), and their accuracy against the bag's truth labels.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>

#include <map>
#include <opencv2/core.hpp>
#include <set>
#include <string>
#include <vector>

#include "act_color/ColorLut.h"
#include "act_color/core/metrics.hpp"
#include "test_util.hpp"

namespace {

namespace core = act_color::core;

cv::Mat view(const sensor_msgs::Image& msg) {
  return cv::Mat(msg.height, msg.width, CV_8UC1, const_cast<uint8_t*>(msg.data.data()), msg.step);
}

TEST(Replay, LabelsForEveryFrame) {
  ros::NodeHandle nh, pnh("~");
  const std::string bag_path = pnh.param<std::string>("bag", "");
  std::vector<double> min_recall, min_precision;
  ASSERT_TRUE(pnh.getParam("min_recall", min_recall));
  ASSERT_TRUE(pnh.getParam("min_precision", min_precision));
  // Of the images, those trained on (the table's revision went up with them).
  const double min_trained = pnh.param("min_trained_fraction", 1.0);
  const std::string pose_source = pnh.param<std::string>("pose_source", "topic");

  // What the bag holds: image stamps and truth labels.
  std::set<ros::Time> image_stamps;
  std::map<ros::Time, sensor_msgs::ImageConstPtr> truth;
  double duration_s = 0.0;
  {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
    rosbag::View images(bag, rosbag::TopicQuery(std::vector<std::string>{"/omni/image_raw", "/omni/labels_truth"}));
    for (const rosbag::MessageInstance& m : images) {
      auto image = m.instantiate<sensor_msgs::Image>();
      if (!image) continue;
      if (m.getTopic() == "/omni/image_raw") image_stamps.insert(image->header.stamp);
      if (m.getTopic() == "/omni/labels_truth") truth[image->header.stamp] = image;
    }
    duration_s = (images.getEndTime() - images.getBeginTime()).toSec();
  }
  ASSERT_GT(image_stamps.size(), 10u) << bag_path;

  act_color_test::Waiter waiter;
  std::map<ros::Time, sensor_msgs::ImageConstPtr> labels;
  size_t duplicates = 0;
  ros::Subscriber sub =
      nh.subscribe<sensor_msgs::Image>("/segmentation/labels", 100, [&](const sensor_msgs::ImageConstPtr& msg) {
        std::lock_guard<std::mutex> lock(waiter.mutex());
        duplicates += labels.count(msg->header.stamp);
        labels[msg->header.stamp] = msg;
        waiter.notify();
      });
  std::map<ros::Time, uint64_t> revisions;  // table stamp -> revision
  ros::Subscriber lut_sub =
      nh.subscribe<act_color::ColorLut>("/act/color_lut", 100, [&](const act_color::ColorLutConstPtr& msg) {
        std::lock_guard<std::mutex> lock(waiter.mutex());
        revisions[msg->header.stamp] = msg->revision;
      });
  ros::AsyncSpinner spinner(2);
  spinner.start();
  // replay.launch waits ~delay s before playing; the bag plays at rate 1.
  const double timeout = 30.0 + 2.0 * duration_s;
  const bool all = waiter.waitFor(
      timeout, [&] { return labels.size() >= image_stamps.size() && revisions.size() >= image_stamps.size(); });

  std::lock_guard<std::mutex> lock(waiter.mutex());
  size_t labeled = 0;
  core::ClassificationMetrics metrics;
  bool first = true;
  for (const ros::Time& stamp : image_stamps) {
    auto l = labels.find(stamp);
    if (l == labels.end()) continue;
    ++labeled;
    auto t = truth.find(stamp);
    if (!first && t != truth.end()) metrics.add(view(*l->second), view(*t->second));
    first = false;
  }
  std::printf("replay of %s (%zu images, %.1f s): labels for %zu images (%.1f%%), %zu duplicates\n%s", bag_path.c_str(),
              image_stamps.size(), duration_s, labeled, 100.0 * labeled / image_stamps.size(), duplicates,
              metrics.report().c_str());
  // One table per image; a revision step of more than one cycle is the bootstrap, fewer: a frame
  // the trainer did not train on.
  size_t trained = 0;
  uint64_t previous = 0;
  for (const auto& [stamp, revision] : revisions) {
    trained += revision > previous ? 1 : 0;
    previous = revision;
  }
  std::printf("pose from %s: tables for %zu images, %zu of them (%.1f%%) trained on their image, last revision %lu\n",
              pose_source.c_str(), revisions.size(), trained, 100.0 * trained / image_stamps.size(),
              static_cast<unsigned long>(previous));
  EXPECT_TRUE(all) << "timed out after " << timeout << " s";
  EXPECT_EQ(revisions.size(), image_stamps.size()) << "images without a table";
  EXPECT_GE(trained, min_trained * image_stamps.size()) << "images the trainer did not train on";
  EXPECT_EQ(labeled, image_stamps.size()) << "images without labels";
  EXPECT_EQ(labels.size(), labeled) << "labels with stamps of no image in the bag";
  EXPECT_EQ(duplicates, 0u);
  act_color_test::expectPerClassAtLeast(metrics, min_recall, min_precision);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_replay");
  return RUN_ALL_TESTS();
}
