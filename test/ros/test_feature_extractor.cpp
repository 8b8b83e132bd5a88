// The segmentation nodelet's ROS-free parts: classification with a borrowed table and feature
// extraction. Plain gtest, no master.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "act_color/core/act_trainer.hpp"
#include "act_color/core/calibration.hpp"
#include "act_color/core/feature_extractor.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/sim/flat_painter.hpp"

namespace {

namespace core = act_color::core;

core::Calibration calibration() {
  return core::loadCalibration(ACT_SOURCE_DIR "/config/calibration/msl_2007_580.yaml");
}

TEST(Segmenter, ABorrowedTableClassifiesLikeTheOwnedOne) {
  const core::Calibration cal = calibration();
  core::ActTrainer trainer(cal);
  const core::Pose2D pose{-1.5, 1.0, 0.4};
  const auto frame = act_color::sim::paintFlatFrame(trainer.model(), pose, 1.0, 5);
  const auto view = core::ImageView::fromMat(frame.rgb, core::PixelFormat::kRgb8);
  trainer.bootstrap(view, pose, 10);
  cv::Mat expected, labels;
  core::Segmenter(cal.camera).classify(trainer.lut(), view, expected);
  core::LutView lut{trainer.lut().data(), trainer.lut().size(), trainer.lut().bitsPerChannel(),
                    trainer.lut().colorSpace()};
  const core::Segmenter segmenter(cal.camera);
  segmenter.classify(lut, view, labels);
  EXPECT_EQ(cv::countNonZero(labels != expected), 0);
  EXPECT_GT(cv::countNonZero(labels == core::kGreen), 50000);

  // BGR gives the same labels for the same colors.
  cv::Mat bgr, labels_bgr;
  cv::cvtColor(frame.rgb, bgr, cv::COLOR_RGB2BGR);
  segmenter.classify(lut, core::ImageView::fromMat(bgr, core::PixelFormat::kBgr8), labels_bgr);
  EXPECT_EQ(cv::countNonZero(labels_bgr != expected), 0);

  // Wrong size, wrong color space, inconsistent table: errors, not crashes.
  cv::Mat small(100, 100, CV_8UC3, cv::Scalar::all(0));
  EXPECT_THROW(segmenter.classify(lut, core::ImageView::fromMat(small, core::PixelFormat::kRgb8), labels),
               std::invalid_argument);
  const cv::Mat uyvy = core::rgbToUyvy(frame.rgb);
  EXPECT_THROW(segmenter.classify(lut, core::ImageView::fromMat(uyvy, core::PixelFormat::kUyvy), labels),
               std::invalid_argument);
  core::LutView broken = lut;
  broken.size = 10;
  EXPECT_THROW(segmenter.classify(broken, view, labels), std::invalid_argument);
}

TEST(FeatureExtractor, LinesAndGoalsWhereTheFieldHasThem) {
  const core::Calibration cal = calibration();
  const core::ExpectedClassModel model(cal);
  // Near the yellow goal, facing it: lines, penalty area and the goal in view.
  const core::Pose2D pose{5.5, 0.5, 0.2};
  const auto frame = act_color::sim::paintFlatFrame(model, pose, 1.0, 9);
  std::vector<core::Feature> features = core::extractFeatures(frame.labels, model.camera());
  core::toField(pose, &features);
  int lines = 0, lines_on_line = 0, yellow = 0, yellow_at_goal = 0;
  for (const core::Feature& f : features) {
    if (f.type == core::FeatureType::kLinePoint) {
      ++lines;
      // Within 10 cm of a line (pixel quantisation far out).
      bool near = false;
      for (double dx = -0.1; dx <= 0.1 && !near; dx += 0.05)
        for (double dy = -0.1; dy <= 0.1 && !near; dy += 0.05)
          near = model.field().isLine(f.field_x_m + dx, f.field_y_m + dy);
      lines_on_line += near ? 1 : 0;
    } else if (f.type == core::FeatureType::kYellowGoal) {
      ++yellow;
      // The goal's foot: at or behind the goal line, within the goal's width.
      yellow_at_goal += (f.field_x_m > 8.8 && f.field_x_m < 9.7 && std::abs(f.field_y_m) < 1.3) ? 1 : 0;
    }
  }
  std::printf("%d line points (%d on a line), %d yellow goal points (%d at the goal)\n", lines, lines_on_line, yellow,
              yellow_at_goal);
  EXPECT_GT(lines, 40);
  EXPECT_GE(lines_on_line, 0.95 * lines);
  EXPECT_GT(yellow, 5);
  EXPECT_GE(yellow_at_goal, 0.9 * yellow);
}

TEST(FeatureExtractor, BallAndObstacleAtTheirFloorPoints) {
  const core::Calibration cal = calibration();
  const core::OmniCameraModel camera(cal.camera);
  cv::Mat labels(cal.camera.height, cal.camera.width, CV_8UC1, cv::Scalar(core::kGreen));
  double u, v;
  // A ball 2 m ahead (its innermost pixel at its floor contact), an obstacle 1.5 m to the left.
  ASSERT_TRUE(camera.projectFloorPoint(2.0, 0.0, &u, &v));
  cv::circle(labels, cv::Point(static_cast<int>(std::lround(u)) + 5, static_cast<int>(std::lround(v))), 5,
             cv::Scalar(core::kOrange), cv::FILLED);
  labels.at<uint8_t>(static_cast<int>(std::lround(v)), static_cast<int>(std::lround(u))) = core::kOrange;
  ASSERT_TRUE(camera.projectFloorPoint(0.0, 1.5, &u, &v));
  const double cx = cal.camera.center_u, cy = cal.camera.center_v;
  const double a = std::atan2(v - cy, u - cx), r = std::hypot(u - cx, v - cy);
  for (double da = -0.15; da <= 0.15; da += 0.005)
    for (double dr = 0; dr < 40; dr += 0.5)
      labels.at<uint8_t>(static_cast<int>(std::lround(cy + (r + dr) * std::sin(a + da))),
                         static_cast<int>(std::lround(cx + (r + dr) * std::cos(a + da)))) = core::kBlack;
  std::vector<core::Feature> features = core::extractFeatures(labels, camera);
  core::toField(core::Pose2D{1.0, -1.0, M_PI / 2}, &features);
  int balls = 0, obstacles = 0;
  for (const core::Feature& f : features) {
    if (f.type == core::FeatureType::kBall) {
      ++balls;
      EXPECT_NEAR(f.base_x_m, 2.0, 0.1);
      EXPECT_NEAR(f.base_y_m, 0.0, 0.1);
      // Field: robot at (1, -1) facing +y.
      EXPECT_NEAR(f.field_x_m, 1.0, 0.1);
      EXPECT_NEAR(f.field_y_m, 1.0, 0.1);
    } else if (f.type == core::FeatureType::kObstacle) {
      ++obstacles;
      EXPECT_NEAR(f.base_x_m, 0.0, 0.1);
      EXPECT_NEAR(f.base_y_m, 1.5, 0.1);
      EXPECT_GT(f.size, 3u);  // merged over neighbouring scan lines
    }
  }
  EXPECT_EQ(balls, 1);
  EXPECT_EQ(obstacles, 1);
  cv::Mat wrong(10, 10, CV_8UC1);
  EXPECT_THROW(core::extractFeatures(wrong, camera), std::invalid_argument);
}

// Features whose floor point lies beyond the carpet (hall clutter, people) are dropped; those on
// it, including the goals' depth behind the goal lines, are kept.
TEST(FeatureExtractor, OnlyFeaturesOnTheCarpetRemain) {
  const core::Calibration cal = calibration();  // 18 x 12 m, margin 1 m, goals 0.5 m deep
  std::vector<core::Feature> features(6);
  const float at[6][2] = {{0.f, 0.f}, {9.9f, 6.9f}, {-9.5f, 0.f}, {10.1f, 0.f}, {0.f, -7.1f}, {NAN, 0.f}};
  for (size_t i = 0; i < features.size(); ++i) {
    features[i].field_x_m = at[i][0];
    features[i].field_y_m = at[i][1];
    features[i].size = static_cast<uint32_t>(i);
  }
  core::removeOffField(cal.field, &features);
  ASSERT_EQ(features.size(), 3u);
  EXPECT_EQ(features[0].size, 0u);
  EXPECT_EQ(features[1].size, 1u);
  EXPECT_EQ(features[2].size, 2u);
}

}  // namespace
