// The trainer nodelet learns the own robot's pixels while the robot drives (~learn_self_mask,
// issue 12) and saves them with ~save_self_mask: a drive of 24 poses over family scene 40, as
// act_eval --learn-self-mask drives it, gives a mask on the scene's mirror struts and nowhere else,
// while every frame is trained and published as before. The service writes only inside ~lut_dir and
// never over a file that is not a PNG; a trainer without ~learn_self_mask says so.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "act_color/ColorLut.h"
#include "act_color/FilePath.h"
#include "act_color/core/calibration.hpp"
#include "act_color/core/self_mask_learner.hpp"
#include "act_color/sim/family_evaluation.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scene_family.hpp"
#include "test_util.hpp"

namespace {

namespace core = act_color::core;
namespace sim = act_color::sim;

bool load(const std::string& name) {
  return act_color_test::loadNodelet("/self_mask_manager", name, "act_color/act_trainer");
}

bool unload(const std::string& name) { return act_color_test::unloadNodelet("/self_mask_manager", name); }

// The share of the mask's pixels that `labels` gives black.
double blackShare(const std::vector<uint8_t>& mask, const sensor_msgs::Image& labels) {
  size_t in_mask = 0, black = 0;
  for (size_t i = 0; i < mask.size() && i < labels.data.size(); ++i) {
    if (!mask[i]) continue;
    ++in_mask;
    black += labels.data[i] == core::kBlack;
  }
  return in_mask ? static_cast<double>(black) / static_cast<double>(in_mask) : 0.0;
}

// Family scene 40 (three mirror struts) and its calibration without a self mask, written to
// `dir`/family_40.yaml.
sim::FamilyScene writeScene(const std::string& dir, core::Calibration* calibration) {
  sim::FamilyScene scene = sim::makeFamilyScene(40);
  *calibration = scene.calibration;
  calibration->camera.self_mask.clear();
  calibration->camera.self_mask_file.clear();
  std::filesystem::create_directories(dir + "/lut");
  std::ofstream(dir + "/family_40.yaml") << core::toYaml(*calibration);
  return scene;
}

act_color::FilePath::Response saveSelfMask(const std::string& trainer, const std::string& path) {
  act_color::FilePath srv;
  srv.request.path = path;
  EXPECT_TRUE(ros::service::call(trainer + "/save_self_mask", srv)) << trainer << " did not answer";
  return srv.response;
}

TEST(SelfMask, TheTrainerLearnsTheStrutsWhileTheRobotDrives) {
  ros::NodeHandle nh, pnh("~");
  const std::string dir = pnh.param<std::string>("dir", "/tmp/act_color_self_mask_test");
  std::filesystem::remove_all(dir);
  core::Calibration calibration;
  const sim::FamilyScene scene = writeScene(dir, &calibration);

  for (const std::string name : {"/drive/trainer", "/still/trainer"}) {
    nh.setParam(name + "/calibration", dir + "/family_40.yaml");
    nh.setParam(name + "/lut_dir", dir + "/lut");
    nh.setParam(name + "/bootstrap_at_first_pose", true);
  }
  nh.setParam("/drive/trainer/learn_self_mask", true);
  nh.setParam("/drive/segmentation/calibration", dir + "/family_40.yaml");
  ASSERT_TRUE(ros::service::waitForService("/self_mask_manager/load_nodelet", ros::Duration(30.0)));
  ASSERT_TRUE(load("/drive/trainer"));
  ASSERT_TRUE(load("/still/trainer"));
  ASSERT_TRUE(act_color_test::loadNodelet("/self_mask_manager", "/drive/segmentation", "act_color/segmentation"));

  act_color_test::Waiter waiter;
  size_t tables = 0;
  ros::Subscriber lut_sub =
      nh.subscribe<act_color::ColorLut>("/drive/color_lut", 100, [&](const act_color::ColorLutConstPtr&) {
        std::lock_guard<std::mutex> lock(waiter.mutex());
        ++tables;
        waiter.notify();
      });
  // The trainer's diagnostics: the poses counted and the time one took.
  std::map<std::string, std::string> diagnostics;
  std::string segmentation_state;  // the segmentation's diagnostics summary
  ros::Subscriber diag_sub = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
      "/diagnostics", 100, [&](const diagnostic_msgs::DiagnosticArrayConstPtr& m) {
        std::lock_guard<std::mutex> lock(waiter.mutex());
        for (const auto& status : m->status) {
          if (status.name.find("drive/segmentation") != std::string::npos) segmentation_state = status.message;
          if (status.name.find("drive/trainer") == std::string::npos) continue;
          for (const auto& kv : status.values) diagnostics[kv.key] = kv.value;
        }
        waiter.notify();
      });
  // The mask the trainer uses once it has learned it (latched), and the segmentation's labels.
  sensor_msgs::ImageConstPtr used_mask;
  int masks = 0;
  ros::Subscriber mask_sub =
      nh.subscribe<sensor_msgs::Image>("/drive/self_mask", 10, [&](const sensor_msgs::ImageConstPtr& m) {
        std::lock_guard<std::mutex> lock(waiter.mutex());
        used_mask = m;
        ++masks;
        waiter.notify();
      });
  const sim::Renderer renderer(calibration, scene.renderer);
  const std::vector<uint8_t> struts = renderer.strutMask();
  std::vector<double> struts_black;  // per labelled frame, in order
  ros::Subscriber labels_sub =
      nh.subscribe<sensor_msgs::Image>("/drive/labels", 200, [&](const sensor_msgs::ImageConstPtr& m) {
        const double share = blackShare(struts, *m);
        std::lock_guard<std::mutex> lock(waiter.mutex());
        struts_black.push_back(share);
        waiter.notify();
      });
  ros::Publisher image_pub = nh.advertise<sensor_msgs::Image>("/drive/image", 10);
  ros::Publisher pose_pub = nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("/drive/pose", 10);
  ros::AsyncSpinner spinner(1);
  spinner.start();
  ASSERT_TRUE(waiter.waitFor(30.0, [&] {
    return image_pub.getNumSubscribers() >= 1 && pose_pub.getNumSubscribers() >= 1 && lut_sub.getNumPublishers() >= 1 &&
           labels_sub.getNumPublishers() >= 1;
  })) << "the trainer and the segmentation did not connect";
  // (One connection per topic to the manager's process, whichever of its nodelets subscribe.) The
  // segmentation's calibration loaded: no frame dropped.
  ASSERT_TRUE(waiter.waitFor(30.0, [&] {
    return !segmentation_state.empty() && segmentation_state.find("loading") == std::string::npos;
  })) << segmentation_state;
  // Not before the calibration is loaded (it is built off the manager's load path).
  ASSERT_TRUE(ros::service::waitForService("/drive/trainer/save_self_mask", ros::Duration(30.0)));
  const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(30.0);
  std::string answer;
  while (ros::WallTime::now() < until &&
         (answer = saveSelfMask("/drive/trainer", "").message).find("still loading") != std::string::npos) {
    ros::WallDuration(0.1).sleep();
  }
  EXPECT_NE(answer.find("no frame counted yet"), std::string::npos) << answer;

  // The drive: each pose for kDriveCyclesPerPose frames at 20 Hz, the pose sent before its image.
  sim::Scene drive = scene.scenario.frames.front().scene;
  const std::vector<core::Pose2D> poses = sim::drivePoses(scene, sim::kDrivePoses);
  ASSERT_EQ(poses.size(), static_cast<size_t>(sim::kDrivePoses));
  size_t sent = 0;
  for (size_t k = 0; k < poses.size(); ++k) {
    drive.robot_pose = poses[k];
    drive.noise_seed = sim::kDriveNoiseSeed + static_cast<uint32_t>(k);
    const sim::LabeledFrame frame = renderer.render(drive);
    for (int c = 0; c < sim::kDriveCyclesPerPose; ++c) {
      const ros::Time t = ros::Time::now();
      pose_pub.publish(act_color_test::makePose(poses[k], t));
      image_pub.publish(act_color_test::makeImage(frame.rgb, "rgb8", t));
      ++sent;
      ros::WallDuration(0.05).sleep();
    }
  }
  // Every frame trained and its table published: learning holds nothing up.
  EXPECT_TRUE(waiter.waitFor(10.0, [&] { return tables >= sent; })) << tables << " tables for " << sent << " frames";
  // Every frame labelled. From 8 poses on the mask learned so far is used: the struts are labelled
  // black (over the field and over the hall) where at the start the table gave them other classes.
  EXPECT_TRUE(waiter.waitFor(10.0, [&] { return struts_black.size() >= sent; }))
      << struts_black.size() << " labels for " << sent << " frames";
  ASSERT_TRUE(waiter.waitFor(10.0, [&] { return used_mask != nullptr; })) << "no self mask used";
  {
    std::lock_guard<std::mutex> lock(waiter.mutex());
    ASSERT_FALSE(struts_black.empty());
    std::printf("struts labelled black: %.3f in the first frame, %.3f in the last; %d masks used\n",
                struts_black.front(), struts_black.back(), masks);
    EXPECT_LT(struts_black.front(), 0.8);
    EXPECT_GT(struts_black.back(), 0.9);
    EXPECT_GE(masks, 1);
    EXPECT_EQ(used_mask->encoding, "mono8");
    ASSERT_EQ(used_mask->data.size(), struts.size());
    size_t on = 0, off = 0;
    for (size_t i = 0; i < struts.size(); ++i) (struts[i] ? on : off) += used_mask->data[i] != 0;
    std::printf("the mask in use: %zu strut pixels, %zu others\n", on, off);
    EXPECT_GT(on, 0.8 * static_cast<double>(std::count(struts.begin(), struts.end(), 1)));
    EXPECT_LT(off, 0.01 * static_cast<double>(on));
  }

  const std::string poses_key = "self mask learned from (distinct poses)";
  EXPECT_TRUE(waiter.waitFor(10.0, [&] { return diagnostics[poses_key] == "24"; })) << diagnostics[poses_key];
  EXPECT_TRUE(waiter.waitFor(10.0, [&] { return std::atoi(diagnostics["self mask in use (pixels)"].c_str()) > 1000; }))
      << diagnostics["self mask in use (pixels)"];
  {
    std::lock_guard<std::mutex> lock(waiter.mutex());
    std::printf("diagnostics: %s %s, last pose counted in %s ms\n", poses_key.c_str(), diagnostics[poses_key].c_str(),
                diagnostics["self mask: last pose counted in (ms, own thread)"].c_str());
  }
  const auto saved = saveSelfMask("/drive/trainer", "");
  std::printf("~save_self_mask: %s\n", saved.message.c_str());
  ASSERT_TRUE(saved.success) << saved.message;
  EXPECT_NE(saved.message.find("from 24 distinct poses"), std::string::npos) << saved.message;
  // A drive that turned: enough directions faced, nothing left to ask of the driver.
  const size_t faced_at = saved.message.find("the poses faced ");
  ASSERT_NE(faced_at, std::string::npos) << saved.message;
  const int faced = std::atoi(saved.message.c_str() + faced_at + 16);
  EXPECT_GE(faced, static_cast<int>(core::SelfMaskLearner::kMinHeadingSectors)) << saved.message;
  {
    std::lock_guard<std::mutex> lock(waiter.mutex());
    EXPECT_EQ(diagnostics["self mask: directions faced (of 8)"], std::to_string(faced));
  }
  EXPECT_EQ(saved.message.find("fewer than"), std::string::npos) << saved.message;
  const cv::Mat mask = cv::imread(dir + "/lut/self_mask.png", cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(mask.cols, calibration.camera.width);
  ASSERT_EQ(mask.rows, calibration.camera.height);
  size_t on = 0, off = 0, strut_pixels = 0;
  for (size_t i = 0; i < struts.size(); ++i) {
    strut_pixels += struts[i];
    (struts[i] ? on : off) += mask.data[i] != 0;
  }
  std::printf("learned online: %zu of the %zu strut pixels, %zu others\n", on, strut_pixels, off);
  EXPECT_GT(on, 0.9 * strut_pixels);
  EXPECT_LT(off, 0.01 * strut_pixels);
  // The calibration takes it as it is (the PNG's size is the camera's).
  calibration.camera.self_mask_file = dir + "/lut/self_mask.png";
  std::ofstream(dir + "/masked.yaml") << core::toYaml(calibration);
  EXPECT_NO_THROW(core::loadCalibration(dir + "/masked.yaml"));

  // Only inside ~lut_dir, never over what is not a PNG, and only when learning.
  const auto outside = saveSelfMask("/drive/trainer", "../outside.png");
  EXPECT_FALSE(outside.success);
  EXPECT_NE(outside.message.find("not inside ~lut_dir"), std::string::npos) << outside.message;
  EXPECT_FALSE(std::filesystem::exists(dir + "/outside.png"));
  std::ofstream(dir + "/lut/notes.txt") << "a team's notes\n";
  const auto over = saveSelfMask("/drive/trainer", "notes.txt");
  EXPECT_FALSE(over.success);
  EXPECT_NE(over.message.find("is not a PNG image: not overwritten"), std::string::npos) << over.message;
  std::ifstream notes(dir + "/lut/notes.txt");
  std::string line;
  std::getline(notes, line);
  EXPECT_EQ(line, "a team's notes");
  const auto again = saveSelfMask("/drive/trainer", "self_mask.png");  // its own PNG: replaced
  EXPECT_TRUE(again.success) << again.message;
  const auto off_answer = saveSelfMask("/still/trainer", "");
  EXPECT_FALSE(off_answer.success);
  EXPECT_NE(off_answer.message.find("~learn_self_mask is off"), std::string::npos) << off_answer.message;
  EXPECT_TRUE(act_color_test::unloadNodelet("/self_mask_manager", "/drive/segmentation"));
}

// The learner's thread goes with its nodelet: unloaded while frames at new poses keep coming (a
// pose being counted, another offered), the manager runs on and loads the next one.
TEST(SelfMask, UnloadingWhileLearningLeavesTheManagerRunning) {
  ros::NodeHandle nh, pnh("~");
  const std::string dir = pnh.param<std::string>("dir", "/tmp/act_color_self_mask_test") + "/cycles";
  core::Calibration calibration;
  const sim::FamilyScene scene = writeScene(dir, &calibration);
  const sim::Renderer renderer(calibration, scene.renderer);
  sim::Scene drive = scene.scenario.frames.front().scene;
  const std::vector<core::Pose2D> poses = sim::drivePoses(scene, 8);
  std::vector<cv::Mat> frames;
  for (const core::Pose2D& pose : poses) {
    drive.robot_pose = pose;
    frames.push_back(renderer.render(drive).rgb);
  }
  ASSERT_TRUE(ros::service::waitForService("/self_mask_manager/load_nodelet", ros::Duration(30.0)));
  ros::Publisher image_pub = nh.advertise<sensor_msgs::Image>("/cycle/image", 10);
  ros::Publisher pose_pub = nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("/cycle/pose", 10);
  nh.setParam("/cycle/trainer/calibration", dir + "/family_40.yaml");
  nh.setParam("/cycle/trainer/lut_dir", dir + "/lut");
  nh.setParam("/cycle/trainer/bootstrap_at_first_pose", true);
  nh.setParam("/cycle/trainer/learn_self_mask", true);
  for (int round = 0; round < 5; ++round) {
    ASSERT_TRUE(load("/cycle/trainer")) << "round " << round;
    // Until its calibration is loaded (it answers, and not "still loading"), then frames at every
    // pose. (Under ASan it had sometimes counted poses already: frames of the round before, still on
    // their way to the manager when the nodelet was unloaded and the next one subscribed.)
    ASSERT_TRUE(ros::service::waitForService("/cycle/trainer/save_self_mask", ros::Duration(30.0)));
    const ros::WallTime until = ros::WallTime::now() + ros::WallDuration(60.0);
    act_color::FilePath srv;
    bool ready = false;
    while (!ready && ros::WallTime::now() < until) {
      ready = ros::service::call("/cycle/trainer/save_self_mask", srv) &&
              srv.response.message.find("still loading") == std::string::npos;
      if (!ready) ros::WallDuration(0.05).sleep();
    }
    EXPECT_TRUE(ready) << "round " << round << ": " << srv.response.message;
    for (size_t k = 0; k < poses.size(); ++k) {
      const ros::Time t = ros::Time::now();
      pose_pub.publish(act_color_test::makePose(poses[k], t));
      image_pub.publish(act_color_test::makeImage(frames[k], "rgb8", t));
      ros::WallDuration(0.01).sleep();
    }
    ASSERT_TRUE(unload("/cycle/trainer")) << "round " << round;
    // The manager destroys an unloaded nodelet once its callback in progress (here a frame being
    // trained) returns, after the unload service has answered; a nodelet of the same name loaded
    // before that found its services still advertised by the old one (under ASan: "Tried to
    // advertise a service that is already advertised", and no ~save_self_mask for 30 s).
    const ros::WallTime gone_by = ros::WallTime::now() + ros::WallDuration(30.0);
    while (ros::service::exists("/cycle/trainer/save_self_mask", false) && ros::WallTime::now() < gone_by) {
      ros::WallDuration(0.05).sleep();
    }
    EXPECT_FALSE(ros::service::exists("/cycle/trainer/save_self_mask", false)) << "round " << round;
  }
  EXPECT_TRUE(load("/cycle/trainer"));
  EXPECT_TRUE(unload("/cycle/trainer"));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_self_mask");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
