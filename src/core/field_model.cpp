#include "act_color/core/field_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace act_color {
namespace core {
namespace {

// Relative margin of the squared-distance pre-checks below: far larger than the rounding of
// a * a + b * b and of std::hypot (a few ulp), far smaller than any field dimension.
constexpr double kHypotMargin = 1e-9;

// std::hypot(a, b) <= hi, calling std::hypot only when a * a + b * b lies near hi * hi.
bool hypotAtMost(double a, double b, double hi) {
  const double s = a * a + b * b;
  const double outer = hi * (1 + kHypotMargin);
  if (hi >= 0 && s > outer * outer) return false;  // surely beyond hi (also for a * a overflowing)
  const double inner = hi * (1 - kHypotMargin);
  if (hi > 0 && s < inner * inner) return true;  // surely within hi
  return std::hypot(a, b) <= hi;
}

// lo <= std::hypot(a, b) <= hi, calling std::hypot only when a * a + b * b lies near a bound.
bool hypotWithin(double a, double b, double lo, double hi) {
  const double s = a * a + b * b;
  const double outer = hi * (1 + kHypotMargin);
  if (hi >= 0 && s > outer * outer) return false;
  const double inner = lo * (1 - kHypotMargin);
  if (lo > 0 && s < inner * inner) return false;
  const double r = std::hypot(a, b);
  return r <= hi && r >= lo;
}

// Side of the cells of the line grid, in metres: lines are 0.125 m wide, so that most cells of
// the carpet lie between lines.
constexpr double kLineGridCellM = 0.1;

// Smallest and largest distance from the origin to a point of [x0, x1] x [y0, y1].
void distanceRange(double x0, double x1, double y0, double y1, double* lo, double* hi) {
  const double nx = std::clamp(0.0, x0, x1), ny = std::clamp(0.0, y0, y1);
  *lo = std::hypot(nx, ny);
  *hi = std::hypot(std::max(std::abs(x0), std::abs(x1)), std::max(std::abs(y0), std::abs(y1)));
}

// Some point of the rectangle has its distance from the origin within [lo, hi].
bool annulusMeets(double x0, double x1, double y0, double y1, double lo, double hi) {
  double near, far;
  distanceRange(x0, x1, y0, y1, &near, &far);
  return near <= hi && far >= lo;
}

}  // namespace

FieldModel::FieldModel(const FieldCalibration& field)
    : field_(field),
      half_length_m_(field.length_m / 2),
      half_width_m_(field.width_m / 2),
      carpet_half_length_m_(field.length_m / 2 + field.margin_m),
      carpet_half_width_m_(field.width_m / 2 + field.margin_m) {
  // Goals stand behind the goal lines' outer edges; index 0 is yellow, 1 blue.
  for (int i = 0; i < 2; ++i) {
    const double sign = (i == 0 ? 1.0 : -1.0) * field.yellow_goal_x_sign;
    const double x_near = sign * (half_length_m_ + field.goal_setback_m);
    const double x_far = sign * (half_length_m_ + field.goal_setback_m + field.goal_depth_m);
    goal_min_[i] = Eigen::Vector3d(std::min(x_near, x_far), -field.goal_width_m / 2, 0.0);
    goal_max_[i] = Eigen::Vector3d(std::max(x_near, x_far), field.goal_width_m / 2, field.goal_height_m);
  }
  // The grid covers the quadrant with whole cells; a point's cell is found by truncating
  // coordinate / cell side, so each cell is tested slightly enlarged against rounding.
  grid_inverse_cell_m_ = 1.0 / kLineGridCellM;
  const size_t columns = static_cast<size_t>(half_length_m_ * grid_inverse_cell_m_) + 1;
  grid_rows_ = static_cast<size_t>(half_width_m_ * grid_inverse_cell_m_) + 1;
  line_may_cross_.assign(columns * grid_rows_, 0);
  const double slack = 1e-6 * std::max(1.0, std::max(half_length_m_, half_width_m_));
  for (size_t i = 0; i < columns; ++i) {
    for (size_t j = 0; j < grid_rows_; ++j) {
      const double x0 = static_cast<double>(i) * kLineGridCellM, y0 = static_cast<double>(j) * kLineGridCellM;
      line_may_cross_[i * grid_rows_ + j] =
          lineMayCross(x0 - slack, x0 + kLineGridCellM + slack, y0 - slack, y0 + kLineGridCellM + slack);
    }
  }
}

bool FieldModel::lineMayCross(double x0, double x1, double y0, double y1) const {
  const double lw = field_.line_width_m;
  const double hl = half_length_m_;
  const double hw = half_width_m_;
  if (y1 >= hw - lw || x1 >= hl - lw) return true;  // side and goal lines
  if (x0 <= lw / 2) return true;                    // halfway line
  const double r = field_.center_circle_radius_m;
  if (annulusMeets(x0, x1, y0, y1, r - lw, r)) return true;
  for (const auto& [depth, width] : {std::make_pair(field_.goal_area_depth_m, field_.goal_area_width_m),
                                     std::make_pair(field_.penalty_area_depth_m, field_.penalty_area_width_m)}) {
    const double x_inner = hl - depth;
    if (y0 <= width / 2 && x1 >= x_inner && x0 <= x_inner + lw) return true;
    if (x1 >= x_inner && y0 <= width / 2 && y1 >= width / 2 - lw) return true;
  }
  const double corner = field_.corner_arc_radius_m;
  if (annulusMeets(hl - x1, hl - x0, hw - y1, hw - y0, corner - lw, corner)) return true;
  if (field_.penalty_mark_distance_m) {
    const double mark = hl - *field_.penalty_mark_distance_m;
    if (annulusMeets(x0 - mark, x1 - mark, y0, y1, -1.0, lw / 2)) return true;
  }
  if (field_.penalty_arc_radius_m && x0 < hl - field_.penalty_area_depth_m) {
    const double centre = hl - field_.penalty_arc_center_m;
    const double r = *field_.penalty_arc_radius_m;
    if (annulusMeets(x0 - centre, x1 - centre, y0, y1, r - lw, r)) return true;
  }
  return false;
}

double FieldModel::lineFreeFraction() const {
  const auto crossed = std::count(line_may_cross_.begin(), line_may_cross_.end(), uint8_t{1});
  return 1.0 - static_cast<double>(crossed) / static_cast<double>(line_may_cross_.size());
}

// Every test here has its interval form in lineMayCross: change both together.
bool FieldModel::isLineUncached(double x_m, double y_m) const {
  const double ax = std::abs(x_m);
  const double ay = std::abs(y_m);
  const double lw = field_.line_width_m;
  const double hl = half_length_m_;
  const double hw = half_width_m_;
  if (ax > hl || ay > hw) return false;             // margin: no markings
  if (ay >= hw - lw || ax >= hl - lw) return true;  // side and goal lines
  if (ax <= lw / 2) return true;                    // halfway line
  if (hypotWithin(x_m, y_m, field_.center_circle_radius_m - lw, field_.center_circle_radius_m)) return true;
  // Goal and penalty areas: outer edges at the given depth and width.
  for (const auto& [depth, width] : {std::make_pair(field_.goal_area_depth_m, field_.goal_area_width_m),
                                     std::make_pair(field_.penalty_area_depth_m, field_.penalty_area_width_m)}) {
    const double x_inner = hl - depth;
    if (ay <= width / 2 && ax >= x_inner && ax <= x_inner + lw) return true;
    if (ax >= x_inner && ay <= width / 2 && ay >= width / 2 - lw) return true;
  }
  if (hypotWithin(hl - ax, hw - ay, field_.corner_arc_radius_m - lw, field_.corner_arc_radius_m)) return true;
  if (field_.penalty_mark_distance_m) {
    if (hypotAtMost(ax - (hl - *field_.penalty_mark_distance_m), y_m, lw / 2)) return true;
  }
  // The penalty arc, outside the penalty area only.
  if (field_.penalty_arc_radius_m && ax < hl - field_.penalty_area_depth_m) {
    const double r = *field_.penalty_arc_radius_m;
    if (hypotWithin(ax - (hl - field_.penalty_arc_center_m), y_m, r - lw, r)) return true;
  }
  return false;
}

ColorClass FieldModel::floorClass(double x_m, double y_m) const {
  if (!onCarpet(x_m, y_m)) return kUnknown;
  return isLine(x_m, y_m) ? kWhite : kGreen;
}

ColorClass FieldModel::goalHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                               double* t_hit) const {
  // Slab test against the axis-aligned goal boxes, with one division per axis for both goals.
  bool parallel[3];
  Eigen::Vector3d inverse;
  for (int a = 0; a < 3; ++a) {
    parallel[a] = std::abs(dir[a]) < 1e-12;
    inverse[a] = parallel[a] ? 0.0 : 1.0 / dir[a];
  }
  ColorClass best = kUnknown;
  double best_t = t_max;
  for (int i = 0; i < 2; ++i) {
    double t0 = 0.0;
    double t1 = best_t;
    bool hit = true;
    for (int a = 0; a < 3 && hit; ++a) {
      if (parallel[a]) {
        hit = origin[a] >= goal_min_[i][a] && origin[a] <= goal_max_[i][a];
        continue;
      }
      double ta = (goal_min_[i][a] - origin[a]) * inverse[a];
      double tb = (goal_max_[i][a] - origin[a]) * inverse[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      hit = t0 <= t1;
    }
    if (hit && t0 < best_t) {
      best_t = t0;
      best = i == 0 ? kYellow : kBlue;
    }
  }
  if (t_hit) *t_hit = best_t;
  return best;
}

void FieldModel::goalBox(ColorClass goal, Eigen::Vector3d* min_corner, Eigen::Vector3d* max_corner) const {
  const int i = goal == kYellow ? 0 : 1;
  *min_corner = goal_min_[i];
  *max_corner = goal_max_[i];
}

}  // namespace core
}  // namespace act_color
