// Issue 15, item 2: loading a calibration happens off the nodelet manager's load path. The test
// loads the trainer with a 16 Mpx calibration (its camera model takes about 2 s to build) through
// the manager's load service and asks it for its table at once: it must answer that the
// calibration is still loading (with the calibration loaded inside onInit, the load call would
// only have returned once the trainer was ready). Unloading nodelets while they load must leave
// the manager running.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>

#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "act_color/FilePath.h"
#include "test_util.hpp"

namespace {

bool load(const std::string& name, const std::string& type) {
  return act_color_test::loadNodelet("/load_manager", name, type);
}

bool unload(const std::string& name) { return act_color_test::unloadNodelet("/load_manager", name); }

// The trainer's answer to ~save_lut, or "" when the service did not answer.
std::string saveAnswer(const std::string& trainer) {
  act_color::FilePath srv;
  srv.request.path = "load_path_test.lut";
  if (!ros::service::call(trainer + "/save_lut", srv)) return "";
  return srv.response.message;
}

double since(const std::chrono::steady_clock::time_point& t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

TEST(LoadPath, CalibrationLoadsOffTheManagersLoadPath) {
  ASSERT_TRUE(ros::service::waitForService("/load_manager/load_nodelet", ros::Duration(30.0)));
  const auto start = std::chrono::steady_clock::now();
  ASSERT_TRUE(load("/big/trainer", "act_color/act_trainer"));
  const double load_call_s = since(start);
  ASSERT_TRUE(ros::service::waitForService("/big/trainer/save_lut", ros::Duration(10.0)));
  const std::string first = saveAnswer("/big/trainer");
  const double first_answer_s = since(start);
  // Then it becomes ready: it has no table yet.
  std::string answer = first;
  while (answer.find("no table trained yet") == std::string::npos && since(start) < 60.0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    answer = saveAnswer("/big/trainer");
  }
  const double ready_s = since(start);
  std::printf("load_nodelet returned after %.3f s; ~save_lut at %.3f s: '%s'; ready after %.3f s: '%s'\n", load_call_s,
              first_answer_s, first.c_str(), ready_s, answer.c_str());
  EXPECT_NE(first.find("the calibration is still loading"), std::string::npos) << first;
  EXPECT_NE(answer.find("no table trained yet"), std::string::npos) << answer;
  EXPECT_LT(load_call_s, ready_s);

  // Unloaded while loading: the nodelet waits for its loader, the manager keeps running.
  ASSERT_TRUE(load("/big/trainer2", "act_color/act_trainer"));
  EXPECT_TRUE(unload("/big/trainer2"));
  ASSERT_TRUE(load("/big/segmentation", "act_color/segmentation"));
  EXPECT_TRUE(unload("/big/segmentation"));
  EXPECT_NE(saveAnswer("/big/trainer").find("no table trained yet"), std::string::npos);
  EXPECT_TRUE(unload("/big/trainer"));
  // The manager still loads nodelets.
  ASSERT_TRUE(load("/big/segmentation", "act_color/segmentation"));
  EXPECT_TRUE(unload("/big/segmentation"));
}

// A calibration that fails to load on the loader's thread: the nodelet stays loaded, says why, and
// the manager goes on.
TEST(LoadPath, FailedCalibrationIsReported) {
  ASSERT_TRUE(ros::service::waitForService("/load_manager/load_nodelet", ros::Duration(30.0)));
  ASSERT_TRUE(load("/broken/trainer", "act_color/act_trainer"));
  ASSERT_TRUE(ros::service::waitForService("/broken/trainer/save_lut", ros::Duration(10.0)));
  const auto start = std::chrono::steady_clock::now();
  std::string answer = saveAnswer("/broken/trainer");
  while (answer.find("not configured") == std::string::npos && since(start) < 30.0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    answer = saveAnswer("/broken/trainer");
  }
  std::printf("a missing calibration: '%s'\n", answer.c_str());
  EXPECT_NE(answer.find("the nodelet is not configured: bad calibration"), std::string::npos) << answer;
  EXPECT_NE(answer.find("/nonexistent/calibration.yaml"), std::string::npos) << answer;
  EXPECT_TRUE(unload("/broken/trainer"));
}

// ~initial_pose mistyped or off the field: refused with a message naming it (it was ignored, or
// trained the start-up table at a pose 1000 km away), the nodelet stays loaded, the manager goes on.
TEST(LoadPath, AWrongInitialPoseIsRefused) {
  ASSERT_TRUE(ros::service::waitForService("/load_manager/load_nodelet", ros::Duration(30.0)));
  ros::NodeHandle nh;
  std::mutex mutex;
  std::vector<std::string> errors;
  ros::Subscriber log_sub = nh.subscribe<rosgraph_msgs::Log>("/rosout", 100, [&](const rosgraph_msgs::LogConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    if (m->level >= rosgraph_msgs::Log::ERROR) errors.push_back(m->name + ": " + m->msg);
  });
  ros::AsyncSpinner spinner(1);
  spinner.start();
  // Connected to the manager's /rosout (and the test's own) before anything is said.
  const auto connecting = std::chrono::steady_clock::now();
  while (log_sub.getNumPublishers() < 2 && since(connecting) < 10.0) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (const auto& [name, expected] : std::vector<std::pair<std::string, std::string>>{
           {"/typo/trainer", "not started: ~initial_pose must be a list [x_m, y_m, theta_rad] of numbers"},
           {"/far/trainer", "not started: ~initial_pose: pose (1e+06, 0) m is off the field"}}) {
    ASSERT_TRUE(load(name, "act_color/act_trainer"));
    const auto start = std::chrono::steady_clock::now();
    bool said = false;
    while (!said && since(start) < 30.0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      std::lock_guard<std::mutex> lock(mutex);
      for (const std::string& e : errors) said = said || e.find(expected) != std::string::npos;
    }
    EXPECT_TRUE(said) << name << ": no error '" << expected << "' in /rosout";
    EXPECT_TRUE(unload(name));
  }
  ASSERT_TRUE(load("/small/segmentation", "act_color/segmentation"));
  EXPECT_TRUE(unload("/small/segmentation"));
}

// Nodelets loaded and unloaded again and again, at once or after their calibration loaded, with a
// service call in between: the manager keeps running and loading.
TEST(LoadPath, LoadUnloadCycles) {
  ASSERT_TRUE(ros::service::waitForService("/load_manager/load_nodelet", ros::Duration(30.0)));
  constexpr int kCycles = 20;
  int answered = 0;
  for (int i = 0; i < kCycles; ++i) {
    ASSERT_TRUE(load("/small/trainer", "act_color/act_trainer")) << "cycle " << i;
    ASSERT_TRUE(load("/small/segmentation", "act_color/segmentation")) << "cycle " << i;
    if (i % 2 == 1) {
      ASSERT_TRUE(ros::service::waitForService("/small/trainer/save_lut", ros::Duration(10.0)));
      answered += saveAnswer("/small/trainer").empty() ? 0 : 1;
    }
    ASSERT_TRUE(unload("/small/segmentation")) << "cycle " << i;
    ASSERT_TRUE(unload("/small/trainer")) << "cycle " << i;
  }
  std::printf("%d load/unload cycles of the trainer and the segmentation; ~save_lut answered %d of %d times\n", kCycles,
              answered, kCycles / 2);
  EXPECT_EQ(answered, kCycles / 2);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_load_path");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
