// The segmentation nodelet alone, fed by the test as the ACT trainer would feed it: the ball the
// trainer saw in an image (/act/ball) is labelled as the ball's image in that image's labels
// (core::labelBallImage), and in no other image's; an image no table can classify is refused
// when it comes; white beyond the carpet's edge is unknown unless ~carpet_edge is switched off.
#include <dynamic_reconfigure/Reconfigure.h>
#include <geometry_msgs/PointStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/core.hpp>
#include <string>
#include <tuple>

#include "act_color/ColorLut.h"
#include "act_color/core/ball_detector.hpp"
#include "act_color/core/calibration.hpp"
#include "act_color/core/carpet_edge.hpp"
#include "act_color/core/omni_camera_model.hpp"
#include "test_util.hpp"

namespace {

namespace core = act_color::core;

// The test's side of the segmentation nodelet, as the trainer and a listener would be: the inputs
// it is fed and the labels it publishes, by stamp.
struct SegmentationFeed {
  ros::NodeHandle nh, pnh{"~"};
  const core::Calibration cal = core::loadCalibration(pnh.param<std::string>("calibration", ""));
  const core::OmniCameraModel camera{cal.camera};
  ros::Publisher image_pub = nh.advertise<sensor_msgs::Image>("/omni/image_raw", 10);
  ros::Publisher lut_pub = nh.advertise<act_color::ColorLut>("/act/color_lut", 10);
  ros::Publisher ball_pub = nh.advertise<geometry_msgs::PointStamped>("/act/ball", 10);
  act_color_test::Waiter waiter;
  std::map<ros::Time, sensor_msgs::ImageConstPtr> labels;  // under waiter.mutex()
  ros::Subscriber labels_sub =
      nh.subscribe<sensor_msgs::Image>("/segmentation/labels", 10, [this](const sensor_msgs::ImageConstPtr& msg) {
        std::lock_guard<std::mutex> lock(waiter.mutex());
        labels[msg->header.stamp] = msg;
        waiter.notify();
      });
  ros::AsyncSpinner spinner{2};

  SegmentationFeed() { spinner.start(); }
  bool connected() {
    return waiter.waitFor(30.0, [&] {
      return image_pub.getNumSubscribers() > 0 && lut_pub.getNumSubscribers() > 0 && ball_pub.getNumSubscribers() > 0 &&
             labels_sub.getNumPublishers() > 0;
    });
  }
  // A table of 6 bits per channel in RGB that knows no color.
  static act_color::ColorLut emptyTable() {
    act_color::ColorLut lut;
    lut.color_space = act_color::ColorLut::COLOR_SPACE_RGB;
    lut.bits_per_channel = 6;
    lut.table.assign(size_t{1} << 18, core::kUnknown);
    return lut;
  }
  // An rgb8 image of the camera's size, every pixel `grey`.
  sensor_msgs::Image image(uint8_t grey) const {
    sensor_msgs::Image m;
    m.width = static_cast<uint32_t>(camera.width());
    m.height = static_cast<uint32_t>(camera.height());
    m.encoding = "rgb8";
    m.step = 3 * m.width;
    m.data.assign(static_cast<size_t>(m.step) * m.height, grey);
    return m;
  }
};

TEST(Segmentation, LabelsTheBallTheTrainerSaw) {
  SegmentationFeed feed;
  ASSERT_TRUE(feed.connected()) << "the segmentation did not connect";
  const core::OmniCameraModel& camera = feed.camera;
  ros::Publisher &image_pub = feed.image_pub, &lut_pub = feed.lut_pub, &ball_pub = feed.ball_pub;
  act_color_test::Waiter& waiter = feed.waiter;
  auto& labels = feed.labels;
  // A table that knows no color: every label is unknown but the ball's image.
  act_color::ColorLut lut = SegmentationFeed::emptyTable();
  sensor_msgs::Image image = feed.image(128);
  const double ball_x = 1.0, ball_y = 0.4;  // base_link, m
  const ros::Time seen(1000, 0), unseen(1000, 100000000);
  for (const ros::Time& stamp : {seen, unseen}) {
    if (stamp == seen) {
      geometry_msgs::PointStamped ball;
      ball.header.stamp = stamp;
      ball.header.frame_id = "base_link";
      ball.point.x = ball_x;
      ball.point.y = ball_y;
      ball_pub.publish(ball);
      // The trainer publishes the ball before the table in one manager; over two connections the
      // test waits for it to arrive first.
      ros::WallDuration(0.5).sleep();
    }
    lut.header.stamp = stamp;
    ++lut.revision;
    lut_pub.publish(lut);
    image.header.stamp = stamp;
    image_pub.publish(image);
  }
  ASSERT_TRUE(waiter.waitFor(30.0, [&] { return labels.size() >= 2; })) << labels.size() << " label images";
  std::lock_guard<std::mutex> lock(waiter.mutex());
  cv::Mat expected(camera.height(), camera.width(), CV_8UC1, cv::Scalar(core::kUnknown));
  const uint32_t ball_pixels = core::labelBallImage(camera, 0.11, ball_x, ball_y, expected);
  ASSERT_GT(ball_pixels, 20u);
  auto orange = [&](const ros::Time& stamp) {
    const sensor_msgs::Image& m = *labels.at(stamp);
    const cv::Mat l(m.height, m.width, CV_8UC1, const_cast<uint8_t*>(m.data.data()), m.step);
    return cv::countNonZero(l == core::kOrange);
  };
  EXPECT_EQ(orange(seen), static_cast<int>(ball_pixels));
  EXPECT_EQ(orange(unseen), 0);
}

TEST(Segmentation, RefusesAnImageNoTableCanClassifyOnArrival) {
  // segmentation.test sets ~max_wait to 5 s. An image of an encoding no table classifies is
  // refused when it comes, not after waiting that long for its table.
  ros::NodeHandle nh;
  ros::Publisher image_pub = nh.advertise<sensor_msgs::Image>("/omni/image_raw", 10);
  act_color_test::Waiter waiter;
  ros::WallTime refused;
  ros::Subscriber log_sub = nh.subscribe<rosgraph_msgs::Log>("/rosout", 100, [&](const rosgraph_msgs::LogConstPtr& m) {
    if (m->level < rosgraph_msgs::Log::ERROR || m->msg.find("unsupported encoding 'mono16'") == std::string::npos)
      return;
    std::lock_guard<std::mutex> lock(waiter.mutex());
    if (refused.isZero()) refused = ros::WallTime::now();
    waiter.notify();
  });
  ros::AsyncSpinner spinner(2);
  spinner.start();
  // /rosout has two publishers here: this test and the manager; the manager's error must not go
  // out before the link to it stands.
  ASSERT_TRUE(
      waiter.waitFor(30.0, [&] { return image_pub.getNumSubscribers() > 0 && log_sub.getNumPublishers() >= 2; }));
  ros::WallDuration(0.5).sleep();
  sensor_msgs::Image image;
  image.width = 580;
  image.height = 580;
  image.encoding = "mono16";
  image.step = 2 * image.width;
  image.data.assign(static_cast<size_t>(image.step) * image.height, 0);
  image.header.stamp = ros::Time(2000, 0);
  const ros::WallTime sent = ros::WallTime::now();
  image_pub.publish(image);
  ASSERT_TRUE(waiter.waitFor(20.0, [&] { return !refused.isZero(); })) << "no error for the mono16 image";
  std::lock_guard<std::mutex> lock(waiter.mutex());
  EXPECT_LT((refused - sent).toSec(), 2.5) << "refused only after waiting for a table";
}

TEST(Segmentation, WhiteBeyondTheCarpetIsUnknownUnlessSwitchedOff) {
  SegmentationFeed feed;
  ASSERT_TRUE(feed.connected()) << "the segmentation did not connect";
  const core::OmniCameraModel& camera = feed.camera;
  ros::Publisher &image_pub = feed.image_pub, &lut_pub = feed.lut_pub;
  act_color_test::Waiter& waiter = feed.waiter;
  auto& labels = feed.labels;
  // Carpet to 3 m (a green the table knows), a white hall beyond it and above the horizon.
  const uint8_t carpet[3] = {20, 140, 20}, hall[3] = {250, 250, 250};
  act_color::ColorLut lut = SegmentationFeed::emptyTable();
  auto cell = [](const uint8_t c[3]) { return (size_t{c[0]} >> 2) << 12 | (size_t{c[1]} >> 2) << 6 | (c[2] >> 2); };
  lut.table[cell(carpet)] = core::kGreen;
  lut.table[cell(hall)] = core::kWhite;
  sensor_msgs::Image image = feed.image(0);
  // The hall, and the part of it farther than the edge's margin (core::CarpetEdge::kMarginM, the
  // 0.1 m bins rounded) from the carpet: always unknown with ~carpet_edge.
  int hall_pixels = 0;
  cv::Mat far_hall(camera.height(), camera.width(), CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      const core::PixelRay& ray = camera.ray(u, v);
      if (ray.region != core::PixelRegion::kFloor && ray.region != core::PixelRegion::kAboveHorizon) continue;
      const bool on_carpet =
          ray.region == core::PixelRegion::kFloor && std::hypot(ray.ground_x_m, ray.ground_y_m) < 3.0;
      hall_pixels += !on_carpet;
      far_hall.at<uint8_t>(v, u) = ray.region == core::PixelRegion::kAboveHorizon ||
                                   std::hypot(ray.ground_x_m, ray.ground_y_m) >= 3.0 + core::CarpetEdge::kMarginM + 0.2;
      std::copy(on_carpet ? carpet : hall, (on_carpet ? carpet : hall) + 3, &image.data[image.step * v + 3 * u]);
    }
  }
  ASSERT_GT(hall_pixels, 1000);
  auto carpetEdge = [&](bool on) {
    dynamic_reconfigure::Reconfigure srv;
    dynamic_reconfigure::BoolParameter p;
    p.name = "carpet_edge";
    p.value = on;
    srv.request.config.bools.push_back(p);
    EXPECT_TRUE(ros::service::call("/segmentation/set_parameters", srv));
  };
  // White pixels in the labels of an image with this stamp; `far`: only those of far_hall.
  auto whiteIn = [&](const ros::Time& stamp, bool far) {
    lut.header.stamp = stamp;
    ++lut.revision;
    lut_pub.publish(lut);
    image.header.stamp = stamp;
    image_pub.publish(image);
    EXPECT_TRUE(waiter.waitFor(30.0, [&] { return labels.count(stamp) > 0; })) << "no labels at " << stamp;
    std::lock_guard<std::mutex> lock(waiter.mutex());
    if (!labels.count(stamp)) return -1;
    const sensor_msgs::Image& m = *labels.at(stamp);
    const cv::Mat l(m.height, m.width, CV_8UC1, const_cast<uint8_t*>(m.data.data()), m.step);
    return cv::countNonZero(far ? (l == core::kWhite) & far_hall : l == core::kWhite);
  };
  const int far_pixels = cv::countNonZero(far_hall);
  ASSERT_GT(far_pixels, hall_pixels / 2);
  EXPECT_EQ(whiteIn(ros::Time(3000, 0), true), 0);
  carpetEdge(false);
  EXPECT_EQ(whiteIn(ros::Time(3000, 100000000), false), hall_pixels);
  carpetEdge(true);
  EXPECT_EQ(whiteIn(ros::Time(3000, 200000000), true), 0);
  EXPECT_LT(whiteIn(ros::Time(3000, 300000000), false), hall_pixels - far_pixels + 1);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_segmentation");
  return RUN_ALL_TESTS();
}
