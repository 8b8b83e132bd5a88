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
  // A lab field with penalty arcs (issue 12): a semicircle on the area's front line, and one whose
  // centre lies inside the area.
  auto lab = fields.front();
  lab.length_m = 6.0;
  lab.width_m = 4.0;
  lab.line_width_m = 0.05;
  lab.center_circle_radius_m = 0.6;
  lab.corner_arc_radius_m = 0.0;
  lab.goal_area_depth_m = 0.25;
  lab.goal_area_width_m = 1.2;
  lab.penalty_area_depth_m = 0.5;
  lab.penalty_area_width_m = 2.0;
  lab.penalty_mark_distance_m.reset();
  lab.penalty_arc_radius_m = 0.4;
  lab.penalty_arc_center_m = 0.5;
  lab.goal_width_m = 1.0;
  fields.push_back(lab);
  auto fifa_like = fields.front();
  fifa_like.penalty_arc_radius_m = 1.7;
  fifa_like.penalty_arc_center_m = 1.9;
  fields.push_back(fifa_like);
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

TEST(FieldModel, PenaltyArcsAreDrawnOutsideThePenaltyAreaOnly) {
  auto cal = act_color::test::contractCalibration().field;  // 18 x 12 m, penalty area 2.25 deep
  cal.penalty_mark_distance_m.reset();
  const FieldModel plain(cal);
  cal.penalty_arc_radius_m = 1.5;
  cal.penalty_arc_center_m = 2.25;  // on the area's front line: a semicircle towards the centre
  const FieldModel f(cal);
  const double front = 9.0 - 2.25;  // the area's front line (outer edge)
  for (const double sign : {1.0, -1.0}) {
    // The arc's apex on the long axis, and a point at 45 degrees, on both halves.
    const double apex = sign * (front - 1.5 + cal.line_width_m / 2);
    EXPECT_TRUE(f.isLine(apex, 0.0));
    EXPECT_FALSE(plain.isLine(apex, 0.0));
    const double r = 1.5 - cal.line_width_m / 2;
    EXPECT_TRUE(f.isLine(sign * (front - r * std::cos(M_PI / 4)), r * std::sin(M_PI / 4)));
    // The same circle inside the area is not drawn; nor is the arc's inside or outside.
    EXPECT_FALSE(f.isLine(sign * (front + r * std::cos(M_PI / 4)), r * std::sin(M_PI / 4)));
    EXPECT_FALSE(f.isLine(sign * (front - 1.0), 0.0));
    EXPECT_FALSE(f.isLine(sign * (front - 1.8), 0.0));
  }
}

TEST(FieldModel, AGoalSetBackStandsBehindTheLine) {
  auto cal = act_color::test::contractCalibration().field;
  cal.goal_depth_m = 0.02;  // a colored panel
  cal.goal_setback_m = 0.3;
  const FieldModel f(cal);
  Eigen::Vector3d lo, hi;
  f.goalBox(kYellow, &lo, &hi);
  EXPECT_NEAR(lo.x(), 9.3, 1e-12);
  EXPECT_NEAR(hi.x(), 9.32, 1e-12);
  f.goalBox(kBlue, &lo, &hi);
  EXPECT_NEAR(lo.x(), -9.32, 1e-12);
  EXPECT_NEAR(hi.x(), -9.3, 1e-12);
}
