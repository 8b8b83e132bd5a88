// The whole pipeline in one manager (simulated camera, ACT trainer, segmentation) over a short
// simulated scenario: every frame gets labels, and their accuracy against the simulator's truth
// reaches the thresholds given as parameters (those of issue 3's end-to-end test).
#include <geometry_msgs/PointStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <map>
#include <opencv2/core.hpp>
#include <set>
#include <string>
#include <vector>

#include "act_color/ColorLut.h"
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
  // Flicker (simulated_camera ~flicker_*): the dark frames are not the steady light.
  const int flicker_period = pnh.param("flicker_period", 0), flicker_start = pnh.param("flicker_start", 0);
  const double max_fill_ratio = pnh.param("max_fill_ratio", 0.0);
  // The ball in the labels of the frames in which the trainer saw it (/act/ball): the segmentation
  // labels its image (issue 13). 0: not checked.
  const double min_ball_recall = pnh.param("min_ball_recall", 0.0);
  auto isDark = [&](size_t i) {
    return flicker_period > 0 && static_cast<int>(i) >= flicker_start &&
           (static_cast<int>(i) - flicker_start) % flicker_period == flicker_period - 1;
  };
  for (size_t i = 0; i < steady.size(); ++i) steady[i] = steady[i] && !isDark(i);
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
  std::map<ros::Time, double> fill;  // table stamp -> fraction of its cells with a class
  ros::Subscriber lut_sub;
  if (max_fill_ratio > 0) {
    lut_sub = nh.subscribe<act_color::ColorLut>("/act/color_lut", 100, [&](const act_color::ColorLutConstPtr& msg) {
      const double filled =
          static_cast<double>(msg->table.size() - std::count(msg->table.begin(), msg->table.end(), 0));
      std::lock_guard<std::mutex> lock(waiter.mutex());
      fill[msg->header.stamp] = filled / static_cast<double>(msg->table.size());
    });
  }
  std::set<ros::Time> ball_seen;  // stamps of /act/ball
  ros::Subscriber ball_sub =
      nh.subscribe<geometry_msgs::PointStamped>("/act/ball", 100, [&](const geometry_msgs::PointStampedConstPtr& msg) {
        std::lock_guard<std::mutex> lock(waiter.mutex());
        ball_seen.insert(msg->header.stamp);
      });
  ros::AsyncSpinner spinner(2);
  spinner.start();

  const size_t frames = scenario.frames.size();
  const bool all = waiter.waitFor(timeout, [&] { return truth.size() >= frames && labels.size() >= frames; });
  std::lock_guard<std::mutex> lock(waiter.mutex());
  EXPECT_TRUE(all) << "after " << timeout << " s: " << truth.size() << " truth images, " << labels.size()
                   << " label images of " << frames << " frames";
  ASSERT_EQ(truth.size(), frames) << "the simulated camera published a different number of frames";

  core::ClassificationMetrics metrics, ball_metrics;
  size_t labeled = 0;
  for (const auto& [stamp, t] : truth) {
    auto l = labels.find(stamp);
    if (l == labels.end()) continue;
    ++labeled;
    ASSERT_EQ(l->second->encoding, "mono8");
    ASSERT_EQ(l->second->header.frame_id, t->header.frame_id);
    if (steady[index_of[stamp]]) metrics.add(view(*l->second), view(*t));
    if (ball_seen.count(stamp)) ball_metrics.add(view(*l->second), view(*t));
  }
  EXPECT_EQ(labeled, frames) << "frames without labels";
  std::printf("pipeline on %s: %zu of %zu frames labeled; steady frames:\n%s", scenario_name.c_str(), labeled, frames,
              metrics.report().c_str());
  act_color_test::expectPerClassAtLeast(metrics, min_recall, min_precision);
  if (min_ball_recall > 0) {
    std::printf("the ball in the %zu frames with /act/ball: recall %.3f, precision %.3f\n", ball_seen.size(),
                ball_metrics.recall(core::kOrange), ball_metrics.precision(core::kOrange));
    EXPECT_GE(ball_seen.size(), frames / 3) << "frames in which the trainer saw the ball";
    EXPECT_GE(ball_metrics.recall(core::kOrange), min_ball_recall);
  }
  if (max_fill_ratio > 0) {
    // The table's fill before the flicker (after the start-up frames) and its largest during it.
    double before = 0, during = 0;
    int n_before = 0;
    for (const auto& [stamp, f] : fill) {
      auto i = index_of.find(stamp);
      if (i == index_of.end()) continue;
      if (i->second >= 4 && static_cast<int>(i->second) < flicker_start) {
        before += f;
        ++n_before;
      } else if (static_cast<int>(i->second) >= flicker_start) {
        during = std::max(during, f);
      }
    }
    ASSERT_GT(n_before, 0) << "no table before the flicker";
    before /= n_before;
    std::printf("table fill before the flicker %.4f, largest during it %.4f (x%.2f; at most x%.2f)\n", before, during,
                during / before, max_fill_ratio);
    EXPECT_LE(during, max_fill_ratio * before);
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_pipeline");
  return RUN_ALL_TESTS();
}
