#include <gtest/gtest.h>

#include <cmath>

#include "act_color/core/omni_camera_model.hpp"
#include "test_util.hpp"

using namespace act_color::core;

TEST(OmniCameraModel, ElevationIsInterpolatedLinearlyInRadius) {
  const OmniCameraModel camera(act_color::test::contractCalibration().camera);
  EXPECT_NEAR(camera.elevationAtRadius(42.0), -1.45, 1e-12);
  EXPECT_NEAR(camera.elevationAtRadius(286.0), 0.20, 1e-12);
  EXPECT_NEAR(camera.elevationAtRadius(164.0), -0.625, 1e-12);
  EXPECT_TRUE(std::isnan(camera.elevationAtRadius(300.0)));
  EXPECT_TRUE(std::isnan(camera.elevationAtRadius(10.0)));
  EXPECT_NEAR(camera.radiusAtElevation(-0.625), 164.0, 1e-9);
}

TEST(OmniCameraModel, RegionsByRadius) {
  const OmniCameraModel camera(act_color::test::contractCalibration().camera);
  EXPECT_EQ(camera.ray(290, 290).region, PixelRegion::kChassis);
  EXPECT_EQ(camera.ray(290 + 41, 290).region, PixelRegion::kChassis);
  EXPECT_EQ(camera.ray(290 + 43, 290).region, PixelRegion::kFloor);
  EXPECT_EQ(camera.ray(290 + 250, 290).region, PixelRegion::kFloor);         // elevation < 0 below r = 256
  EXPECT_EQ(camera.ray(290 + 260, 290).region, PixelRegion::kAboveHorizon);  // elevation > 0
  EXPECT_EQ(camera.ray(0, 0).region, PixelRegion::kNotImaged);
  EXPECT_EQ(camera.ray(290 + 287, 290).region, PixelRegion::kNotImaged);
}

TEST(OmniCameraModel, BearingFollowsTheContract) {
  auto cal = act_color::test::contractCalibration().camera;
  {
    const OmniCameraModel camera(cal);
    EXPECT_NEAR(camera.ray(390, 290).bearing_rad, 0.0, 1e-6);
    EXPECT_NEAR(camera.ray(290, 390).bearing_rad, M_PI / 2, 1e-6);  // atan2(dv, du)
    EXPECT_NEAR(camera.ray(290, 190).bearing_rad, -M_PI / 2, 1e-6);
  }
  cal.bearing_sign = -1;
  cal.bearing_offset_rad = 0.5;
  const OmniCameraModel camera(cal);
  EXPECT_NEAR(camera.ray(290, 390).bearing_rad, -M_PI / 2 + 0.5, 1e-6);
}

TEST(OmniCameraModel, FloorPointsLieAtHeightOverTanOfDepression) {
  const OmniCameraModel camera(act_color::test::contractCalibration().camera);
  const PixelRay& ray = camera.ray(290 + 164, 290);  // elevation -0.625
  ASSERT_EQ(ray.region, PixelRegion::kFloor);
  EXPECT_NEAR(ray.ground_x_m, 0.75 / std::tan(0.625), 1e-5);
  EXPECT_NEAR(ray.ground_y_m, 0.0, 1e-5);
  EXPECT_NEAR(std::hypot(std::hypot(ray.dir_x, ray.dir_y), ray.dir_z), 1.0, 1e-6);
  EXPECT_NEAR(ray.dir_z, std::sin(-0.625), 1e-6);
}

TEST(OmniCameraModel, ProjectionInvertsTheRays) {
  for (const auto& cal :
       {act_color::test::contractCalibration().camera, act_color::test::defaultCalibration().camera}) {
    auto c = cal;
    c.bearing_sign = -1;
    c.bearing_offset_rad = 0.3;
    auto t = c;
    t.tilt_x_rad = 0.03;
    t.tilt_y_rad = -0.02;
    for (const auto& cam_cal : {cal, c, t}) {
      const OmniCameraModel camera(cam_cal);
      for (double x : {-4.0, -1.0, 0.5, 2.0, 6.0}) {
        for (double y : {-3.0, 0.2, 1.0, 5.0}) {
          double u, v;
          ASSERT_TRUE(camera.projectFloorPoint(x, y, &u, &v)) << x << " " << y;
          const PixelRay ray = camera.computeRay(u, v);
          ASSERT_EQ(ray.region, PixelRegion::kFloor);
          EXPECT_NEAR(ray.ground_x_m, x, 1e-3 * std::max(1.0, std::abs(x)));
          EXPECT_NEAR(ray.ground_y_m, y, 1e-3 * std::max(1.0, std::abs(y)));
        }
      }
    }
  }
}

// camera.tilt: the view rays turn by the rotation vector (x, y) in base_link. A tilt about +y of
// 0.05 rad turns the rays that look along +x down by 0.05 (the floor they meet comes nearer) and
// those along -x up by as much; rays along y keep their elevation to first order.
TEST(OmniCameraModel, TiltTurnsTheViewRays) {
  auto cal = act_color::test::contractCalibration().camera;
  cal.tilt_y_rad = 0.05;
  const OmniCameraModel camera(cal);
  const PixelRay& ahead = camera.ray(290 + 164, 290);  // elevation -0.625 untilted, bearing 0
  ASSERT_EQ(ahead.region, PixelRegion::kFloor);
  EXPECT_NEAR(ahead.elevation_rad, -0.675, 1e-6);
  EXPECT_NEAR(ahead.bearing_rad, 0.0, 1e-6);
  EXPECT_NEAR(ahead.ground_x_m, 0.75 / std::tan(0.675), 1e-5);
  const PixelRay& behind = camera.ray(290 - 164, 290);
  EXPECT_NEAR(behind.elevation_rad, -0.575, 1e-6);
  EXPECT_NEAR(behind.ground_x_m, -0.75 / std::tan(0.575), 1e-5);
  const PixelRay& side = camera.ray(290, 290 + 164);
  EXPECT_NEAR(side.elevation_rad, -0.625, 2e-3);
  EXPECT_NEAR(std::hypot(std::hypot(side.dir_x, side.dir_y), side.dir_z), 1.0, 1e-6);
}
