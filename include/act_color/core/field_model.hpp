#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/types.hpp"

namespace act_color {
namespace core {

// The static world of a 2007-rules MSL field in the `field` frame: carpet, lines and marks (and the
// penalty arcs of lab fields), the green margin and the two goals as solid colored boxes behind
// the goal lines (a colored panel: a box of small depth, optionally set back from the line).
class FieldModel {
 public:
  explicit FieldModel(const FieldCalibration& field);

  const FieldCalibration& calibration() const { return field_; }

  // Class of the floor at (x, y): kWhite on a line or mark, kGreen on carpet or margin,
  // kUnknown beyond the margin. Goals are not part of the floor (see goalHit).
  ColorClass floorClass(double x_m, double y_m) const;
  // On a line or mark. Looks up a grid of the field first: most floor points lie in cells that no
  // line crosses. Always equal to isLineUncached.
  bool isLine(double x_m, double y_m) const {
    const double ax = std::abs(x_m);
    const double ay = std::abs(y_m);
    if (!(ax <= half_length_m_ && ay <= half_width_m_)) return false;  // margin (or NaN): no markings
    const size_t cell =
        static_cast<size_t>(ax * grid_inverse_cell_m_) * grid_rows_ + static_cast<size_t>(ay * grid_inverse_cell_m_);
    return line_may_cross_[cell] && isLineUncached(x_m, y_m);
  }
  // isLine from the line geometry alone (for tests).
  bool isLineUncached(double x_m, double y_m) const;
  // Fraction of the grid's cells that no line crosses.
  double lineFreeFraction() const;
  // Inside the carpet (playable field plus margin).
  bool onCarpet(double x_m, double y_m) const {
    return std::abs(x_m) <= carpet_half_length_m_ && std::abs(y_m) <= carpet_half_width_m_;
  }

  // First goal box met by the ray origin + t * dir (t > 0) before parameter `t_max`:
  // kYellow or kBlue, kUnknown when none. `t_hit` receives the entry parameter.
  ColorClass goalHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                     double* t_hit = nullptr) const;

  // Goal box of the given color: min and max corners in the field frame.
  void goalBox(ColorClass goal, Eigen::Vector3d* min_corner, Eigen::Vector3d* max_corner) const;

  double halfLength() const { return half_length_m_; }
  double halfWidth() const { return half_width_m_; }
  // The carpet: the field plus margin (onCarpet).
  double carpetHalfLength() const { return carpet_half_length_m_; }
  double carpetHalfWidth() const { return carpet_half_width_m_; }

 private:
  FieldCalibration field_;
  double half_length_m_;
  double half_width_m_;
  double carpet_half_length_m_;
  double carpet_half_width_m_;
  Eigen::Vector3d goal_min_[2];  // [0] yellow, [1] blue
  Eigen::Vector3d goal_max_[2];

  // May a line or mark cross the rectangle [x0, x1] x [y0, y1] of the quadrant x, y >= 0? False
  // only when isLineUncached is false everywhere in it: every test of isLineUncached, on intervals.
  bool lineMayCross(double x0, double x1, double y0, double y1) const;
  // The quadrant [0, half length] x [0, half width] (the markings are symmetric about both axes)
  // in square cells, column-major; 1 where a line may cross the cell.
  std::vector<uint8_t> line_may_cross_;
  double grid_inverse_cell_m_ = 0.0;
  size_t grid_rows_ = 0;
};

}  // namespace core
}  // namespace act_color
