#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "act_color/core/field_model.hpp"
#include "test_util.hpp"

using namespace act_color::core;

namespace {
FieldModel defaultField() { return FieldModel(act_color::test::contractCalibration().field); }
}  // namespace

TEST(FieldModel, OuterLinesAndMargin) {
  const FieldModel f = defaultField();           // 18 x 12 m, lines 0.125 m, margin 1 m
  EXPECT_EQ(f.floorClass(3.0, 5.95), kWhite);    // side line, outer edge at 6.0
  EXPECT_EQ(f.floorClass(3.0, 5.85), kGreen);    // just inside it
  EXPECT_EQ(f.floorClass(3.0, 6.05), kGreen);    // margin
  EXPECT_EQ(f.floorClass(3.0, 6.95), kGreen);    // margin up to 7.0
  EXPECT_EQ(f.floorClass(3.0, 7.05), kUnknown);  // beyond the margin
  EXPECT_EQ(f.floorClass(-8.95, 2.0), kWhite);   // goal line
  EXPECT_EQ(f.floorClass(-10.05, 2.0), kUnknown);
}

TEST(FieldModel, HalfwayLineAndCentreCircle) {
  const FieldModel f = defaultField();
  EXPECT_EQ(f.floorClass(0.05, 3.0), kWhite);
  EXPECT_EQ(f.floorClass(0.1, 3.0), kGreen);
  const double d = 1.95 / std::sqrt(2.0);  // on the circle, outer radius 2.0
  EXPECT_EQ(f.floorClass(d, d), kWhite);
  EXPECT_EQ(f.floorClass(-d, d), kWhite);
  EXPECT_EQ(f.floorClass(1.5, 1.5), kGreen);  // r = 2.12
  EXPECT_EQ(f.floorClass(1.2, 1.2), kGreen);  // r = 1.70
}

TEST(FieldModel, GoalAndPenaltyAreasAndMarks) {
  const FieldModel f = defaultField();
  // Goal area: outer edge 0.75 m from the goal line's outer edge, 3.5 m wide.
  EXPECT_EQ(f.floorClass(8.3, 0.0), kWhite);
  EXPECT_EQ(f.floorClass(8.2, 0.0), kGreen);
  EXPECT_EQ(f.floorClass(8.6, 1.7), kWhite);
  EXPECT_EQ(f.floorClass(8.6, 1.5), kGreen);
  EXPECT_EQ(f.floorClass(8.3, 1.9), kGreen);  // beyond the goal area's width
  // Penalty area: 2.25 deep, 6.5 wide.
  EXPECT_EQ(f.floorClass(-6.8, 0.5), kWhite);
  EXPECT_EQ(f.floorClass(-6.7, 0.5), kGreen);
  EXPECT_EQ(f.floorClass(-7.5, 3.2), kWhite);
  // Penalty mark: 3 m from the goal line, line-width diameter.
  EXPECT_EQ(f.floorClass(6.0, 0.0), kWhite);
  EXPECT_EQ(f.floorClass(6.1, 0.0), kGreen);
  // Corner arcs, radius 0.75 m around each corner.
  const double a = 0.7 / std::sqrt(2.0);
  EXPECT_EQ(f.floorClass(9.0 - a, 6.0 - a), kWhite);
  EXPECT_EQ(f.floorClass(-9.0 + a, -6.0 + a), kWhite);
  const double b = 0.5 / std::sqrt(2.0);
  EXPECT_EQ(f.floorClass(9.0 - b, 6.0 - b), kGreen);
}

TEST(FieldModel, GoalsAreThreeDimensionalBoxesBehindTheGoalLines) {
  FieldModel f = defaultField();
  const Eigen::Vector3d eye(0, 0, 0.75);
  const double inf = std::numeric_limits<double>::infinity();
  double t = 0;
  EXPECT_EQ(f.goalHit(eye, Eigen::Vector3d(1, 0, 0), inf, &t), kYellow);  // yellow at +x
  EXPECT_NEAR(t, 9.0, 1e-9);
  EXPECT_EQ(f.goalHit(eye, Eigen::Vector3d(-1, 0, 0), inf), kBlue);
  EXPECT_EQ(f.goalHit(eye, Eigen::Vector3d(0, 1, 0), inf), kUnknown);
  EXPECT_EQ(f.goalHit(eye, Eigen::Vector3d(1, 0, 0), 8.0), kUnknown);  // ends before the goal
  // Over the crossbar: at x = 9 the ray is at 0.75 + 9 * 0.1 = 1.65 m > 1 m.
  EXPECT_EQ(f.goalHit(eye, Eigen::Vector3d(1, 0, 0.1).normalized(), inf), kUnknown);
  // Beside the post: y = 1.2 at x = 9, the goal is 2 m wide.
  EXPECT_EQ(f.goalHit(eye, Eigen::Vector3d(9, 1.2, 0).normalized(), inf), kUnknown);
  EXPECT_EQ(f.goalHit(eye, Eigen::Vector3d(9, 0.9, 0).normalized(), inf), kYellow);
  // Down into the goal's floor between 9.0 and 9.5 m.
  EXPECT_EQ(f.goalHit(eye, Eigen::Vector3d(9.3, 0, -0.75).normalized(), inf), kYellow);
  // yellow_goal_x_sign flips the goals.
  auto cal = act_color::test::contractCalibration().field;
  cal.yellow_goal_x_sign = -1;
  EXPECT_EQ(FieldModel(cal).goalHit(eye, Eigen::Vector3d(1, 0, 0), inf), kBlue);
  Eigen::Vector3d lo, hi;
  f.goalBox(kYellow, &lo, &hi);
  EXPECT_TRUE(lo.isApprox(Eigen::Vector3d(9.0, -1.0, 0.0)));
  EXPECT_TRUE(hi.isApprox(Eigen::Vector3d(9.5, 1.0, 1.0)));
}

// isLine answers most points from its grid of cells no line crosses: the grid must never hide a
// line. Checked on the contract's field and on fields whose markings fall across cells
// differently, at random points and at points on and around every cell boundary.
TEST(FieldModel, LineGridNeverHidesALine) {
  std::vector<act_color::core::FieldCalibration> fields;
  fields.push_back(act_color::test::contractCalibration().field);
  auto odd = fields.front();
  odd.line_width_m = 0.05;
  odd.center_circle_radius_m = 1.234;
  odd.corner_arc_radius_m = 0.333;
  odd.goal_area_depth_m = 0.777;
  odd.penalty_mark_distance_m = 2.913;
  odd.length_m = 17.93;
  odd.width_m = 11.87;
  fields.push_back(odd);
  auto wide = fields.front();
  wide.line_width_m = 0.31;
  wide.corner_arc_radius_m = 0.0;
  wide.penalty_mark_distance_m.reset();
  fields.push_back(wide);
  std::mt19937 rng(7);
  for (const auto& calibration : fields) {
    const FieldModel f(calibration);
    const double hl = calibration.length_m / 2 + 0.05, hw = calibration.width_m / 2 + 0.05;
    std::uniform_real_distribution<double> x(-hl, hl), y(-hw, hw);
    int lines = 0;
    for (int n = 0; n < 400000; ++n) {
      const double px = x(rng), py = y(rng);
      ASSERT_EQ(f.isLine(px, py), f.isLineUncached(px, py)) << px << ", " << py;
      lines += f.isLine(px, py);
    }
    EXPECT_GT(lines, 1000);  // the random points do meet lines
    // On and next to the cell boundaries (multiples of 0.1 m), along lines across the field.
    for (int i = 0; i <= static_cast<int>(hl * 10) + 1; ++i) {
      for (const double eps : {-1e-9, 0.0, 1e-9}) {
        const double b = i * 0.1 + eps;
        for (double t = -hw; t <= hw; t += 0.00731) {
          ASSERT_EQ(f.isLine(b, t), f.isLineUncached(b, t)) << b << ", " << t;
          ASSERT_EQ(f.isLine(t * hl / hw, b * hw / hl), f.isLineUncached(t * hl / hw, b * hw / hl));
        }
      }
    }
    EXPECT_GT(f.lineFreeFraction(), 0.5);  // and it answers most of the field
  }
  EXPECT_FALSE(FieldModel(fields.front()).isLine(std::nan(""), 0.0));
}
