// act.launch driven frame by frame, as a team engineer would probe it (issue 14): diagnostics
// that say why nothing works (images rejected, no pose) and OK once it does; dynamic_reconfigure
// refusing a value out of range with the value as typed and keeping the one in effect;
// ~save_lut / ~load_lut restoring table, clusters and revision; a jump back in time logged once,
// the table kept; stale input reported by both nodelets.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/Image.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "act_color/ColorLut.h"
#include "act_color/FilePath.h"
#include "act_color/core/calibration.hpp"
#include "act_color/core/expected_class_model.hpp"
#include "act_color/sim/flat_painter.hpp"
#include "act_color/sim/scenario.hpp"
#include "test_util.hpp"

namespace {

namespace core = act_color::core;
using act_color_test::makeImage;
using act_color_test::makePose;

class Operability : public ::testing::Test {
 protected:
  void SetUp() override {
    ros::NodeHandle pnh("~");
    model_ =
        std::make_unique<core::ExpectedClassModel>(core::loadCalibration(pnh.param<std::string>("calibration", "")));
    lut_file_ = pnh.param<std::string>("lut_file", "");
    lut_dir_ = pnh.param<std::string>("lut_dir", "");
    std::remove(lut_file_.c_str());
    image_pub_ = nh_.advertise<sensor_msgs::Image>("/omni/image_raw", 50);
    pose_pub_ = nh_.advertise<geometry_msgs::PoseWithCovarianceStamped>("/localization/pose", 50);
    log_sub_ = nh_.subscribe<rosgraph_msgs::Log>("/rosout", 1000, [this](const rosgraph_msgs::LogConstPtr& m) {
      if (m->name != "/act_manager") return;
      std::lock_guard<std::mutex> lock(waiter_.mutex());
      logs_.push_back(m);
      waiter_.notify();
    });
    diag_sub_ = nh_.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics", 100, [this](const diagnostic_msgs::DiagnosticArrayConstPtr& m) {
          std::lock_guard<std::mutex> lock(waiter_.mutex());
          for (const auto& s : m->status) status_[s.name] = s;
          waiter_.notify();
        });
    agg_sub_ = nh_.subscribe<diagnostic_msgs::DiagnosticArray>(
        "/diagnostics_agg", 10, [this](const diagnostic_msgs::DiagnosticArrayConstPtr& m) {
          std::lock_guard<std::mutex> lock(waiter_.mutex());
          size_t n = 0;
          for (const auto& s : m->status) n += s.name.rfind("/ACT color", 0) == 0 ? 1 : 0;  // the group, its two
          aggregated_ = n;
          waiter_.notify();
        });
    lut_sub_ = nh_.subscribe<act_color::ColorLut>("/act/color_lut", 50, [this](const act_color::ColorLutConstPtr& m) {
      std::lock_guard<std::mutex> lock(waiter_.mutex());
      luts_[m->header.stamp] = m;
      newest_ = m;
      waiter_.notify();
    });
    spinner_.start();
    ASSERT_TRUE(waiter_.waitFor(30.0, [this] {
      return image_pub_.getNumSubscribers() >= 1 && pose_pub_.getNumSubscribers() >= 1 &&
             lut_sub_.getNumPublishers() >= 1 && log_sub_.getNumPublishers() >= 1 && diag_sub_.getNumPublishers() >= 1;
    })) << "the nodelets did not connect";
    frame_ = act_color::sim::paintFlatFrame(*model_, pose_, 1.0, 3);
  }

  // Sends frames at ~20 Hz (pose first when `with_pose`: `told`, else the right one; stamped
  // `offset_s` from now) until `done` holds (checked under the waiter's mutex) or `timeout_s` passed.
  bool sendUntil(const cv::Mat& image, bool with_pose, double timeout_s, const std::function<bool()>& done,
                 double offset_s = 0.0, const core::Pose2D* told = nullptr) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout_s);
    while (ros::WallTime::now() < end) {
      const ros::Time t = ros::Time::now() + ros::Duration(offset_s);
      if (with_pose) pose_pub_.publish(makePose(told ? *told : pose_, t));
      image_pub_.publish(makeImage(image, "rgb8", t));
      last_sent_ = t;
      if (waiter_.waitFor(0.05, done)) return true;
    }
    return false;
  }
  // The latest diagnostics status whose name contains `task` (under the waiter's mutex).
  const diagnostic_msgs::DiagnosticStatus* status(const std::string& task) const {
    for (const auto& [name, s] : status_) {
      if (name.find(task) != std::string::npos) return &s;
    }
    return nullptr;
  }
  bool statusIs(const std::string& task, uint8_t level, const std::string& text) const {
    const auto* s = status(task);
    return s && s->level == level && s->message.find(text) != std::string::npos;
  }
  double value(const std::string& task, const std::string& key) const {
    const auto* s = status(task);
    for (const auto& kv : s->values) {
      if (kv.key == key) return std::stod(kv.value);
    }
    ADD_FAILURE() << "no value '" << key << "' in the status of " << task;
    return -1.0;
  }
  int countLogs(uint8_t level, const std::string& text) const {
    int n = 0;
    for (const auto& m : logs_) n += (m->level >= level && m->msg.find(text) != std::string::npos) ? 1 : 0;
    return n;
  }
  std::string describe(const std::string& task) {
    std::lock_guard<std::mutex> lock(waiter_.mutex());
    const auto* s = status(task);
    return s ? "level " + std::to_string(s->level) + ": " + s->message : "no status";
  }
  // The table that came last.
  act_color::ColorLutConstPtr latestTable() const { return newest_; }

  ros::NodeHandle nh_;
  ros::AsyncSpinner spinner_{2};
  std::unique_ptr<core::ExpectedClassModel> model_;
  std::string lut_file_, lut_dir_;
  const core::Pose2D pose_{-1.5, 1.0, 0.4};
  act_color::sim::LabeledFrame frame_;
  ros::Publisher image_pub_, pose_pub_;
  ros::Subscriber log_sub_, diag_sub_, agg_sub_, lut_sub_;
  size_t aggregated_ = 0;
  act_color_test::Waiter waiter_;
  std::vector<rosgraph_msgs::LogConstPtr> logs_;
  std::map<std::string, diagnostic_msgs::DiagnosticStatus> status_;
  std::map<ros::Time, act_color::ColorLutConstPtr> luts_;
  act_color::ColorLutConstPtr newest_;
  ros::Time last_sent_;
};

using diagnostic_msgs::DiagnosticStatus;

TEST_F(Operability, DiagnosticsReconfigureSaveLoadTimeJump) {
  const std::string trainer = "ACT trainer", segmentation = "segmentation";
  // 1. Images of the wrong size only: ERROR with the reason (not OK as before issue 14).
  const cv::Mat small(100, 100, CV_8UC3, cv::Scalar(30, 120, 30));
  EXPECT_TRUE(sendUntil(small, true, 15.0, [&] { return statusIs(trainer, DiagnosticStatus::ERROR, "100x100"); }))
      << describe(trainer);
  // 2. Good images, no new pose: ERROR "not training" with the reason.
  EXPECT_TRUE(sendUntil(frame_.rgb, false, 15.0, [&] {
    return statusIs(trainer, DiagnosticStatus::ERROR, "not training: the latest pose");
  })) << describe(trainer);
  // 3. Good images with poses: OK once the bad seconds have left the window; the start-up
  // training is reported apart from the cycle times.
  EXPECT_TRUE(sendUntil(frame_.rgb, true, 20.0, [&] { return statusIs(trainer, DiagnosticStatus::OK, "training"); }))
      << describe(trainer);
  {
    std::lock_guard<std::mutex> lock(waiter_.mutex());
    const double startup_ms = value(trainer, "start-up training (ms)");
    const double cycle_max_ms = value(trainer, "cycle time max (ms, last 5 s)");
    std::printf("start-up training %.1f ms, cycle time max %.2f ms, trained %.0f%%\n", startup_ms, cycle_max_ms,
                value(trainer, "trained (%, last 5 s)"));
    EXPECT_GT(startup_ms, 0.0);
    EXPECT_GT(cycle_max_ms, 0.0);
    EXPECT_LT(cycle_max_ms, startup_ms);
    EXPECT_GE(value(trainer, "trained (%, last 5 s)"), 90.0);
  }

  // 3b. Self-localization lost (the paper's 2.5 m and 165 degrees off): the table contradicts the
  // pose, those frames train nothing, and the diagnostics and the log say so (~pose_check) ...
  const core::Pose2D wrong = act_color::sim::wrongPose(pose_, 0.0);
  EXPECT_TRUE(sendUntil(
      frame_.rgb, true, 15.0,
      [&] { return statusIs(trainer, DiagnosticStatus::WARN, "the pose contradicted the color table"); }, 0.0, &wrong))
      << describe(trainer);
  EXPECT_TRUE(
      waiter_.waitFor(5.0, [&] { return countLogs(rosgraph_msgs::Log::WARN, "contradict the color table") > 0; }));
  // ... until it is right again.
  EXPECT_TRUE(sendUntil(frame_.rgb, true, 20.0, [&] { return statusIs(trainer, DiagnosticStatus::OK, "training"); }))
      << describe(trainer);

  // 4. dynamic_reconfigure: out of range is refused with the value as typed, the old value stays.
  auto reconfigure = [&](const std::string& node, const std::string& name, double v) {
    dynamic_reconfigure::Reconfigure srv;
    dynamic_reconfigure::DoubleParameter p;
    p.name = name;
    p.value = v;
    srv.request.config.doubles.push_back(p);
    EXPECT_TRUE(ros::service::call("/" + node + "/set_parameters", srv)) << node;
    for (const auto& d : srv.response.config.doubles) {
      if (d.name == name) return d.value;
    }
    ADD_FAILURE() << "no " << name << " in the answer of " << node;
    return -1.0;
  };
  EXPECT_DOUBLE_EQ(reconfigure("act_trainer", "zeta", 1000.0), 2.5);
  EXPECT_TRUE(waiter_.waitFor(5.0, [&] { return countLogs(rosgraph_msgs::Log::ERROR, "zeta must be in") > 0; }));
  {
    std::lock_guard<std::mutex> lock(waiter_.mutex());
    EXPECT_EQ(countLogs(rosgraph_msgs::Log::ERROR, "is 1000"), 1) << "the value as typed";
  }
  EXPECT_DOUBLE_EQ(reconfigure("act_trainer", "zeta", 3.0), 3.0);
  double zeta = 0;
  EXPECT_TRUE(nh_.getParam("/act_trainer/zeta", zeta));
  EXPECT_DOUBLE_EQ(zeta, 3.0);
  EXPECT_DOUBLE_EQ(reconfigure("act_trainer", "zeta", 2.5), 2.5);
  EXPECT_DOUBLE_EQ(reconfigure("segmentation", "max_wait", -1.0), 0.2);
  EXPECT_TRUE(waiter_.waitFor(5.0, [&] { return countLogs(rosgraph_msgs::Log::ERROR, "max_wait must be in") > 0; }));

  // 5. Save, train on, load: the table comes back with its clusters and revision.
  act_color::FilePath save;
  ASSERT_TRUE(ros::service::call("/act_trainer/save_lut", save));
  ASSERT_TRUE(save.response.success) << save.response.message;
  act_color::ColorLutConstPtr before_save;
  {
    std::lock_guard<std::mutex> lock(waiter_.mutex());
    before_save = latestTable();
  }
  ASSERT_TRUE(before_save);
  const uint64_t saved_revision =
      before_save->revision;  // no frame in between: the service runs on the trainer's queue
  std::printf("%s\n", save.response.message.c_str());
  EXPECT_NE(save.response.message.find("revision " + std::to_string(saved_revision)), std::string::npos);
  sendUntil(frame_.rgb, true, 10.0, [&] { return latestTable() && latestTable()->revision >= saved_revision + 10; });
  act_color::FilePath load;
  ASSERT_TRUE(ros::service::call("/act_trainer/load_lut", load));
  ASSERT_TRUE(load.response.success) << load.response.message;
  std::printf("%s\n", load.response.message.c_str());
  {
    std::lock_guard<std::mutex> lock(waiter_.mutex());
    luts_.clear();
    newest_.reset();
  }
  ASSERT_TRUE(sendUntil(frame_.rgb, true, 10.0, [&] { return latestTable() != nullptr; }));
  {
    std::lock_guard<std::mutex> lock(waiter_.mutex());
    const act_color::ColorLutConstPtr after = luts_.begin()->second;
    EXPECT_EQ(after->revision, saved_revision + 1) << "one cycle after the loaded revision";
    ASSERT_EQ(after->clusters.size(), before_save->clusters.size());
    for (size_t k = 0; k < after->clusters.size(); ++k) {
      if (before_save->clusters[k].lut_cells == 0) continue;
      // One cycle on (eta = 4) from the saved cluster, not from eq. 2-3 (mean 127.5, sigma 221).
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(after->clusters[k].mean[i], before_save->clusters[k].mean[i], 10.0) << k;
      EXPECT_LT(after->clusters[k].sigma, 100.0) << k;
    }
  }

  // 5b. Saves stay inside ~lut_dir and never overwrite an unrelated file; loads read regular files.
  {
    auto call = [](const std::string& service, const std::string& path) {
      act_color::FilePath srv;
      srv.request.path = path;
      EXPECT_TRUE(ros::service::call(service, srv));
      return srv.response;
    };
    const std::string unrelated = lut_dir_ + "/notes.lut";
    { std::ofstream(unrelated) << "team notes\n"; }
    for (const std::string& bad : {std::string("../escape.lut"), std::string("/etc/act_color.lut"),
                                   std::string("sub/../../escape.lut"), unrelated}) {
      const auto r = call("/act_trainer/save_lut", bad);
      EXPECT_FALSE(r.success) << bad;
      std::printf("save_lut %s: %s\n", bad.c_str(), r.message.c_str());
    }
    std::ifstream in(unrelated);
    std::string text;
    std::getline(in, text);
    EXPECT_EQ(text, "team notes") << "an unrelated file was overwritten";
    EXPECT_FALSE(std::ifstream("/tmp/escape.lut").good());
    const auto inside = call("/act_trainer/save_lut", "second.lut");
    EXPECT_TRUE(inside.success) << inside.message;
    const std::string fifo = lut_dir_ + "/fifo.lut";
    ::unlink(fifo.c_str());
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const auto from_fifo = call("/act_trainer/load_lut", fifo);
    EXPECT_FALSE(from_fifo.success);
    EXPECT_NE(from_fifo.message.find("not a regular file"), std::string::npos) << from_fifo.message;
    ::unlink(fifo.c_str());
  }

  // 6. Time jumps back 100 s (a bag played again): logged once per nodelet, the table kept.
  uint64_t revision_before_jump = 0;
  {
    std::lock_guard<std::mutex> lock(waiter_.mutex());
    revision_before_jump = latestTable()->revision;
  }
  int sent_after_jump = 0;
  EXPECT_TRUE(sendUntil(
      frame_.rgb, true, 10.0, [&] { return ++sent_after_jump >= 10 && latestTable()->header.stamp == last_sent_; },
      -100.0));
  {
    std::lock_guard<std::mutex> lock(waiter_.mutex());
    EXPECT_EQ(countLogs(rosgraph_msgs::Log::WARN, "time jumped back"), 2) << "trainer and segmentation, once each";
    EXPECT_GT(latestTable()->revision, revision_before_jump) << "the table is kept and trained on";
    EXPECT_LT(latestTable()->revision, revision_before_jump + 50) << "not trained again from the start";
  }

  // 7. The shipped aggregator config groups both nodelets under "ACT color".
  EXPECT_TRUE(waiter_.waitFor(10.0, [&] { return aggregated_ >= 3; }))
      << "statuses under /ACT color on /diagnostics_agg: " << aggregated_;

  // 8. No more images: both nodelets report their input stale.
  EXPECT_TRUE(waiter_.waitFor(10.0,
                              [&] {
                                return statusIs(trainer, DiagnosticStatus::WARN, "input stale") &&
                                       statusIs(segmentation, DiagnosticStatus::WARN, "input stale");
                              }))
      << describe(trainer) << " / " << describe(segmentation);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_operability");
  return RUN_ALL_TESTS();
}
