// The whole pipeline in one manager (simulated camera, ACT trainer, segmentation) over a short
// simulated scenario: every frame gets labels, and their accuracy against the simulator's truth
// reaches the thresholds given as parameters (those of issue 3's end-to-end test).
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/metrics.hpp"
#include "act_color/sim/scenario.hpp"
#include "test_util.hpp"

namespace {

namespace core = act_color::core;

cv::Mat view(const sensor_msgs::Image& msg) {
  return cv::Mat(msg.height, msg.width, CV_8UC1, const_cast<uint8_t*>(msg.data.data()), msg.step);
}

TEST(Pipeline, SimulatedScenarioAccuracy) {
  ros::NodeHandle nh, pnh("~");
  const std::string scenario_name = pnh.param<std::string>("scenario", "static_darkening");
  const std::string calibration_path = pnh.param<std::string>("calibration", "");
  const double timeout = pnh.param("timeout", 120.0);
  std::vector<double> min_recall, min_precision;
  ASSERT_TRUE(pnh.getParam("min_recall", min_recall));
  ASSERT_TRUE(pnh.getParam("min_precision", min_precision));
  ASSERT_EQ(min_recall.size(), core::trainableClasses().size());
  ASSERT_EQ(min_precision.size(), core::trainableClasses().size());
  const core::Calibration cal = core::loadCalibration(calibration_path);
  const act_color::sim::Scenario scenario =
      act_color::sim::makeScenario(scenario_name, act_color::sim::ScenarioLength::kSmall, cal, 1);
  // Frames right after a change of light are adaptation (paper, 3.2: 12 cycles), as in issue 3's test.
  std::vector<bool> steady(scenario.frames.size(), true);
  steady[0] = false;  // the bootstrap frame
  for (size_t i = 0; i < scenario.frames.size(); ++i) {
    for (const std::string& e : scenario.frames[i].events) {
      if (e == "darken" || e == "brighten") {
        for (size_t j = i; j < std::min(i + 12, steady.size()); ++j) steady[j] = false;
      }
    }
  }

  act_color_test::Waiter waiter;
  std::map<ros::Time, size_t> index_of;  // truth stamp -> frame index (truth comes in frame order)
  std::map<ros::Time, sensor_msgs::ImageConstPtr> truth, labels;
  ros::Subscriber truth_sub =
      nh.subscribe<sensor_msgs::Image>("/omni/labels_truth", 100, [&](const sensor_msgs::ImageConstPtr& msg) {
        std::lock_guard<std::mutex> lock(waiter.mutex());
        const size_t index = index_of.size();
        index_of[msg->header.stamp] = index;
        truth[msg->header.stamp] = msg;
        waiter.notify();
      });
  ros::Subscriber labels_sub =
      nh.subscribe<sensor_msgs::Image>("/segmentation/labels", 100, [&](const sensor_msgs::ImageConstPtr& msg) {
        std::lock_guard<std::mutex> lock(waiter.mutex());
        labels[msg->header.stamp] = msg;
        waiter.notify();
      });
  ros::AsyncSpinner spinner(2);
  spinner.start();

  const size_t frames = scenario.frames.size();
  const bool all = waiter.waitFor(timeout, [&] { return truth.size() >= frames && labels.size() >= frames; });
  std::lock_guard<std::mutex> lock(waiter.mutex());
  EXPECT_TRUE(all) << "after " << timeout << " s: " << truth.size() << " truth images, " << labels.size()
                   << " label images of " << frames << " frames";
  ASSERT_EQ(truth.size(), frames) << "the simulated camera published a different number of frames";

  core::ClassificationMetrics metrics;
  size_t labeled = 0;
  for (const auto& [stamp, t] : truth) {
    auto l = labels.find(stamp);
    if (l == labels.end()) continue;
    ++labeled;
    ASSERT_EQ(l->second->encoding, "mono8");
    ASSERT_EQ(l->second->header.frame_id, t->header.frame_id);
    if (steady[index_of[stamp]]) metrics.add(view(*l->second), view(*t));
  }
  EXPECT_EQ(labeled, frames) << "frames without labels";
  std::printf("pipeline on %s: %zu of %zu frames labeled; steady frames:\n%s", scenario_name.c_str(), labeled, frames,
              metrics.report().c_str());
  act_color_test::expectPerClassAtLeast(metrics, min_recall, min_precision);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_pipeline");
  return RUN_ALL_TESTS();
}
