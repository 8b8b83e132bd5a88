#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "act_color/core/image_view.hpp"

namespace act_color {
namespace core {

// A global change of light, or of the camera's gain, contrast, gamma or white balance, maps every
// color through one monotone (non-decreasing) function per channel. ACT estimates that function
// from the pixels whose class the pose tells best: the carpet, the lines (eq. 1) and the own
// chassis, whose per-channel quantiles are anchors, before (a running reference) and after.
// The anchors are first moved onto the curve y = a + b 255 (x / 255)^gamma that fits them (one
// misleading anchor left out), which the function then follows; when no such curve fits, the
// function is linear between the anchors as seen. Beyond them it continues the nearest segment.
// The colors of one surface under more or less light: the line from LightModel::pivot (black, or
// YUV's grey for the chroma) through one of its colors; a color is on it between the positions
// `from` and `to` along the unit `axis` and within `tolerance` of the line (the carpet in a
// shadow, a ball's shaded side and highlight).
struct ShadeLine {
  Eigen::Vector3d pivot = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  double from = 0, to = 0, tolerance = 0;
  double position(const Eigen::Vector3d& c) const { return (c - pivot).dot(axis); }
  bool contains(const Eigen::Vector3d& c) const {
    const Eigen::Vector3d d = c - pivot;
    const double t = d.dot(axis);
    return t > from && t < to && (d - t * axis).norm() <= tolerance;
  }
};

// Per-channel histograms of colors whose channels are byte values (8-bit images), counted in one
// pass over them: quantiles linear in the samples, without sorting.
struct ChannelHistograms {
  std::array<std::array<uint32_t, 256>, 3> counts{};
  // Replaces the counts with those of `colors`.
  void count(const std::vector<Eigen::Vector3f>& colors);
  // The value of the given rank (0: the smallest; below the number counted) in channel `ch`.
  int valueOfRank(int ch, size_t rank) const;
};

class LightModel {
 public:
  // f(x) for x = 0 ... 256 (the upper end of the last color value), per channel.
  struct Map {
    std::array<std::array<double, 257>, 3> f;
    double at(int channel, double x) const;
    Eigen::Vector3d apply(const Eigen::Vector3d& color) const;
    // The largest slope of the channels' functions over [x - half_width, x + half_width].
    double maxSlope(const Eigen::Vector3d& x, double half_width) const;
  };

  // This cycle's anchor colors: carpet, line and chassis samples (any may be empty); replaces
  // what was observed before in this cycle.
  void observe(const std::vector<Eigen::Vector3f>& green, const std::vector<Eigen::Vector3f>& white,
               const std::vector<Eigen::Vector3f>& chassis);
  bool hasReference() const { return has_reference_; }
  bool observedGreen() const { return !current_.quantiles[kGreenAnchor].empty(); }
  // The carpet's median color now (observedGreen()) and in the reference (hasReference()).
  const Eigen::Vector3d& greenMedian() const { return current_.quantiles[kGreenAnchor][kMedianLevel]; }
  const Eigen::Vector3d& referenceGreenMedian() const { return reference_.quantiles[kGreenAnchor][kMedianLevel]; }
  // The value about which a gain scales a channel: 0, or 128 for the chroma channels of YUV.
  static Eigen::Vector3d pivot(ColorSpace space) {
    return space == ColorSpace::kYuv ? Eigen::Vector3d(0, 128, 128) : Eigen::Vector3d::Zero();
  }
  // The shade line through `color` (its position along the line: the distance from the pivot);
  // from, to and tolerance 0 (it contains no color until they are set).
  static ShadeLine shadeLine(const Eigen::Vector3d& color, ColorSpace space) {
    ShadeLine line;
    line.pivot = pivot(space);
    line.axis = (color - line.pivot).normalized();
    return line;
  }

  // The map from the reference to this cycle's anchors. False when the anchors do not describe a
  // global change of light: fewer than two anchors per channel, or slopes further apart (within a
  // channel between the anchor classes, or between the channels at the carpet) than light,
  // contrast and gamma make them (a poster laid on the carpet moves green, not white or black).
  // `space` decides the chroma channels' pivot for a one-anchor fall-back.
  bool estimate(ColorSpace space, Map* map) const;

  // After a cycle without a change: the reference follows the anchors with memory eta (eq. 4).
  void follow(double eta);
  // After a change: the reference becomes this cycle's anchors; anchors not seen are mapped.
  void rebase(const Map& map);
  // This cycle's anchors from another model (which observed this cycle's image); the reference stays.
  void adoptObservation(const LightModel& other) { current_ = other.current_; }
  void reset();

 private:
  // Per anchor class (0 chassis, 1 carpet, 2 lines), quantile levels of each.
  static constexpr int kAnchorClasses = 3;
  static constexpr int kGreenAnchor = 1;  // the carpet's quantiles: 10, 30, 50, 70, 90%
  static constexpr int kMedianLevel = 2;  // the carpet's 50%
  struct Anchors {
    std::array<std::vector<Eigen::Vector3d>, kAnchorClasses> quantiles;  // empty: not seen
  };
  Anchors current_, reference_;
  bool has_reference_ = false;
  ChannelHistograms histograms_;  // scratch
};

}  // namespace core
}  // namespace act_color
