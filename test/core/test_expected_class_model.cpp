#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "act_color/core/expected_class_model.hpp"
#include "test_util.hpp"

using namespace act_color::core;

namespace {

// Index of the pixel that sees the field point (fx, fy) from `pose`.
size_t pixelSeeing(const ExpectedClassModel& model, const Pose2D& pose, double fx, double fy) {
  const double dx = fx - pose.x_m, dy = fy - pose.y_m;
  const double c = std::cos(pose.theta_rad), s = std::sin(pose.theta_rad);
  double u, v;
  EXPECT_TRUE(model.camera().projectFloorPoint(c * dx + s * dy, -s * dx + c * dy, &u, &v));
  return static_cast<size_t>(std::lround(v)) * model.camera().width() + static_cast<size_t>(std::lround(u));
}

}  // namespace

TEST(ExpectedClassModel, ChassisAndNotImaged) {
  const ExpectedClassModel model(act_color::test::defaultCalibration());
  const PoseTransform pose(Pose2D{});
  EXPECT_EQ(model.geometricClass(290 * 580 + 290, pose), kBlack);
  EXPECT_EQ(model.geometricClass(0, pose), kNotImaged);
}

TEST(ExpectedClassModel, FloorClassFollowsThePose) {
  const ExpectedClassModel model(act_color::test::defaultCalibration());
  struct Case {
    Pose2D pose;
    double fx, fy;  // field point within a few metres, where a pixel is a few cm wide
    uint8_t expected;
  };
  const Case cases[] = {
      {{6.0, 0.8, 0.3}, 6.81, 0.5, kWhite},     // penalty area line
      {{6.0, 0.8, 0.3}, 6.5, 0.5, kGreen},      //
      {{-3.0, 4.0, 2.5}, -3.0, 5.94, kWhite},   // side line
      {{-3.0, 4.0, 2.5}, -2.0, 5.5, kGreen},    //
      {{-3.0, 4.0, 2.5}, -3.5, 7.3, kUnknown},  // beyond the margin
      {{0.5, -1.0, -1.2}, 0.02, -0.5, kWhite},  // halfway line
      {{0.5, -1.0, -1.2}, 1.0, -0.2, kGreen},   //
  };
  for (const Case& c : cases) {
    EXPECT_EQ(model.geometricClass(pixelSeeing(model, c.pose, c.fx, c.fy), PoseTransform(c.pose)), c.expected)
        << c.fx << ", " << c.fy;
  }
}

TEST(ExpectedClassModel, GoalRegionIsWhereRaysMeetTheGoal) {
  const ExpectedClassModel model(act_color::test::defaultCalibration());
  const OmniCameraModel& camera = model.camera();
  const Pose2D pose{5.0, 0.0, 0.0};
  const PoseTransform t(pose);
  double u, v;
  // Just above the horizon towards +x: at x = 9 the ray is at 0.75 + 4 tan(0.05) = 0.95 m.
  ASSERT_TRUE(camera.projectDirection(0.0, 0.05, &u, &v));
  EXPECT_EQ(model.geometricClass(std::lround(v) * 580 + std::lround(u), t), kYellow);
  // Higher: over the crossbar.
  ASSERT_TRUE(camera.projectDirection(0.0, 0.15, &u, &v));
  EXPECT_EQ(model.geometricClass(std::lround(v) * 580 + std::lround(u), t), kUnknown);
  // Towards -x the blue goal is 14 m away: the ray passes over it at this elevation...
  ASSERT_TRUE(camera.projectDirection(M_PI, 0.05, &u, &v));
  EXPECT_EQ(model.geometricClass(std::lround(v) * 580 + std::lround(u), t), kUnknown);
  // ...and a floor ray ending on the goal's floor is in the goal region.
  EXPECT_EQ(model.geometricClass(pixelSeeing(model, pose, 9.25, 0.0), t), kYellow);
  // Rotated by pi the yellow goal is behind.
  const Pose2D turned{5.0, 0.0, M_PI};
  ASSERT_TRUE(camera.projectDirection(M_PI, 0.05, &u, &v));
  EXPECT_EQ(model.geometricClass(std::lround(v) * 580 + std::lround(u), PoseTransform(turned)), kYellow);
}

TEST(ExpectedClassModel, WhiteFilterIsEquationOne) {
  cv::Mat img(20, 20, CV_8UC3, cv::Scalar(100, 100, 100));
  const ImageView view = ImageView::fromMat(img, PixelFormat::kRgb8);
  EXPECT_FALSE(ExpectedClassModel::brighterThanNeighbourhood(view, 10, 10));  // equal, not brighter
  img.at<cv::Vec3b>(10, 10) = cv::Vec3b(104, 100, 100);
  EXPECT_TRUE(ExpectedClassModel::brighterThanNeighbourhood(view, 10, 10));
  // The neighbourhood is 5x5: a bright pixel 2 px away lifts the mean above the centre...
  img.at<cv::Vec3b>(12, 12) = cv::Vec3b(255, 255, 255);
  EXPECT_FALSE(ExpectedClassModel::brighterThanNeighbourhood(view, 10, 10));
  // ...one 3 px away does not count.
  img.at<cv::Vec3b>(12, 12) = cv::Vec3b(100, 100, 100);
  img.at<cv::Vec3b>(13, 13) = cv::Vec3b(255, 255, 255);
  EXPECT_TRUE(ExpectedClassModel::brighterThanNeighbourhood(view, 10, 10));
  EXPECT_FALSE(ExpectedClassModel::brighterThanNeighbourhood(view, 1, 10));  // border
  // A line pixel 3 px wide (on an image row) is brighter than its neighbourhood.
  cv::Mat line(20, 20, CV_8UC3, cv::Scalar(40, 120, 40));
  line.rowRange(9, 12).setTo(cv::Scalar(200, 200, 200));
  EXPECT_TRUE(ExpectedClassModel::brighterThanNeighbourhood(ImageView::fromMat(line, PixelFormat::kBgr8), 10, 10));
  // Same in UYVY: intensity is Y.
  const cv::Mat uyvy = rgbToUyvy(line);
  EXPECT_TRUE(ExpectedClassModel::brighterThanNeighbourhood(ImageView::fromMat(uyvy, PixelFormat::kUyvy), 10, 10));
  EXPECT_FALSE(ExpectedClassModel::brighterThanNeighbourhood(ImageView::fromMat(uyvy, PixelFormat::kUyvy), 10, 5));
}

TEST(ExpectedClassModel, SkippedPixelsAreNeverUnknown) {
  const ExpectedClassModel model(act_color::test::defaultCalibration());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> x(-10.0, 10.0), y(-7.0, 7.0), th(-M_PI, M_PI);
  for (int trial = 0; trial < 5; ++trial) {
    const Pose2D pose{x(rng), y(rng), th(rng)};
    const PoseTransform t(pose);
    const double safe = model.safeCarpetRange(pose);
    size_t skipped = 0;
    for (size_t i = 0; i < 580u * 580u; i += 7) {
      if (!model.surelyOnCarpet(i, safe)) continue;
      ++skipped;
      const uint8_t c = model.geometricClass(i, t);
      ASSERT_TRUE(c == kGreen || c == kWhite) << "pixel " << i << " class " << int(c);
    }
    if (safe > 1.0) {
      EXPECT_GT(skipped, 0u);
    }
  }
  EXPECT_NEAR(model.safeCarpetRange(Pose2D{0, 0, 0}), 7.0, 1e-9);  // 6 m half width + 1 m margin
  EXPECT_NEAR(model.safeCarpetRange(Pose2D{8, 0, 0}), 1.0, 1e-9);  // 1 m to the goal
}

TEST(ExpectedClassModel, PixelsBelowTheirSectorsSafeRangeAreNeverUnknown) {
  const ExpectedClassModel model(act_color::test::defaultCalibration());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> x(-9.5, 9.5), y(-7.5, 7.5), th(-M_PI, M_PI);
  std::array<double, ExpectedClassModel::kRemovalSectors> safe;
  size_t skipped_total = 0, skipped_by_carpet_range = 0;
  for (int trial = 0; trial < 12; ++trial) {
    const Pose2D pose = trial == 0 ? Pose2D{0, 0, 0} : Pose2D{x(rng), y(rng), th(rng)};
    const PoseTransform t(pose);
    model.sectorSafeRanges(pose, safe);
    const double carpet_range = model.safeCarpetRange(pose);
    for (size_t i = 0; i < 580u * 580u; i += 3) {
      const float range = model.removalRange(i);
      if (!(range > -std::numeric_limits<float>::infinity())) continue;
      if (ExpectedClassModel::mayBeOffField(range, carpet_range) == false) ++skipped_by_carpet_range;
      if (ExpectedClassModel::mayBeOffField(range, safe[static_cast<size_t>(model.removalSector(i))])) continue;
      ++skipped_total;
      const uint8_t c = model.geometricClass(i, t);
      ASSERT_TRUE(c == kGreen || c == kWhite)
          << "pose " << pose.x_m << " " << pose.y_m << " " << pose.theta_rad << " pixel " << i << " class " << int(c);
    }
  }
  // The sectors skip more than the one safe range for all directions does.
  EXPECT_GT(skipped_total, skipped_by_carpet_range + skipped_by_carpet_range / 10);
  // Beyond the goal line or off the carpet nothing is skipped.
  model.sectorSafeRanges(Pose2D{9.2, 0.0, 0.3}, safe);
  for (double s : safe) EXPECT_EQ(s, 0.0);
  // At the centre: the sector that starts at +y reaches the side line plus margin after 7 m, the
  // next one after 7 m / cos(one sector), the one that starts at +x the goal line after 9 m.
  model.sectorSafeRanges(Pose2D{0.0, 0.0, 0.0}, safe);
  const size_t along_y = ExpectedClassModel::kRemovalSectors / 4;
  EXPECT_NEAR(safe[along_y], 7.0, 1e-3);
  EXPECT_NEAR(safe[along_y + 1], 7.0 / std::cos(2 * M_PI / ExpectedClassModel::kRemovalSectors), 1e-3);
  EXPECT_NEAR(safe[0], 9.0, 1e-3);
}

TEST(ExpectedClassModel, PixelsBeyondTheirSectorsOffRangeAreAlwaysOffTheField) {
  // The removal step trusts sectorOffRanges instead of a ray cast: every pixel beyond its sector's
  // off range must be off the field, at poses all over the carpet, near the goals and its corners,
  // on the contract's camera and on a tilted one.
  for (const bool tilted : {false, true}) {
    Calibration cal = act_color::test::defaultCalibration();
    if (tilted) {
      cal.camera.tilt_x_rad = 0.03;
      cal.camera.tilt_y_rad = -0.02;
    }
    const ExpectedClassModel model(cal);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> x(-9.9, 9.9), y(-6.9, 6.9), th(-M_PI, M_PI);
    std::array<double, ExpectedClassModel::kRemovalSectors> off;
    size_t shortcut = 0, off_field = 0;
    for (int trial = 0; trial < 16; ++trial) {
      const Pose2D pose = trial == 0   ? Pose2D{0, 0, 0}
                          : trial == 1 ? Pose2D{8.8, 0.5, 2.0}
                                       : Pose2D{x(rng), y(rng), th(rng)};
      const PoseTransform t(pose);
      model.sectorOffRanges(pose, off);
      for (size_t i = 0; i < 580u * 580u; i += 3) {
        const float range = model.removalRange(i);
        if (!(range > -std::numeric_limits<float>::infinity())) continue;
        const bool is_off = model.offField(i, t);
        off_field += is_off;
        if (!(range > off[static_cast<size_t>(model.removalSector(i))])) continue;
        ++shortcut;
        ASSERT_TRUE(is_off) << "pose " << pose.x_m << " " << pose.y_m << " " << pose.theta_rad << " pixel " << i;
      }
    }
    // Most pixels off the field need no ray cast.
    EXPECT_GT(shortcut, off_field / 2) << tilted;
  }
  // Off the carpet: no sector is trusted.
  const ExpectedClassModel model(act_color::test::defaultCalibration());
  std::array<double, ExpectedClassModel::kRemovalSectors> off;
  model.sectorOffRanges(Pose2D{0.0, 9.0, 0.0}, off);
  for (const double r : off) EXPECT_EQ(r, std::numeric_limits<double>::infinity());
}

TEST(ExpectedClassModel, ExpectedLabelsMarkRejectedWhite) {
  const ExpectedClassModel model(act_color::test::defaultCalibration());
  cv::Mat flat(580, 580, CV_8UC3, cv::Scalar(50, 140, 50));  // lines invisible: eq. 1 rejects them all
  const cv::Mat labels = model.expectedLabels(ImageView::fromMat(flat, PixelFormat::kRgb8), Pose2D{});
  EXPECT_EQ(cv::countNonZero(labels == kWhite), 0);
  EXPECT_GT(cv::countNonZero(labels == kRejectedWhite), 100);
  EXPECT_GT(cv::countNonZero(labels == kGreen), 50000);
  EXPECT_EQ(labels.at<uint8_t>(290, 290), kBlack);
  EXPECT_EQ(labels.at<uint8_t>(0, 0), kNotImaged);
}
