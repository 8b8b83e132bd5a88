// ActParams::carpet_edge (core::CarpetEdge): white beyond the carpet's edge, found in the labels
// along each bearing, is labelled unknown, and black there where no robot stands on the carpet;
// white on the carpet stays, however the carpet ends, and so do the robots' bodies.
#include <gtest/gtest.h>

#include <cmath>

#include "act_color/core/carpet_edge.hpp"
#include "act_color/core/omni_camera_model.hpp"
#include "act_color/core/types.hpp"
#include "test_util.hpp"

namespace act_color {
namespace {

struct Scene {
  cv::Mat labels;
  cv::Mat keep;  // white and black that must stay
  cv::Mat hall;  // white and black that must go
};

double bearingDeg(const core::PixelRay& ray) {
  double b = ray.bearing_rad * 180.0 / M_PI;
  return b < 0 ? b + 360.0 : b;
}

// Labels drawn from the camera model in base_link: a carpet out to 4 m, a line ring at 3.0-3.12 m
// and the outer line right at the carpet's edge (3.88-4.0 m, a lab field's wall behind it); the
// hall beyond it white in patches (5-6 m at bearings 40-80 degrees, and everything above the
// horizon at 200-220 and 355-360 degrees, the last sector of bearings) and black in one (5-6 m at
// 150-170 degrees). A robot (black, 2.0-2.4 m at 100-102 degrees) hides the carpet behind it;
// another stands at the carpet's edge (3.6-4.0 m at 250-254 degrees) and its body reaches on to
// 4.8 m in the image. At 300-340 degrees nothing is green (a part of the image the table does not
// know): the white there (at 6 m, away from the green sectors next to it) stays.
Scene makeScene(const core::OmniCameraModel& camera) {
  Scene s;
  const int w = camera.width(), h = camera.height();
  s.labels = cv::Mat(h, w, CV_8UC1, cv::Scalar(core::kUnknown));
  s.keep = cv::Mat::zeros(h, w, CV_8UC1);
  s.hall = cv::Mat::zeros(h, w, CV_8UC1);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const core::PixelRay& ray = camera.ray(u, v);
      uint8_t& l = s.labels.at<uint8_t>(v, u);
      auto set = [&](uint8_t k, bool stays) {
        l = k;
        (stays ? s.keep : s.hall).at<uint8_t>(v, u) = 1;
      };
      const double b = bearingDeg(ray);
      const bool unknown_sector = b >= 300 && b <= 340;
      if (ray.region == core::PixelRegion::kAboveHorizon && ((b >= 200 && b <= 220) || b >= 355)) {
        set(core::kWhite, false);
      }
      if (ray.region != core::PixelRegion::kFloor) continue;
      const double d = std::hypot(ray.ground_x_m, ray.ground_y_m);
      const bool edge_robot = b >= 250 && b <= 254 && d >= 3.6 && d < 4.8;
      if (edge_robot) {
        set(core::kBlack, true);
      } else if (d < 4.0) {
        const bool line = (d >= 3.0 && d < 3.12) || d >= 3.88;
        const bool robot = b >= 100 && b <= 102 && d >= 2.0;
        if (robot && d < 2.4) {
          set(core::kBlack, true);
        } else if (line) {  // behind the robot too: its sectors have no green beyond it
          set(core::kWhite, true);
        } else if (!unknown_sector && !robot) {
          l = core::kGreen;
        }
      } else if (d >= 5.0 && d < 6.0 && b >= 40 && b <= 80) {
        set(core::kWhite, false);
      } else if (d >= 5.0 && d < 6.0 && b >= 150 && b <= 170) {
        set(core::kBlack, false);
      } else if (b >= 305 && b <= 335 && d >= 6.0 && d < 6.2) {
        set(core::kWhite, true);
      }
    }
  }
  return s;
}

TEST(CarpetEdge, HallWhiteAndBlackGoLinesAndRobotsStay) {
  const core::OmniCameraModel camera(test::defaultCalibration().camera);
  const core::CarpetEdge edge(camera);
  Scene s = makeScene(camera);
  const cv::Mat black_hall = s.hall & (s.labels == core::kBlack), black_kept = s.keep & (s.labels == core::kBlack);
  const int hall = cv::countNonZero(s.hall), kept = cv::countNonZero(s.keep);
  ASSERT_GT(hall, 100);
  ASSERT_GT(kept, 1000);
  ASSERT_GT(cv::countNonZero(black_hall), 100);
  ASSERT_GT(cv::countNonZero(black_kept), 100);
  const cv::Mat before = s.labels.clone();
  const uint32_t unlabelled = edge.unlabelBeyond(s.labels);
  EXPECT_EQ(unlabelled, static_cast<uint32_t>(hall));
  EXPECT_EQ(cv::countNonZero((s.labels == before) & (s.keep != 0)), kept);
  EXPECT_EQ(cv::countNonZero((s.labels == core::kUnknown) & (s.hall != 0)), hall);
  // Nothing but white and black is touched, and they only become unknown.
  EXPECT_EQ(cv::countNonZero((s.labels != before) & (before != core::kWhite) & (before != core::kBlack)), 0);
  EXPECT_EQ(cv::countNonZero((s.labels != before) & (s.labels != core::kUnknown)), 0);
}

TEST(CarpetEdge, NoGreenNothingKnownNothingChanged) {
  const core::OmniCameraModel camera(test::defaultCalibration().camera);
  const core::CarpetEdge edge(camera);
  cv::Mat labels(camera.height(), camera.width(), CV_8UC1, cv::Scalar(core::kWhite));
  EXPECT_EQ(edge.unlabelBeyond(labels), 0u);
  EXPECT_EQ(cv::countNonZero(labels != core::kWhite), 0);
  // Labels of another size are left alone.
  cv::Mat small(10, 10, CV_8UC1, cv::Scalar(core::kWhite));
  EXPECT_EQ(edge.unlabelBeyond(small), 0u);
}

}  // namespace
}  // namespace act_color
