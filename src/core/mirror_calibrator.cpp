#include "act_color/core/mirror_calibrator.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <random>
#include <regex>
#include <sstream>

#include "act_color/core/field_model.hpp"
#include "act_color/core/file_io.hpp"
#include "act_color/core/omni_camera_model.hpp"

namespace act_color {
namespace core {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kHalfPi = kPi / 2;
// The calibrator's tilt (camera.tilt) is free up to this (5 degrees) and held back beyond it.
constexpr double kTiltSoftRad = 0.09;
// A tilted fit is taken when it covers this much more of the model's lines (points within 2.5 px of
// a line pixel, weighted): on the simulated cameras, all upright, an upright fit refitted with the
// tilt free gains -0.04 to +0.017 (seeds 0-47; +0.005 or more on 9, 14, 18 and 28, which it brings
// nearer the truth); NuBot's nubot_2 +0.24, nubot_3_new +0.085, nubot_101 +0.036.
constexpr double kTiltCoverageGain = 0.005;
constexpr double kTiltCoverageTauPx = 2.5;
// Elevations are kept this far from the nadir (validateCalibration wants (-pi/2, pi/2)).
constexpr double kMinElevation = -kHalfPi + 0.01;
// Distinct starts of the grid refined per bearing sign: with 4 the right basin was missed on
// simulated cameras whose line pixels changed by a few percent (tuning seed 29: the fit a half
// turn off, 75% distance error, with 4; within the targets with 8 or 16).
constexpr size_t kStartsPerSign = 8;

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::infinity();
  const auto mid = v.begin() + static_cast<long>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// ---------------------------------------------------------------------------------------------
// Colors of the image (BGR, 8 bit).

struct ColorMasks {
  cv::Mat green;     // carpet-like: green to teal, saturated enough
  cv::Mat whiteish;  // low chroma, not dark
  cv::Mat yellow, blue;
  cv::Mat luma;  // CV_32F
};

ColorMasks colorMasks(const cv::Mat& bgr) {
  ColorMasks m;
  cv::Mat hsv;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);  // H in [0, 180)
  // Goal panels under lab light are paler than the simulator's boxes (nubot_1_bak_bak's blue: S ~ 90).
  cv::inRange(hsv, cv::Scalar(16, 90, 90), cv::Scalar(34, 255, 255), m.yellow);
  cv::inRange(hsv, cv::Scalar(100, 70, 50), cv::Scalar(130, 255, 255), m.blue);
  // White and grey: low saturation (lines under colored light are greyish, not pure white).
  cv::inRange(hsv, cv::Scalar(0, 0, 70), cv::Scalar(180, 95, 255), m.whiteish);
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  grey.convertTo(m.luma, CV_32F);

  // The carpet is the dominant chroma around the image centre: real carpets range from saturated
  // green to a dull teal that is hardly greener than grey, so no fixed hue range finds them all.
  cv::Mat lab;
  cv::cvtColor(bgr, lab, cv::COLOR_BGR2Lab);
  constexpr int kBins = 64;  // 4 units of a and b per bin
  cv::Mat hist = cv::Mat::zeros(kBins, kBins, CV_32F);
  const double cu = 0.5 * bgr.cols, cv_ = 0.5 * bgr.rows, reach = 0.42 * std::min(bgr.cols, bgr.rows);
  // Weighted towards the centre: the carpet is what surrounds the robot, while a small field seen
  // from afar leaves more of the mirror's area to the hall (seeds 33, 34, 36, 41 and 46 of the
  // family: the hall's grey or lilac was taken for the carpet, and then the chassis, the line
  // pixels or the fit were wrong).
  for (int v = 0; v < lab.rows; ++v) {
    const cv::Vec3b* row = lab.ptr<cv::Vec3b>(v);
    for (int u = 0; u < lab.cols; ++u) {
      const double r = std::hypot(u - cu, v - cv_);
      if (r > reach || row[u][0] < 30 || row[u][0] > 220) continue;
      const double w = 1.0 - r / reach;
      hist.at<float>(row[u][1] / 4, row[u][2] / 4) += static_cast<float>(w * w);
    }
  }
  cv::GaussianBlur(hist, hist, {5, 5}, 1.0);
  cv::Point mode;
  cv::minMaxLoc(hist, nullptr, nullptr, nullptr, &mode);
  const double a0 = 4.0 * mode.y + 2.0, b0 = 4.0 * mode.x + 2.0;
  std::vector<double> carpet_l;
  for (int v = 0; v < lab.rows; v += 2) {
    const cv::Vec3b* row = lab.ptr<cv::Vec3b>(v);
    for (int u = 0; u < lab.cols; u += 2) {
      if (std::abs(row[u][1] - a0) <= 6 && std::abs(row[u][2] - b0) <= 6 && row[u][0] >= 30)
        carpet_l.push_back(row[u][0]);
    }
  }
  double l0 = 120;
  if (!carpet_l.empty()) {
    std::nth_element(carpet_l.begin(), carpet_l.begin() + static_cast<long>(carpet_l.size() / 2), carpet_l.end());
    l0 = carpet_l[carpet_l.size() / 2];
  }
  constexpr double kChromaTolerance = 10.0;
  const double ca0 = a0 - 128.0, cb0 = b0 - 128.0, chroma0 = std::hypot(ca0, cb0);
  m.green = cv::Mat::zeros(bgr.size(), CV_8UC1);
  for (int v = 0; v < lab.rows; ++v) {
    const cv::Vec3b* row = lab.ptr<cv::Vec3b>(v);
    uint8_t* out = m.green.ptr<uint8_t>(v);
    for (int u = 0; u < lab.cols; ++u) {
      const double da = row[u][1] - a0, db = row[u][2] - b0, l = row[u][0];
      if (l < 0.45 * l0 || l > 1.6 * l0) continue;
      bool carpet = da * da + db * db <= kChromaTolerance * kChromaTolerance;
      // A saturated carpet keeps its hue where it is lit brighter (a spot, one channel clipped) and
      // its chroma moves along it: on one scene the lit carpet around the chassis was 9-10 units
      // from the mode, and its holes looked like the chassis.
      if (!carpet && chroma0 >= 25.0) {
        const double ca = row[u][1] - 128.0, cb = row[u][2] - 128.0, chroma = std::hypot(ca, cb);
        const double cos_angle = (ca * ca0 + cb * cb0) / std::max(1e-9, chroma * chroma0);
        carpet = chroma >= 0.6 * chroma0 && chroma <= 1.5 * chroma0 && cos_angle >= std::cos(12.0 * M_PI / 180.0);
      }
      out[u] = carpet ? 255 : 0;
    }
  }
  return m;
}

// ---------------------------------------------------------------------------------------------
// Floor distance to the nearest line of the field model, on a grid in the field frame.

class LineDistanceMap {
 public:
  explicit LineDistanceMap(const FieldCalibration& field, double cell_m = 0.01) : cell_m_(cell_m) {
    const FieldModel model(field);
    half_x_ = field.length_m / 2 + field.margin_m + 1.0;
    half_y_ = field.width_m / 2 + field.margin_m + 1.0;
    cols_ = static_cast<int>(std::ceil(2 * half_x_ / cell_m_));
    rows_ = static_cast<int>(std::ceil(2 * half_y_ / cell_m_));
    cv::Mat free(rows_, cols_, CV_8UC1);
    for (int r = 0; r < rows_; ++r) {
      uint8_t* row = free.ptr<uint8_t>(r);
      const double y = -half_y_ + (r + 0.5) * cell_m_;
      for (int c = 0; c < cols_; ++c) row[c] = model.isLine(-half_x_ + (c + 0.5) * cell_m_, y) ? 0 : 255;
    }
    cv::distanceTransform(free, distance_, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    distance_ *= cell_m_;
    // Distance to the lines' middles: outside a line its distance plus half the width, inside
    // half the width less the distance to its edge. The fit uses it: a line pixel anywhere across
    // a painted line's width pulls towards its middle, so wide lines do not leave the profile
    // loose by their width.
    cv::Mat inside;
    cv::distanceTransform(~free, inside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    const float half_width = static_cast<float>(field.line_width_m / 2);
    middle_distance_ = distance_ - inside * cell_m_ + half_width;
    middle_distance_ = cv::max(middle_distance_, 0.f);
  }

  // Points on the model's lines (cells on a line), about `spacing_m` apart.
  std::vector<Eigen::Vector2d> linePoints(double spacing_m) const {
    std::vector<Eigen::Vector2d> out;
    const int step = std::max(1, static_cast<int>(std::round(spacing_m / cell_m_)));
    for (int r = 0; r < rows_; r += step) {
      for (int c = 0; c < cols_; c += step) {
        // Any cell of the line in this block (lines are thinner than a block).
        bool found = false;
        for (int rr = r; rr < std::min(rows_, r + step) && !found; ++rr) {
          for (int cc = c; cc < std::min(cols_, c + step) && !found; ++cc) {
            if (distance_.at<float>(rr, cc) == 0.f) {
              out.emplace_back(-half_x_ + (cc + 0.5) * cell_m_, -half_y_ + (rr + 0.5) * cell_m_);
              found = true;
            }
          }
        }
      }
    }
    return out;
  }

  // Distance to the painted line, bilinear; `outside` beyond the grid.
  double at(double x_m, double y_m, double outside = 10.0) const { return lookUp(distance_, x_m, y_m, outside); }
  // Distance to the line's middle.
  double middleAt(double x_m, double y_m, double outside = 10.0) const {
    return lookUp(middle_distance_, x_m, y_m, outside);
  }

 private:
  double lookUp(const cv::Mat& grid, double x_m, double y_m, double outside) const {
    const double fc = (x_m + half_x_) / cell_m_ - 0.5, fr = (y_m + half_y_) / cell_m_ - 0.5;
    if (!(fc >= 0 && fr >= 0 && fc < cols_ - 1 && fr < rows_ - 1)) return outside;
    const int c = static_cast<int>(fc), r = static_cast<int>(fr);
    const double ac = fc - c, ar = fr - r;
    const float* p0 = grid.ptr<float>(r) + c;
    const float* p1 = grid.ptr<float>(r + 1) + c;
    return (1 - ar) * ((1 - ac) * p0[0] + ac * p0[1]) + ar * ((1 - ac) * p1[0] + ac * p1[1]);
  }

  double cell_m_;
  double half_x_ = 0, half_y_ = 0;
  int cols_ = 0, rows_ = 0;
  cv::Mat distance_;         // CV_32F, metres to the painted line
  cv::Mat middle_distance_;  // CV_32F, metres to the line's middle
};

// ---------------------------------------------------------------------------------------------
// The fitted model: parameter vector [cx, cy, psi, x, y, profile...] with psi = heading + bearing
// offset (only their sum is seen), profile either
//   tan:      [ln a, ln r_h], d = a tan(pi/2 r / r_h) (NuBot's a tan(b r), b = pi / (2 r_h)), or
//   monotone: [ln d_0, ln q_1, ...], knot distances d_k = d_{k-1} (1 + exp(q_k)), elevation linear
//             in r between knots (the contract's interpolation, so the fit is the file's mapping).

enum class ProfileKind { kTan, kMonotone };

struct Model {
  ProfileKind kind = ProfileKind::kTan;
  int sign = 1;
  double height_m = 0.7;
  std::vector<double> knots_r;  // monotone
  // Two more parameters: the tilt's rotation vector (x, y) in the field's frame. The height stays
  // the one given: tilted, it and the tilt trade against each other on the lines (a simulated
  // camera 0.54 m high, told 0.7 m, 2 degrees tilted: fitted with both free, 0.22 m and 0.7
  // degrees), and the trainer's robot rule and the ball's size need the true one.
  bool tilted = false;

  static constexpr int kGeometry = 5;
  int profileEnd() const { return kGeometry + (kind == ProfileKind::kTan ? 2 : static_cast<int>(knots_r.size())); }
  int size() const { return profileEnd() + (tilted ? 2 : 0); }
  // The tilt as a rotation of view directions in the field's frame (identity when not tilted).
  Eigen::Matrix3d tilt(const Eigen::VectorXd& p) const {
    return tilted ? tiltRotation(p[profileEnd()], p[profileEnd() + 1]) : Eigen::Matrix3d::Identity();
  }

  // Elevations at the knots (monotone).
  std::vector<double> knotElevations(const Eigen::VectorXd& p) const {
    std::vector<double> e(knots_r.size());
    double d = std::exp(p[kGeometry]);
    for (size_t k = 0; k < knots_r.size(); ++k) {
      if (k > 0) d *= 1.0 + std::exp(p[kGeometry + static_cast<int>(k)]);
      e[k] = -std::atan(height_m / d);
    }
    return e;
  }

  // Elevation at radius r; the end segments extrapolate. NaN when not defined.
  double elevation(double r, const Eigen::VectorXd& p, const std::vector<double>& knot_e) const {
    if (kind == ProfileKind::kTan) {
      const double a = std::exp(p[kGeometry]), r_h = std::exp(p[kGeometry + 1]);
      if (!(r > 0 && r < r_h)) return r >= r_h ? 0.0 : std::numeric_limits<double>::quiet_NaN();
      return -std::atan(height_m / (a * std::tan(kHalfPi * r / r_h)));
    }
    const size_t n = knots_r.size();
    size_t i = 1;
    while (i + 1 < n && r > knots_r[i]) ++i;
    const double f = (r - knots_r[i - 1]) / (knots_r[i] - knots_r[i - 1]);
    return std::max(kMinElevation, knot_e[i - 1] + f * (knot_e[i] - knot_e[i - 1]));
  }
};

// Inverse of Model::elevation for a ground distance: the radius (NaN when not imaged).
double radiusOf(const Model& model, double d, const Eigen::VectorXd& p, const std::vector<double>& knot_e) {
  if (model.kind == ProfileKind::kTan) {
    const double a = std::exp(p[Model::kGeometry]), r_h = std::exp(p[Model::kGeometry + 1]);
    return r_h / kHalfPi * std::atan(d / a);
  }
  const double e = -std::atan(model.height_m / d);
  const size_t n = knot_e.size();
  size_t i = 1;
  while (i + 1 < n && e > knot_e[i]) ++i;
  const double f = (e - knot_e[i - 1]) / (knot_e[i] - knot_e[i - 1]);
  return model.knots_r[i - 1] + f * (model.knots_r[i] - model.knots_r[i - 1]);
}

// Cost and residuals of line pixels under a model.
class LineFit {
 public:
  LineFit(const LineDistanceMap& map, const std::vector<cv::Point2f>& pixels, const MirrorCalibratorOptions& options)
      : map_(map), pixels_(pixels), options_(options) {}

  // Distance (m) of every pixel's floor point to the nearest model line; kOff for a pixel that
  // does not look at the floor.
  static constexpr double kOff = 10.0;
  void distances(const Model& model, const Eigen::VectorXd& p, std::vector<double>* out) const {
    out->resize(pixels_.size());
    const std::vector<double> knot_e =
        model.kind == ProfileKind::kMonotone ? model.knotElevations(p) : std::vector<double>{};
    const Eigen::Matrix3d tilt = model.tilt(p);
    for (size_t i = 0; i < pixels_.size(); ++i) {
      const double du = pixels_[i].x - p[0], dv = pixels_[i].y - p[1];
      const double r = std::hypot(du, dv);
      const double e = model.elevation(r, p, knot_e);
      if (!(e < 0) && !model.tilted) {
        (*out)[i] = kOff;
        continue;
      }
      const double b = p[2] + model.sign * std::atan2(dv, du);
      if (model.tilted) {
        const Eigen::Vector3d dir = tilt * viewDirection(b, e);
        if (!(dir.z() < 0)) {
          (*out)[i] = kOff;
          continue;
        }
        const double t = model.height_m / -dir.z();
        (*out)[i] = map_.middleAt(p[3] + t * dir.x(), p[4] + t * dir.y(), kOff);
        continue;
      }
      const double d = model.height_m / std::tan(-e);
      (*out)[i] = map_.middleAt(p[3] + d * std::cos(b), p[4] + d * std::sin(b), kOff);
    }
  }

  // Mean truncated quadratic (each pixel costs at most 1) plus the priors.
  double cost(const Model& model, const Eigen::VectorXd& p, double tau) const {
    distances(model, p, &scratch_);
    double c = 0;
    for (double d : scratch_) c += std::min(1.0, d * d / (tau * tau));
    return c / std::max<size_t>(1, scratch_.size()) + prior(p) + reachPrior(model, p) -
           kCoverageWeight * coverage(model, p, std::max(2.5, 40.0 * tau));
  }

  // An omnidirectional camera sees far at its mirror's rim; without this a fit can shrink the
  // whole image onto one line (every pixel an inlier). Soft: penalised below rim_reach_m.
  // Also the floor next to the chassis is not at the robot's centre (at least 8 cm away), and
  // a tan profile's a stays within 0.3-30 m (a tiny a with the horizon inside the mirror is
  // another collapse: everything near the robot but a thin ring).
  double reachPrior(const Model& model, const Eigen::VectorXd& p) const {
    const std::vector<double> knot_e =
        model.kind == ProfileKind::kMonotone ? model.knotElevations(p) : std::vector<double>{};
    auto squaredLog = [](double ratio) { return ratio > 1.0 ? 4.0 * std::log(ratio) * std::log(ratio) : 0.0; };
    double c = 0.0;
    const double e = model.elevation(rim_px_, p, knot_e);
    if (e < 0) c += squaredLog(rim_reach_m_ / (model.height_m / std::tan(-e)));  // else: sees the horizon
    const double e_near = model.elevation(near_px_, p, knot_e);
    if (e_near < 0) c += squaredLog(0.08 / (model.height_m / std::tan(-e_near)));
    if (model.kind == ProfileKind::kTan) {
      const double a = std::exp(p[Model::kGeometry]);
      c += squaredLog(0.3 / a) + squaredLog(a / 30.0);
    }
    if (model.tilted) {  // a mount askew by a few degrees, not a camera looking sideways
      const double over = std::max(0.0, std::hypot(p[model.profileEnd()], p[model.profileEnd() + 1]) - kTiltSoftRad);
      c += 25.0 * over * over / (kTiltSoftRad * kTiltSoftRad);
    }
    return c;
  }
  void setReach(double near_px, double rim_px, double rim_reach_m) {
    near_px_ = near_px;
    rim_px_ = rim_px;
    rim_reach_m_ = rim_reach_m;
  }

  // Soft walls at the tolerances of the rough pose (and of the heading when the bearing offset is
  // given): the fit may not wander to another place on the symmetric field.
  double prior(const Eigen::VectorXd& p) const {
    const double dx = p[3] - options_.pose.x_m, dy = p[4] - options_.pose.y_m;
    const double over = std::max(0.0, std::hypot(dx, dy) - options_.position_tolerance_m);
    double c = 25.0 * over * over;
    if (options_.bearing_offset_rad) {
      const double heading = wrapAngle(p[2] - *options_.bearing_offset_rad - options_.pose.theta_rad);
      const double over_h = std::max(0.0, std::abs(heading) - options_.heading_tolerance_rad);
      c += 25.0 * over_h * over_h;
    }
    // The chassis' centre is a good estimate of the mirror axis: lines alone, far apart, let the
    // centre trade against the profile.
    const double off_px = std::hypot(p[0] - center_px_.x(), p[1] - center_px_.y()) / center_sigma_px_;
    c += 0.005 * off_px * off_px;
    return c;
  }
  void setCenterPrior(const Eigen::Vector2d& center_px, double sigma_px) {
    center_px_ = center_px;
    center_sigma_px_ = sigma_px;
  }

  // The other direction: the fraction of the model's line points (within the radii where line
  // pixels were found) that land on a line pixel. Without it, a fit could map every pixel onto
  // one line (a collapsed or flattened profile) at no cost.
  void setCoverage(std::vector<Eigen::Vector2d> model_points, cv::Mat pixel_distance_px, double r_min, double r_max) {
    model_points_ = std::move(model_points);
    pixel_distance_px_ = std::move(pixel_distance_px);
    cover_r_min_ = r_min;
    cover_r_max_ = r_max;
  }
  double coverage(const Model& model, const Eigen::VectorXd& p, double tau_px) const {
    if (model_points_.empty()) return 0.0;
    const std::vector<double> knot_e =
        model.kind == ProfileKind::kMonotone ? model.knotElevations(p) : std::vector<double>{};
    double covered = 0;
    const Eigen::Matrix3d untilt = model.tilt(p).transpose();
    const double h = model.height_m;
    for (const Eigen::Vector2d& w : model_points_) {
      double dx = w.x() - p[3], dy = w.y() - p[4];
      double d = std::hypot(dx, dy);
      if (model.tilted) {  // the direction in the camera's frame, and the upright floor point it has there
        const Eigen::Vector3d dir = untilt * Eigen::Vector3d(dx, dy, -h);
        if (!(dir.z() < 0)) continue;
        dx = dir.x(), dy = dir.y();
        d = h * std::hypot(dx, dy) / -dir.z();
      }
      const double r = radiusOf(model, d, p, knot_e);
      if (!(r >= cover_r_min_ && r <= cover_r_max_)) continue;
      const double phi = model.sign * (std::atan2(dy, dx) - p[2]);
      const double u = p[0] + r * std::cos(phi), v = p[1] + r * std::sin(phi);
      const int iu = static_cast<int>(u), iv = static_cast<int>(v);
      if (iu < 0 || iv < 0 || iu >= pixel_distance_px_.cols || iv >= pixel_distance_px_.rows) continue;
      const double dist = pixel_distance_px_.at<float>(iv, iu);
      covered += std::max(0.0, 1.0 - dist * dist / (tau_px * tau_px));
    }
    return covered / static_cast<double>(model_points_.size());
  }

 private:
  const LineDistanceMap& map_;
  const std::vector<cv::Point2f>& pixels_;
  const MirrorCalibratorOptions& options_;
  mutable std::vector<double> scratch_;
  double near_px_ = 0, rim_px_ = 1e9, rim_reach_m_ = 0.0;
  std::vector<Eigen::Vector2d> model_points_;
  Eigen::Vector2d center_px_{0.0, 0.0};
  double center_sigma_px_ = 1e9;
  cv::Mat pixel_distance_px_;
  double cover_r_min_ = 0, cover_r_max_ = 0;
  // A fully covered field outweighs the data term of a fit whose every pixel is an outlier.
  static constexpr double kCoverageWeight = 1.5;
};

// Nelder-Mead simplex minimisation (the truncated cost is not smooth enough for derivatives far
// from the optimum).
Eigen::VectorXd nelderMead(const std::function<double(const Eigen::VectorXd&)>& f, const Eigen::VectorXd& start,
                           const Eigen::VectorXd& step, int max_evals, double* best_value) {
  const int n = static_cast<int>(start.size());
  std::vector<Eigen::VectorXd> x(n + 1, start);
  std::vector<double> fx(n + 1);
  for (int i = 0; i < n; ++i) x[i + 1][i] += step[i];
  for (int i = 0; i <= n; ++i) fx[i] = f(x[i]);
  int evals = n + 1;
  std::vector<int> order(n + 1);
  while (evals < max_evals) {
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return fx[a] < fx[b]; });
    const int best = order[0], worst = order[n], second = order[n - 1];
    if (fx[worst] - fx[best] < 1e-7 * (1 + std::abs(fx[best])) && evals > 4 * n) break;
    Eigen::VectorXd centroid = Eigen::VectorXd::Zero(n);
    for (int i = 0; i < n; ++i) centroid += x[order[i]];
    centroid /= n;
    const Eigen::VectorXd reflected = centroid + (centroid - x[worst]);
    const double fr = f(reflected);
    ++evals;
    if (fr < fx[best]) {
      const Eigen::VectorXd expanded = centroid + 2.0 * (centroid - x[worst]);
      const double fe = f(expanded);
      ++evals;
      if (fe < fr) {
        x[worst] = expanded, fx[worst] = fe;
      } else {
        x[worst] = reflected, fx[worst] = fr;
      }
    } else if (fr < fx[second]) {
      x[worst] = reflected, fx[worst] = fr;
    } else {
      const Eigen::VectorXd contracted = centroid + 0.5 * (x[worst] - centroid);
      const double fc = f(contracted);
      ++evals;
      if (fc < fx[worst]) {
        x[worst] = contracted, fx[worst] = fc;
      } else {  // shrink towards the best vertex
        for (int i = 0; i <= n; ++i) {
          if (i == best) continue;
          x[i] = x[best] + 0.5 * (x[i] - x[best]);
          fx[i] = f(x[i]);
          ++evals;
        }
      }
    }
  }
  const int best = static_cast<int>(std::min_element(fx.begin(), fx.end()) - fx.begin());
  *best_value = fx[best];
  return x[best];
}

Eigen::VectorXd leastSquares(const std::function<void(const Eigen::VectorXd&, Eigen::VectorXd*)>& residuals,
                             Eigen::VectorXd p, int iterations);

// Levenberg-Marquardt on the line pixels' distances, iteratively reweighted: the inliers (closer
// than tau) are chosen at the current fit, fitted by plain least squares (a smooth problem), and
// chosen again; outliers do not pull. Numeric Jacobian; `regularize` adds rows.
Eigen::VectorXd levenbergMarquardt(
    const LineFit& fit, const Model& model, Eigen::VectorXd p, double tau, int iterations,
    const std::function<void(const Eigen::VectorXd&, std::vector<double>*)>& regularize) {
  std::vector<uint8_t> inlier;
  auto choose = [&](const Eigen::VectorXd& q) {
    std::vector<double> d;
    fit.distances(model, q, &d);
    inlier.resize(d.size());
    for (size_t i = 0; i < d.size(); ++i) inlier[i] = d[i] < tau;
  };
  auto residuals = [&](const Eigen::VectorXd& q, Eigen::VectorXd* out) {
    std::vector<double> d;
    fit.distances(model, q, &d);
    std::vector<double> extra;
    if (regularize) regularize(q, &extra);
    out->resize(static_cast<long>(d.size() + extra.size() + 1));
    for (size_t i = 0; i < d.size(); ++i) (*out)[static_cast<long>(i)] = inlier[i] ? std::min(d[i], 3 * tau) : 0.0;
    for (size_t i = 0; i < extra.size(); ++i) (*out)[static_cast<long>(d.size() + i)] = extra[i];
    // The priors as one more residual. Not the coverage: the simplex has found the basin, and its
    // numeric derivative (a distance transform in whole pixels) would only add noise here.
    const double extra_cost = fit.prior(q) + fit.reachPrior(model, q);
    (*out)[out->size() - 1] = std::sqrt(extra_cost * static_cast<double>(d.size())) * tau;
  };
  constexpr int kRounds = 4;
  for (int round = 0; round < kRounds; ++round) {
    choose(p);
    p = leastSquares(residuals, p, iterations / kRounds);
  }
  return p;
}

// Levenberg-Marquardt with a numeric Jacobian on the parameter layout of Model.
Eigen::VectorXd leastSquares(const std::function<void(const Eigen::VectorXd&, Eigen::VectorXd*)>& residuals,
                             Eigen::VectorXd p, int iterations) {
  const int n = static_cast<int>(p.size());
  Eigen::VectorXd steps(n);
  for (int i = 0; i < n; ++i) steps[i] = i < 2 ? 0.25 : (i < 3 ? 1e-3 : (i < 5 ? 4e-3 : 2e-3));
  Eigen::VectorXd res;
  residuals(p, &res);
  double current = res.squaredNorm();
  double lambda = 1e-3;
  for (int it = 0; it < iterations; ++it) {
    Eigen::MatrixXd J(res.size(), n);
    for (int j = 0; j < n; ++j) {
      Eigen::VectorXd q = p, rq;
      q[j] += steps[j];
      residuals(q, &rq);
      J.col(j) = (rq - res) / steps[j];
    }
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    const Eigen::VectorXd Jtr = J.transpose() * res;
    bool improved = false;
    for (int attempt = 0; attempt < 8 && !improved; ++attempt) {
      Eigen::MatrixXd A = JtJ;
      A.diagonal() += lambda * (JtJ.diagonal().array() + 1e-9).matrix();
      const Eigen::VectorXd delta = A.ldlt().solve(-Jtr);
      const Eigen::VectorXd q = p + delta;
      Eigen::VectorXd rq;
      residuals(q, &rq);
      const double value = rq.squaredNorm();
      if (std::isfinite(value) && value < current) {
        p = q, res = rq;
        improved = current - value > 1e-10 * current;
        current = value;
        lambda = std::max(1e-7, lambda / 3);
        if (!improved) return p;
      } else {
        lambda *= 4;
      }
    }
    if (!improved) break;
  }
  return p;
}

// Camera of a model: the elevation map sampled densely from the tan profile or the monotone knots,
// from the chassis to the mirror rim (beyond the fitted range the profile is continued).
// `tan_p`: the tan fit's parameters, whose shape a monotone profile follows beyond its last knot.
CameraCalibration cameraOf(const Model& model, const Eigen::VectorXd& p, const ImageGeometry& geometry, int width,
                           int height, double bearing_offset, const Eigen::VectorXd& tan_p) {
  CameraCalibration c;
  c.width = width;
  c.height = height;
  c.center_u = p[0];
  c.center_v = p[1];
  c.bearing_sign = model.sign;
  c.bearing_offset_rad = wrapAngle(bearing_offset);
  c.height_m = model.height_m;
  c.chassis_radius_px = geometry.chassis_radius_px;
  c.mirror_radius_px = geometry.mirror_radius_px;
  const double r0 = geometry.chassis_radius_px, r1 = geometry.mirror_radius_px;
  auto push = [&](double r, double e) {
    e = std::clamp(e, kMinElevation, 1.2);
    if (!c.elevation_map.empty() && !(r > c.elevation_map.back().first + 1e-6)) return;
    if (!c.elevation_map.empty() && !(e > c.elevation_map.back().second + 1e-7)) {
      e = c.elevation_map.back().second + 1e-4;  // keep it strictly increasing (above the horizon)
    }
    c.elevation_map.emplace_back(r, e);
  };
  if (model.kind == ProfileKind::kTan) {
    const double r_h = std::exp(p[Model::kGeometry + 1]);
    const double r_end = std::min(r1, 0.995 * r_h);
    // Denser towards the horizon, where the ground distance grows fastest.
    constexpr int kSamples = 48;
    for (int i = 0; i < kSamples; ++i) {
      const double t = static_cast<double>(i) / (kSamples - 1);
      const double r = r0 + (r_end - r0) * (1.0 - std::pow(1.0 - t, 1.6));
      push(r, model.elevation(r, p, {}));
    }
    if (r1 > r_end + 1.0) {  // the rim beyond the horizon: continue with the slope at the horizon
      const auto& m = c.elevation_map;
      const double slope =
          std::max(1e-4, (m.back().second - m[m.size() - 2].second) / (m.back().first - m[m.size() - 2].first));
      const double e_end = m.back().second, r_last = m.back().first;
      push(r1, e_end + slope * (r1 - r_last));
    }
  } else {
    const std::vector<double> e = model.knotElevations(p);
    const double first_slope = (e[1] - e[0]) / (model.knots_r[1] - model.knots_r[0]);
    if (r0 < model.knots_r.front()) push(r0, e[0] - first_slope * (model.knots_r.front() - r0));
    for (size_t k = 0; k < e.size(); ++k) {
      if (model.knots_r[k] >= r0 && model.knots_r[k] <= r1) push(model.knots_r[k], e[k]);
    }
    if (r1 > model.knots_r.back()) {
      const size_t n = e.size();
      const double r_last = model.knots_r[n - 1];
      // Beyond the farthest line pixels no line decides: the tan fit's shape, joined at the last
      // knot. A straight continuation of the last segment drew the hall of nubot_1_bak_bak onto the
      // goal's box (its yellow wall trained as the goal, 17% of the hall in a field class).
      Model tan_model;
      tan_model.height_m = model.height_m;
      const double r_h = std::exp(tan_p[Model::kGeometry + 1]);
      const auto tanElevation = [&](double r) { return tan_model.elevation(std::min(r, 0.995 * r_h), tan_p, {}); };
      const double e_tan_last = tanElevation(r_last);
      constexpr int kTailSamples = 12;
      for (int i = 1; i <= kTailSamples; ++i) {
        const double r = r_last + (r1 - r_last) * i / kTailSamples;
        push(r, e[n - 1] + tanElevation(r) - e_tan_last);
      }
    }
  }
  return c;
}

// How well the yellow and blue pixels point at their goals: pixels in the sector of bearings of
// a goal (its posts from the robot, 4 degrees wider) and not on the field in front of it vote for
// (their goal's color) or against (the other one's) the fit, in [-1, 1]; 0 without votes. Other
// directions are not counted: the hall may hold yellow and blue things anywhere.
double goalAgreement(const Model& model, const Eigen::VectorXd& p, const std::vector<cv::Point2f>& yellow,
                     const std::vector<cv::Point2f>& blue, const FieldCalibration& field) {
  const double half_l = field.length_m / 2;
  const std::vector<double> knot_e =
      model.kind == ProfileKind::kMonotone ? model.knotElevations(p) : std::vector<double>{};
  // Sector and goal-line distance of the goal at x = side * half_l.
  auto inGoalSector = [&](double side, double b, double d) {
    const double gx = side * half_l - p[3];
    const double b1 = std::atan2(field.goal_width_m / 2 - p[4], gx),
                 b2 = std::atan2(-field.goal_width_m / 2 - p[4], gx);
    const double mid = std::atan2(std::sin(b1) + std::sin(b2), std::cos(b1) + std::cos(b2));
    const double half = 0.5 * std::abs(wrapAngle(b1 - b2)) + 4.0 * kPi / 180;
    if (std::abs(wrapAngle(b - mid)) > half) return false;
    return d > std::abs(gx) / std::max(0.2, std::abs(std::cos(b))) - 0.3;  // at or beyond the goal line
  };
  double agree = 0, disagree = 0;
  for (int color = 0; color < 2; ++color) {
    const double own_side = (color == 0 ? 1.0 : -1.0) * field.yellow_goal_x_sign;
    for (const cv::Point2f& px : color == 0 ? yellow : blue) {
      const double du = px.x - p[0], dv = px.y - p[1];
      const double b = wrapAngle(p[2] + model.sign * std::atan2(dv, du));
      const double e = model.elevation(std::hypot(du, dv), p, knot_e);
      const double d = e < 0 ? model.height_m / std::tan(-e) : 1e9;  // above the horizon: far away
      if (inGoalSector(own_side, b, d)) agree += 1;
      if (inGoalSector(-own_side, b, d)) disagree += 1;
    }
  }
  return (agree - disagree) / (agree + disagree + 1.0);
}

// The mirror rim seen from `center`: going outwards from the farthest ring with carpet in a fifth
// of it, the first ring that is mostly dark (the housing); else the image border nearest to the
// centre. With `beyond_border`, rings cut by the image border count (their pixels inside it).
double rimRadius(const ColorMasks& masks, const Eigen::Vector2d& center, bool beyond_border) {
  const int cols = masks.luma.cols, rows = masks.luma.rows;
  const double r_border = std::min({center.x(), cols - 1 - center.x(), center.y(), rows - 1 - center.y()});
  const double r_corner =
      std::max({std::hypot(center.x(), center.y()), std::hypot(cols - center.x(), center.y()),
                std::hypot(center.x(), rows - center.y()), std::hypot(cols - center.x(), rows - center.y())});
  const int bins = std::max(2, static_cast<int>(r_corner) + 1);
  std::vector<double> count(bins, 0), dark(bins, 0), green(bins, 0);
  std::vector<double> floor_luma;
  for (int v = 0; v < rows; v += 2) {
    for (int u = 0; u < cols; u += 2) {
      if (masks.green.at<uint8_t>(v, u)) floor_luma.push_back(masks.luma.at<float>(v, u));
    }
  }
  const double carpet_luma = floor_luma.empty() ? 100.0 : median(floor_luma);
  const double dark_threshold = std::max(22.0, 0.4 * carpet_luma);
  for (int v = 0; v < rows; ++v) {
    for (int u = 0; u < cols; ++u) {
      const int r = static_cast<int>(std::hypot(u - center.x(), v - center.y()));
      if (r >= bins) continue;
      count[r] += 1;
      dark[r] += masks.luma.at<float>(v, u) < dark_threshold;
      green[r] += masks.green.at<uint8_t>(v, u) != 0;
    }
  }
  int r_floor = 0;
  for (int r = 0; r < bins; ++r) {
    if (count[r] > 0 && green[r] > 0.2 * count[r]) r_floor = r;
  }
  for (int r = r_floor; r < bins && (beyond_border || r < r_border); ++r) {
    if (count[r] > 20 && dark[r] > 0.6 * count[r]) return r;
  }
  return r_border;
}

std::vector<cv::Point2f> maskPixels(const cv::Mat& mask, const ImageGeometry& g, size_t max_count, uint32_t seed) {
  std::vector<cv::Point2f> out;
  for (int v = 0; v < mask.rows; ++v) {
    const uint8_t* row = mask.ptr<uint8_t>(v);
    for (int u = 0; u < mask.cols; ++u) {
      if (!row[u]) continue;
      const double r = std::hypot(u - g.center_px.x(), v - g.center_px.y());
      if (r > g.chassis_radius_px + 2 && r < g.mirror_radius_px - 2) out.emplace_back(u, v);
    }
  }
  if (out.size() > max_count) {
    std::mt19937 rng(seed);
    std::shuffle(out.begin(), out.end(), rng);
    out.resize(max_count);
  }
  return out;
}

// Distances of line pixels to the nearest model line through the contract's exact mapping
// (OmniCameraModel::computeRay); +inf for a pixel that does not look at the floor.
std::vector<double> lineDistances(const LineDistanceMap& map, const CameraCalibration& camera, const Pose2D& pose,
                                  const std::vector<cv::Point2f>& pixels, const FieldCalibration* field = nullptr,
                                  std::vector<uint8_t>* on_carpet = nullptr) {
  if (on_carpet) on_carpet->assign(pixels.size(), 0);
  const double c = std::cos(pose.theta_rad), s = std::sin(pose.theta_rad);
  const OmniCameraModel exact(camera);  // the file's mapping, as every consumer reads it
  std::vector<double> d;
  d.reserve(pixels.size());
  for (const cv::Point2f& px : pixels) {
    const PixelRay ray = exact.computeRay(px.x, px.y);
    if (ray.region != PixelRegion::kFloor) {
      d.push_back(std::numeric_limits<double>::infinity());
      continue;
    }
    const double wx = pose.x_m + c * ray.ground_x_m - s * ray.ground_y_m;
    const double wy = pose.y_m + s * ray.ground_x_m + c * ray.ground_y_m;
    d.push_back(map.at(wx, wy, std::numeric_limits<double>::infinity()));
    if (on_carpet && field) {
      (*on_carpet)[d.size() - 1] =
          std::abs(wx) <= field->length_m / 2 + field->margin_m && std::abs(wy) <= field->width_m / 2 + field->margin_m;
    }
  }
  return d;
}

struct Candidate {
  Model model;
  Eigen::VectorXd p;
  double cost = 0;
};

std::string fixed(double value, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << value;
  return s.str();
}

}  // namespace

// ---------------------------------------------------------------------------------------------

MirrorCalibrator::MirrorCalibrator(const FieldCalibration& field, const MirrorCalibratorOptions& options)
    : field_(field), options_(options) {}

ImageGeometry MirrorCalibrator::estimateImageGeometry(const cv::Mat& bgr) const {
  const ColorMasks masks = colorMasks(bgr);
  ImageGeometry g;
  // The floor near the robot is carpet or line: the own chassis is the large non-floor blob it
  // encloses. Struts (thin) are opened away so that the blob does not leak along them.
  cv::Mat floor = masks.green | masks.whiteish;
  {
    // Lines are brighter than the carpet, a chassis far darker: a dark grey one in sensor noise is
    // partly "whiteish" too (V around 70), and its blob fell apart (on one scene the chassis taken
    // was a dark piece 43 px from the mirror centre).
    std::vector<double> carpet_luma;
    for (int v = 0; v < bgr.rows; v += 3) {
      for (int u = 0; u < bgr.cols; u += 3) {
        if (masks.green.at<uint8_t>(v, u)) carpet_luma.push_back(masks.luma.at<float>(v, u));
      }
    }
    if (!carpet_luma.empty()) floor = masks.green | (masks.whiteish & (masks.luma >= 0.5 * median(carpet_luma)));
  }
  cv::morphologyEx(floor, floor, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, {5, 5}));
  cv::Mat not_floor = ~floor;
  const int k = std::max(9, (std::min(bgr.cols, bgr.rows) / 40) | 1);
  cv::morphologyEx(not_floor, not_floor, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, {k, k}));
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(not_floor, labels, stats, centroids, 8);
  const cv::Mat goal_colored = masks.yellow | masks.blue;
  const Eigen::Vector2d image_center(0.5 * bgr.cols, 0.5 * bgr.rows);
  double best_score = -1;
  for (int i = 1; i < n; ++i) {
    const int left = stats.at<int>(i, cv::CC_STAT_LEFT), top = stats.at<int>(i, cv::CC_STAT_TOP);
    const int w = stats.at<int>(i, cv::CC_STAT_WIDTH), h = stats.at<int>(i, cv::CC_STAT_HEIGHT);
    if (left == 0 || top == 0 || left + w >= bgr.cols || top + h >= bgr.rows) continue;  // the outside
    const double area = stats.at<int>(i, cv::CC_STAT_AREA);
    // A goal is a large compact region too, but of a goal's color (seed 44 of the family: the
    // yellow goal was taken for the chassis).
    const cv::Rect box(left, top, w, h);
    if (cv::countNonZero((labels(box) == i) & goal_colored(box)) > 0.5 * area) continue;
    const Eigen::Vector2d c(centroids.at<double>(i, 0), centroids.at<double>(i, 1));
    // Compact, large and near the image centre.
    const double compact = area / std::max(1.0, static_cast<double>(w) * h);
    const double off = (c - image_center).norm() / (0.25 * std::min(bgr.cols, bgr.rows));
    if (compact < 0.5 || off > 1.0) continue;
    const double score = area * compact * (1.0 - 0.7 * off);
    if (score > best_score) {
      best_score = score;
      g.center_px = c;
      g.chassis_radius_px = 0.5 * std::max(w, h);
      g.chassis_found = true;
    }
  }
  if (best_score < 0) {
    g.center_px = image_center;
    g.chassis_radius_px = 0.08 * std::min(bgr.cols, bgr.rows);
  }
  if (options_.center_px) g.center_px = *options_.center_px;
  if (options_.chassis_radius_px) g.chassis_radius_px = *options_.chassis_radius_px;

  // Rings cut by the image border only from a centre seen: from a guessed one they would reach
  // into the housing.
  const double rim = rimRadius(masks, g.center_px, g.chassis_found);
  g.mirror_radius_px = std::max(rim - 2.0, g.chassis_radius_px + 10);
  if (options_.mirror_radius_px) g.mirror_radius_px = *options_.mirror_radius_px;
  return g;
}

std::vector<cv::Point2f> MirrorCalibrator::findLinePixels(const cv::Mat& bgr, const ImageGeometry& g) const {
  const ColorMasks masks = colorMasks(bgr);
  // Brighter than the neighbourhood's median by a margin above the noise: thin bright structures;
  // the window is wider than twice a near line is in the image. Not the white top-hat (brighter
  // than the morphological opening): the opening of a noisy carpet lies about one noise sigma
  // below its middle, and on the noisiest real cameras (nubot_100, nubot_101) thousands of specks
  // of the carpet's own noise passed as line pixels and no fit was accepted.
  const int k = std::max(9, static_cast<int>(g.mirror_radius_px / 12) | 1);
  cv::Mat grey, background, above_median;
  masks.luma.convertTo(grey, CV_8U);
  cv::medianBlur(grey, background, k);
  cv::subtract(grey, background, above_median, cv::noArray(), CV_32F);
  cv::Mat blurred;
  cv::GaussianBlur(masks.luma, blurred, {0, 0}, 1.0);
  cv::Mat noise;
  cv::absdiff(masks.luma, blurred, noise);
  const double noise_level = cv::mean(noise)[0];
  const double threshold = std::max(14.0, 4.0 * noise_level);
  cv::Mat bright = above_median > threshold;
  // Lines are painted on the carpet: green next to them, and within a few pixels on both sides
  // along one of four directions. The carpet's own edge (the grey floor or a wall beyond the
  // margin) has it on one side only; taken for a line it let fits shrink the profile at the rim
  // until that edge fell on the outer line (7 of the first 16 tuning scenes fitted 4-20% short).
  const int kg = std::max(5, (k / 2) | 1);
  cv::Mat near_green;
  cv::dilate(masks.green, near_green, cv::getStructuringElement(cv::MORPH_ELLIPSE, {kg, kg}));
  cv::Mat line = bright & masks.whiteish & near_green & ~masks.green;
  const auto greenWithin = [&](int u, int v, int du, int dv) {
    for (int t = 1; t <= kg; ++t) {
      const int x = u + t * du, y = v + t * dv;
      if (x < 0 || y < 0 || x >= line.cols || y >= line.rows) return false;
      if (masks.green.at<uint8_t>(y, x)) return true;
    }
    return false;
  };
  constexpr int kDirections[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
  for (int v = 0; v < line.rows; ++v) {
    uint8_t* row = line.ptr<uint8_t>(v);
    for (int u = 0; u < line.cols; ++u) {
      if (!row[u]) continue;
      bool between = false;
      for (const auto& d : kDirections) {
        between = between || (greenWithin(u, v, d[0], d[1]) && greenWithin(u, v, -d[0], -d[1]));
      }
      if (!between) row[u] = 0;
    }
  }
  // Lines are long connected curves; specks (noise, texture, clutter edges) are not.
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(line, labels, stats, centroids, 8);
  const int min_area = 4;
  for (int v = 0; v < line.rows; ++v) {
    uint8_t* row = line.ptr<uint8_t>(v);
    const int* label = labels.ptr<int>(v);
    for (int u = 0; u < line.cols; ++u) {
      if (row[u] && label[u] > 0 && label[u] < n && stats.at<int>(label[u], cv::CC_STAT_AREA) < min_area) row[u] = 0;
    }
  }
  return maskPixels(line, g, 4000, 12345u);
}

LineResidual MirrorCalibrator::residual(const CameraCalibration& camera, const Pose2D& pose,
                                        const std::vector<cv::Point2f>& pixels) const {
  std::vector<uint8_t> on_carpet;
  const std::vector<double> d = lineDistances(LineDistanceMap(field_), camera, pose, pixels, &field_, &on_carpet);
  LineResidual out;
  out.total = pixels.size();
  size_t inliers = 0;
  std::vector<double> carpet_d;  // hall clutter that lands beyond the carpet is no field line
  for (size_t i = 0; i < d.size(); ++i) {
    out.pixels += std::isfinite(d[i]);
    inliers += d[i] <= options_.inlier_distance_m;
    if (on_carpet[i]) carpet_d.push_back(d[i]);
  }
  out.on_carpet = carpet_d.size();
  out.median_m = median(carpet_d);
  const size_t carpet_inliers = static_cast<size_t>(
      std::count_if(carpet_d.begin(), carpet_d.end(), [&](double x) { return x <= options_.inlier_distance_m; }));
  out.carpet_inlier_fraction =
      carpet_d.empty() ? 0.0 : static_cast<double>(carpet_inliers) / static_cast<double>(carpet_d.size());
  out.inlier_fraction = pixels.empty() ? 0.0 : static_cast<double>(inliers) / static_cast<double>(pixels.size());
  return out;
}

MirrorFit MirrorCalibrator::fitUnchecked(const cv::Mat& bgr) const {
  if (bgr.empty() || bgr.type() != CV_8UC3) throw CalibrationFitError("the image must be 8-bit with 3 channels");
  MirrorFit result;
  result.image_geometry = estimateImageGeometry(bgr);
  const ImageGeometry& g = result.image_geometry;
  result.line_pixels = findLinePixels(bgr, g);
  const auto& pixels = result.line_pixels;
  if (static_cast<int>(pixels.size()) < options_.min_line_pixels) {
    throw CalibrationFitError("found " + std::to_string(pixels.size()) + " line pixels (white, thin, next to green " +
                              "carpet) where at least " + std::to_string(options_.min_line_pixels) +
                              " are needed: is this an image of the field?");
  }
  const ColorMasks masks = colorMasks(bgr);
  cv::Mat yellow_mask, blue_mask;
  cv::erode(masks.yellow, yellow_mask, cv::Mat());
  cv::erode(masks.blue, blue_mask, cv::Mat());
  const std::vector<cv::Point2f> yellow = maskPixels(yellow_mask, g, 1500, 7u);
  const std::vector<cv::Point2f> blue = maskPixels(blue_mask, g, 1500, 8u);

  const LineDistanceMap map(field_);
  // A coarse subset for the grid search, all pixels for the refinement.
  // Subsets (the pixels are in random order) for the grid search and the simplex, all pixels for
  // the final least squares.
  const auto subset = [&](long n) {
    return std::vector<cv::Point2f>(pixels.begin(), pixels.begin() + std::min(n, static_cast<long>(pixels.size())));
  };
  const std::vector<cv::Point2f> coarse = subset(700), middle = subset(1500);
  LineFit coarse_fit(map, coarse, options_);
  LineFit middle_fit(map, middle, options_);
  LineFit full_fit(map, pixels, options_);
  // At the rim the camera sees at least across 40% of the field's width (MSL mirrors see the
  // horizon; NuBot's reach about 10 m).
  for (LineFit* f : {&coarse_fit, &middle_fit, &full_fit}) {
    f->setReach(g.chassis_radius_px + 2, g.mirror_radius_px, 0.4 * field_.width_m);
    if (g.chassis_found) f->setCenterPrior(g.center_px, 0.01 * g.mirror_radius_px);
  }
  {
    cv::Mat not_line(bgr.size(), CV_8UC1, cv::Scalar(255));
    for (const cv::Point2f& px : pixels) not_line.at<uint8_t>(cvRound(px.y), cvRound(px.x)) = 0;
    cv::Mat pixel_distance;
    cv::distanceTransform(not_line, pixel_distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    std::vector<double> radii;
    for (const cv::Point2f& px : pixels) radii.push_back(std::hypot(px.x - g.center_px.x(), px.y - g.center_px.y()));
    std::sort(radii.begin(), radii.end());
    const double r_min = radii[radii.size() / 100], r_max = radii[radii.size() - 1 - radii.size() / 100];
    coarse_fit.setCoverage(map.linePoints(0.15), pixel_distance, r_min, r_max);
    middle_fit.setCoverage(map.linePoints(0.1), pixel_distance, r_min, r_max);
    full_fit.setCoverage(map.linePoints(0.05), pixel_distance, r_min, r_max);
  }

  const Pose2D& pose = options_.pose;
  std::vector<int> signs = options_.bearing_sign ? std::vector<int>{*options_.bearing_sign} : std::vector<int>{1, -1};
  const double R = g.mirror_radius_px;
  // Without the chassis the centre is a guess (the image's centre): first a coarse search over
  // centres 0.15 R around it (bearings every 10 degrees, a few profiles) for the best start.
  Eigen::Vector2d start_center = g.center_px;
  if (!g.chassis_found && !options_.center_px) {
    double best = std::numeric_limits<double>::infinity();
    const double step = 0.075 * R;
    for (int i = -2; i <= 2; ++i) {
      for (int j = -2; j <= 2; ++j) {
        const Eigen::Vector2d c = g.center_px + step * Eigen::Vector2d(i, j);
        for (int sign : signs) {
          Model model;
          model.sign = sign;
          model.height_m = options_.height_m;
          for (double a : {0.8, 1.8, 4.0}) {
            for (double rh : {0.9, 1.2, 1.8}) {
              for (int k = 0; k < 36; ++k) {
                Eigen::VectorXd p(7);
                p << c.x(), c.y(), k * kPi / 18, pose.x_m, pose.y_m, std::log(a), std::log(rh * R);
                const double cost = coarse_fit.cost(model, p, 0.3);
                if (cost < best) best = cost, start_center = c;
              }
            }
          }
        }
      }
    }
  }
  // Grid over the bearing (psi = heading + offset), the sign and the a tan(b r) family (its
  // horizon from inside the mirror to far beyond it), at the start centre and the rough pose.
  std::vector<Candidate> grid;
  for (int sign : signs) {
    Model model;
    model.sign = sign;
    model.height_m = options_.height_m;
    for (double a : {0.5, 0.8, 1.2, 1.8, 2.7, 4.0, 6.0}) {
      for (double rh : {0.8, 0.9, 1.0, 1.15, 1.35, 1.6, 2.0, 2.6}) {
        for (int k = 0; k < 72; ++k) {
          double psi = k * kPi / 36;
          if (options_.bearing_offset_rad) {
            const double off = (k / 71.0 - 0.5) * 2 * options_.heading_tolerance_rad;
            psi = pose.theta_rad + *options_.bearing_offset_rad + off;
          }
          Eigen::VectorXd p(7);
          p << start_center.x(), start_center.y(), psi, pose.x_m, pose.y_m, std::log(a), std::log(rh * R);
          grid.push_back({model, p, coarse_fit.cost(model, p, 0.3)});
        }
      }
    }
  }
  std::sort(grid.begin(), grid.end(), [](const Candidate& a, const Candidate& b) { return a.cost < b.cost; });
  // The best distinct starts per sign (bearings 20 degrees apart), each refined by simplex
  // with a shrinking outlier distance.
  std::vector<Candidate> refined;
  for (int sign : signs) {
    std::vector<Candidate> starts;
    for (const Candidate& c : grid) {
      if (c.model.sign != sign) continue;
      bool distinct = true;
      for (const Candidate& s : starts) distinct &= std::abs(wrapAngle(s.p[2] - c.p[2])) > 0.35;
      if (distinct) starts.push_back(c);
      if (starts.size() >= kStartsPerSign) break;
    }
    for (Candidate c : starts) {
      Eigen::VectorXd step(7);
      step << 4.0, 4.0, 0.08, 0.2, 0.2, 0.2, 0.1;
      for (double tau : {0.3, 0.15, 0.08}) {
        const auto f = [&](const Eigen::VectorXd& q) { return middle_fit.cost(c.model, q, tau); };
        c.p = nelderMead(f, c.p, step, 450, &c.cost);
        step *= 0.5;
      }
      refined.push_back(c);
    }
  }
  std::sort(refined.begin(), refined.end(), [](const Candidate& a, const Candidate& b) { return a.cost < b.cost; });
  // Ambiguities of the symmetric field. Its mirror image about the x axis (the other bearing
  // sign, psi -> -psi, y -> -y) and its half turn about the centre spot (psi -> psi + pi,
  // position -> -position) see the same lines; the pose prior tells them apart unless the pose
  // is near that axis or the centre. Each is refined from the best fit and compared.
  const Candidate best = refined.front();
  std::vector<Candidate> variants = {best};
  auto variant = [&](const Candidate& from, bool mirror, bool turn) {
    Candidate c = from;
    if (mirror) c.model.sign = -c.model.sign, c.p[2] = -c.p[2], c.p[4] = -c.p[4];
    if (turn) c.p[2] += kPi, c.p[3] = -c.p[3], c.p[4] = -c.p[4];
    c.p[2] = wrapAngle(c.p[2]);
    Eigen::VectorXd step(7);
    step << 1.0, 1.0, 0.02, 0.05, 0.05, 0.05, 0.03;
    const auto f = [&](const Eigen::VectorXd& q) { return middle_fit.cost(c.model, q, 0.08); };
    c.p = nelderMead(f, c.p, step, 500, &c.cost);
    variants.push_back(c);
  };
  if (!options_.bearing_sign) variant(best, true, false);
  if (!options_.bearing_offset_rad) {
    variant(best, false, true);
    if (!options_.bearing_sign) variant(best, true, true);
  }
  const double best_cost =
      std::min_element(variants.begin(), variants.end(), [](const Candidate& a, const Candidate& b) {
        return a.cost < b.cost;
      })->cost;
  // Costs are negative with the coverage reward: margins are fractions of the range they span
  // (a pixel costs at most 1).
  const auto within = [&](const Candidate& c, double fraction) {
    return c.cost <= best_cost + fraction * (1.0 + std::abs(best_cost));
  };
  std::vector<Candidate> pool;
  for (const Candidate& c : variants) {
    if (within(c, 0.03)) pool.push_back(c);
  }
  const bool sign_ambiguous = std::any_of(pool.begin(), pool.end(),
                                          [&](const Candidate& c) { return c.model.sign != pool.front().model.sign; });
  std::sort(pool.begin(), pool.end(), [](const Candidate& a, const Candidate& b) { return a.cost < b.cost; });
  int sign = pool.front().model.sign;
  if (sign_ambiguous) {
    sign = options_.bearing_sign_prior;
    result.notes.push_back("bearing sign: the image fits either sign (a pose near the field's long axis); took " +
                           std::to_string(sign) + " (--bearing-sign to change)");
  }
  // The best of that sign, and its half turn when that fits nearly as well: the goal colors tell.
  std::vector<Candidate> same_sign;
  for (const Candidate& c : variants) {
    if (c.model.sign == sign) same_sign.push_back(c);
  }
  std::sort(same_sign.begin(), same_sign.end(), [](const Candidate& a, const Candidate& b) { return a.cost < b.cost; });
  Candidate chosen = same_sign.front();
  for (size_t i = 1; i < same_sign.size(); ++i) {
    const Candidate& other = same_sign[i];
    if (std::abs(wrapAngle(other.p[2] - chosen.p[2])) < kPi / 2 || !within(other, 0.1)) continue;
    const double here = goalAgreement(chosen.model, chosen.p, yellow, blue, field_);
    const double there = goalAgreement(other.model, other.p, yellow, blue, field_);
    const bool decided = std::abs(here - there) > 0.2;
    if (decided && there > here) chosen = other;
    result.notes.push_back(decided ? "heading: the lines fit a half turn nearly as well; the goal colors chose "
                                     "(agreement " +
                                         fixed(std::max(here, there), 2) + " against " +
                                         fixed(std::min(here, there), 2) + ")"
                                   : "heading: the lines fit a half turn nearly as well and the goal colors cannot "
                                     "tell; check the overlay");
    break;
  }

  // Refinement with all pixels, then the monotone profile from it; the profile with the smaller
  // median residual is kept (the monotone one only when clearly better: it has more freedom).
  Candidate tan = chosen;
  tan.p = levenbergMarquardt(full_fit, tan.model, tan.p, 0.08, 40, nullptr);
  tan.p = levenbergMarquardt(full_fit, tan.model, tan.p, 0.05, 40, nullptr);

  // The rim again from the fitted centre when the start was a guess.
  ImageGeometry fitted_geometry = g;
  if (!g.chassis_found && !options_.mirror_radius_px) {
    fitted_geometry.mirror_radius_px =
        std::max(rimRadius(masks, Eigen::Vector2d(tan.p[0], tan.p[1]), true) - 2.0, g.chassis_radius_px + 10);
  }
  std::vector<double> radii;
  for (const cv::Point2f& px : pixels) radii.push_back(std::hypot(px.x - tan.p[0], px.y - tan.p[1]));
  std::sort(radii.begin(), radii.end());
  const double r_lo = g.chassis_radius_px + 1.0;  // from the chassis: the smoothness carries the fit inwards
  const double r_hi = std::min(fitted_geometry.mirror_radius_px, radii[radii.size() - 1 - radii.size() / 200]);
  Candidate mono;
  mono.model = tan.model;
  mono.model.kind = ProfileKind::kMonotone;
  constexpr int kKnots = 18;
  for (int i = 0; i < kKnots; ++i) {
    const double t = static_cast<double>(i) / (kKnots - 1);
    mono.model.knots_r.push_back(r_lo + (r_hi - r_lo) * (1.0 - std::pow(1.0 - t, 1.4)));
  }
  mono.p.resize(Model::kGeometry + kKnots);
  mono.p.head(Model::kGeometry) = tan.p.head(Model::kGeometry);
  std::vector<double> tan_log_d;  // the tan fit at the knots: the shape where no line decides
  {
    double previous = 0;
    const double a = std::exp(tan.p[5]), r_h = std::exp(tan.p[6]);
    for (int i = 0; i < kKnots; ++i) {
      // Knots beyond the tan fit's horizon: keep growing.
      const double r = std::min(mono.model.knots_r[i], 0.98 * r_h);
      double d = a * std::tan(kHalfPi * r / r_h);
      if (i > 0) d = std::max(d, previous * 1.02);
      mono.p[Model::kGeometry + i] = i == 0 ? std::log(d) : std::log(d / previous - 1.0);
      tan_log_d.push_back(std::log(d));
      previous = d;
    }
  }
  // Smoothness of ln d over the knots: knots that few lines constrain follow their neighbours.
  const double smooth = 0.02 * std::sqrt(static_cast<double>(pixels.size()));
  const auto regularize = [&](const Eigen::VectorXd& q, std::vector<double>* rows) {
    std::vector<double> ld(kKnots);
    double d = std::exp(q[Model::kGeometry]);
    for (int k = 0; k < kKnots; ++k) {
      if (k > 0) d *= 1.0 + std::exp(q[Model::kGeometry + k]);
      ld[k] = std::log(d);
    }
    for (int k = 1; k + 1 < kKnots; ++k) {
      const double h0 = mono.model.knots_r[k] - mono.model.knots_r[k - 1];
      const double h1 = mono.model.knots_r[k + 1] - mono.model.knots_r[k];
      const double curvature = ((ld[k + 1] - ld[k]) / h1 - (ld[k] - ld[k - 1]) / h0) * 0.5 * (h0 + h1);
      rows->push_back(smooth * curvature);
    }
    // Weakly towards the tan fit: between lines far apart (a lab field seen from its centre) the
    // data leave the profile free, and there the rigid family's shape is the better guess.
    for (int k = 0; k < kKnots; ++k) rows->push_back(0.25 * smooth * (ld[k] - tan_log_d[k]));
  };
  // From a wide inlier distance down: where the tan shape was wrong (often near the robot) its
  // line pixels are still inliers when the monotone profile starts.
  for (double tau : {0.12, 0.08, 0.05}) mono.p = levenbergMarquardt(full_fit, mono.model, mono.p, tau, 40, regularize);

  auto finish = [&](const Candidate& c, Calibration* cal, Pose2D* refined_pose) {
    // psi = heading + offset: keep the given heading and fit the offset, or the other way round.
    refined_pose->x_m = c.p[3];
    refined_pose->y_m = c.p[4];
    double offset = c.p[2] - pose.theta_rad;
    refined_pose->theta_rad = pose.theta_rad;
    if (options_.bearing_offset_rad) {
      offset = *options_.bearing_offset_rad;
      refined_pose->theta_rad = wrapAngle(c.p[2] - offset);
    }
    cal->camera = cameraOf(c.model, c.p, fitted_geometry, bgr.cols, bgr.rows, offset, tan.p);
    if (c.model.tilted) {  // the field's frame into base_link
      const double wx = c.p[c.model.profileEnd()], wy = c.p[c.model.profileEnd() + 1];
      const double ct = std::cos(refined_pose->theta_rad), st = std::sin(refined_pose->theta_rad);
      cal->camera.tilt_x_rad = ct * wx + st * wy;
      cal->camera.tilt_y_rad = -st * wx + ct * wy;
    }
    cal->field = field_;
    return residual(cal->camera, *refined_pose, pixels);
  };
  Calibration tan_cal, mono_cal;
  Pose2D tan_pose, mono_pose;
  const LineResidual tan_res = finish(tan, &tan_cal, &tan_pose);
  const LineResidual mono_res = finish(mono, &mono_cal, &mono_pose);
  result.tan_a_m = std::exp(tan.p[5]);
  result.tan_b_per_px = kHalfPi / std::exp(tan.p[6]);
  result.tan_median_m = tan_res.median_m;
  result.monotone_median_m = mono_res.median_m;
  // Chosen by the RMS distance to the lines' middles over the pixels that both profiles take for
  // inliers (the medians are often 0: most pixels lie on a painted line; and outliers would add
  // the same to both); the monotone profile only when clearly better, as it has more freedom.
  {
    std::vector<double> d_tan, d_mono;
    full_fit.distances(tan.model, tan.p, &d_tan);
    full_fit.distances(mono.model, mono.p, &d_mono);
    double sum_tan = 0, sum_mono = 0;
    size_t common = 0;
    for (size_t i = 0; i < d_tan.size(); ++i) {
      if (d_tan[i] >= options_.inlier_distance_m || d_mono[i] >= options_.inlier_distance_m) continue;
      sum_tan += d_tan[i] * d_tan[i];
      sum_mono += d_mono[i] * d_mono[i];
      ++common;
    }
    result.tan_rms_m = std::sqrt(sum_tan / static_cast<double>(std::max<size_t>(1, common)));
    result.monotone_rms_m = std::sqrt(sum_mono / static_cast<double>(std::max<size_t>(1, common)));
  }
  // Carpet next to the lines must not land on them: a fit that puts carpet on the lines explains
  // nothing there (a flexible profile can bend a band of the image flat onto a line).
  cv::Mat carpet;
  cv::erode(masks.green, carpet, cv::getStructuringElement(cv::MORPH_ELLIPSE, {5, 5}));
  const std::vector<cv::Point2f> carpet_pixels = maskPixels(carpet, g, 3000, 9u);
  const auto carpetOnLines = [&](const Calibration& cal, const Pose2D& at) {
    const std::vector<double> d = lineDistances(map, cal.camera, at, carpet_pixels);
    size_t on_line = 0, on_floor = 0;
    for (double x : d) {
      on_floor += std::isfinite(x);
      on_line += x <= 0.0;
    }
    return on_floor > 0 ? static_cast<double>(on_line) / static_cast<double>(on_floor) : 1.0;
  };
  const double tan_carpet = carpetOnLines(tan_cal, tan_pose), mono_carpet = carpetOnLines(mono_cal, mono_pose);
  const bool use_mono =
      options_.profile == "monotone" ||
      (options_.profile != "tan" && result.monotone_rms_m < 0.95 * result.tan_rms_m &&
       mono_res.inlier_fraction >= tan_res.inlier_fraction - 0.01 && mono_carpet <= tan_carpet + 0.005);
  result.carpet_on_lines = use_mono ? mono_carpet : tan_carpet;
  result.profile = use_mono ? "monotone" : "tan";
  result.calibration = use_mono ? mono_cal : tan_cal;
  result.pose = use_mono ? mono_pose : tan_pose;
  result.residual = use_mono ? mono_res : tan_res;
  // A mirror axis a degree or two off the vertical (a camera mounted askew) draws one side of the
  // field nearer than the other, which no radial profile follows. The chosen profile is refitted
  // with the tilt free (camera.tilt), from a wide inlier distance down, and replaces it when it
  // covers clearly more of the model's lines with line pixels (coverage, as in the simplex), takes
  // as many line pixels on the carpet for inliers and puts no more carpet on the lines. Only a
  // fit that stands upright: a tilt is no rescue for a wrong basin.
  if (rejection(result).empty()) {
    const Candidate& upright = use_mono ? mono : tan;
    Candidate tilted = upright;
    tilted.model.tilted = true;
    Eigen::VectorXd q = Eigen::VectorXd::Zero(tilted.model.size());
    q.head(tilted.p.size()) = tilted.p;
    const auto& reg = use_mono ? regularize : std::function<void(const Eigen::VectorXd&, std::vector<double>*)>();
    for (double tau : {0.2, 0.12, 0.08, 0.05}) q = levenbergMarquardt(full_fit, tilted.model, q, tau, 40, reg);
    tilted.p = q;
    Calibration tilted_cal;
    Pose2D tilted_pose;
    const LineResidual tilted_res = finish(tilted, &tilted_cal, &tilted_pose);
    const double tilted_carpet = carpetOnLines(tilted_cal, tilted_pose);
    result.upright_coverage = full_fit.coverage(upright.model, upright.p, kTiltCoverageTauPx);
    result.tilted_coverage = full_fit.coverage(tilted.model, tilted.p, kTiltCoverageTauPx);
    if (result.tilted_coverage >= result.upright_coverage + kTiltCoverageGain &&
        tilted_res.carpet_inlier_fraction >= result.residual.carpet_inlier_fraction - 0.005 &&
        tilted_carpet <= result.carpet_on_lines + 0.001) {
      result.calibration = tilted_cal;
      result.pose = tilted_pose;
      result.residual = tilted_res;
      result.carpet_on_lines = tilted_carpet;
      result.notes.push_back("the mirror axis is tilted " + fixed(tilted_cal.camera.tiltRad() * 180.0 / kPi, 1) +
                             " degrees from the vertical (camera.tilt)");
    }
  }
  validateCalibration(result.calibration, "fitted calibration");

  return result;
}

std::string MirrorCalibrator::rejection(const MirrorFit& fit) const {
  if (fit.carpet_on_lines > options_.max_carpet_on_lines) {
    return "no fit: " + fixed(100 * fit.carpet_on_lines, 1) +
           "% of the carpet pixels land on the model's lines (limit " + fixed(100 * options_.max_carpet_on_lines, 1) +
           "%): wrong field, pose or image?";
  }
  if (!(fit.residual.median_m <= options_.max_median_residual_m) ||
      fit.residual.carpet_inlier_fraction < options_.min_inlier_fraction) {
    return "no fit: median line-pixel residual " + fixed(fit.residual.median_m, 3) + " m (limit " +
           fixed(options_.max_median_residual_m, 3) + "), inlier fraction " +
           fixed(fit.residual.carpet_inlier_fraction, 2) + " (limit " + fixed(options_.min_inlier_fraction, 2) +
           ") over the " + std::to_string(fit.residual.on_carpet) +
           " line pixels on the carpet: wrong field, pose or image?";
  }
  return "";
}

MirrorFit MirrorCalibrator::fit(const cv::Mat& bgr) const {
  MirrorFit result = fitUnchecked(bgr);
  const std::string why = rejection(result);
  if (!why.empty()) throw CalibrationFitError(why);
  return result;
}

// ---------------------------------------------------------------------------------------------

cv::Mat drawCalibrationOverlay(const cv::Mat& bgr, const Calibration& calibration, const Pose2D& pose,
                               const std::vector<cv::Point2f>& line_pixels, double inlier_distance_m) {
  cv::Mat out = bgr.clone();
  const OmniCameraModel camera(calibration.camera);
  const FieldModel field(calibration.field);
  const double c = std::cos(pose.theta_rad), s = std::sin(pose.theta_rad);
  auto world = [&](const PixelRay& ray, double* wx, double* wy) {
    *wx = pose.x_m + c * ray.ground_x_m - s * ray.ground_y_m;
    *wy = pose.y_m + s * ray.ground_x_m + c * ray.ground_y_m;
  };
  const int w = std::min(out.cols, camera.width()), h = std::min(out.rows, camera.height());
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const PixelRay& ray = camera.ray(u, v);
      if (ray.region != PixelRegion::kFloor) continue;
      double wx, wy;
      world(ray, &wx, &wy);
      if (field.isLine(wx, wy)) {
        cv::Vec3b& p = out.at<cv::Vec3b>(v, u);
        p = cv::Vec3b(static_cast<uint8_t>(0.4 * p[0] + 0.6 * 255), static_cast<uint8_t>(0.4 * p[1]),
                      static_cast<uint8_t>(0.4 * p[2] + 0.6 * 255));
      }
    }
  }
  const std::vector<double> d =
      lineDistances(LineDistanceMap(calibration.field), calibration.camera, pose, line_pixels);
  for (size_t i = 0; i < line_pixels.size(); ++i) {
    const bool inlier = d[i] <= inlier_distance_m;
    cv::circle(out, line_pixels[i], 0, inlier ? cv::Scalar(255, 255, 0) : cv::Scalar(0, 0, 255), 1);
  }
  const cv::Point2d center(calibration.camera.center_u, calibration.camera.center_v);
  cv::circle(out, center, static_cast<int>(calibration.camera.mirror_radius_px), cv::Scalar(0, 200, 255), 1);
  cv::circle(out, center, static_cast<int>(calibration.camera.chassis_radius_px), cv::Scalar(0, 200, 255), 1);
  cv::drawMarker(out, center, cv::Scalar(0, 200, 255), cv::MARKER_CROSS, 12, 1);
  return out;
}

const std::vector<std::string>& fieldPresetNames() {
  static const std::vector<std::string> kNames = {"msl2007", "lab6x4"};
  return kNames;
}

FieldCalibration fieldPreset(const std::string& name) {
  FieldCalibration f;
  if (name == "msl2007") {  // the contract's example: 2007 rules
    f.length_m = 18.0, f.width_m = 12.0, f.line_width_m = 0.125, f.margin_m = 1.0;
    f.center_circle_radius_m = 2.0, f.corner_arc_radius_m = 0.75;
    f.goal_area_depth_m = 0.75, f.goal_area_width_m = 3.5;
    f.penalty_area_depth_m = 2.25, f.penalty_area_width_m = 6.5;
    f.penalty_mark_distance_m = 3.0;
    f.goal_width_m = 2.0, f.goal_height_m = 1.0, f.goal_depth_m = 0.5;
  } else if (name == "lab6x4") {
    // NuBot's lab field, 600 x 400 cm (shared/real/README.md). The markings were measured on
    // nubot_1's image (act_calibrate --check with the field varied, scored by NuBot's hand-picked
    // white pixels): centre circle 0.6 m, goal area 0.45 x 1.6 m, penalty area 0.8 x 2.0 m, lines
    // about 7 cm; the penalty arcs, semicircles of 0.6 m on the areas' front lines, measured the
    // same way on nubot_1 and nubot_1_bak_bak (hand-picked pixels within 0.08 m of a model line:
    // 0.891 -> 0.981 and 0.904 -> 0.974 with them). No corner arcs.
    f.length_m = 6.0, f.width_m = 4.0, f.line_width_m = 0.07, f.margin_m = 0.5;
    f.center_circle_radius_m = 0.6, f.corner_arc_radius_m = 0.0;
    f.goal_area_depth_m = 0.45, f.goal_area_width_m = 1.6;
    f.penalty_area_depth_m = 0.8, f.penalty_area_width_m = 2.0;
    f.penalty_arc_radius_m = 0.6, f.penalty_arc_center_m = 0.8;
    f.goal_width_m = 1.0, f.goal_height_m = 0.6, f.goal_depth_m = 0.3;
  } else {
    throw std::invalid_argument("unknown field preset '" + name + "' (known: msl2007, lab6x4)");
  }
  f.yellow_goal_x_sign = 1;
  return f;
}

// ---------------------------------------------------------------------------------------------

namespace {

// The number in <key> ... </key> of an OpenCV-style XML file; nullopt when the key is absent.
std::optional<double> xmlNumber(const std::string& text, const std::string& path, const std::string& key) {
  const std::regex element("<" + key + ">([^<]*)</" + key + ">");
  std::smatch m;
  if (!std::regex_search(text, m, element)) return std::nullopt;
  const std::string value = m[1].str();
  const size_t begin = value.find_first_not_of(" \t\r\n");
  const size_t end = value.find_last_not_of(" \t\r\n");
  const std::string trimmed = begin == std::string::npos ? "" : value.substr(begin, end - begin + 1);
  char* stop = nullptr;
  const double number = std::strtod(trimmed.c_str(), &stop);
  if (trimmed.empty() || *stop != '\0' || !std::isfinite(number)) {
    throw CalibrationError(path + ": " + key + ": '" + trimmed + "' is not a number");
  }
  return number;
}

// NuBot's XML files are a few hundred bytes.
constexpr size_t kMaxNubotXmlBytes = size_t{1} << 20;

std::string readText(const std::string& path) {
  std::string text, error;
  if (!readRegularFile(path, kMaxNubotXmlBytes, &text, &error)) throw CalibrationError(error);
  return text;
}

double requireNumber(const std::string& text, const std::string& path, const std::string& key) {
  const std::optional<double> v = xmlNumber(text, path, key);
  if (!v) throw CalibrationError(path + ": " + key + ": missing");
  return *v;
}

}  // namespace

std::vector<cv::Point2f> readNubotWhites(const std::string& path) {
  std::string text, error;
  if (!readRegularFile(path, kMaxImageFileBytes, &text, &error)) throw std::runtime_error(error);
  std::istringstream file(text);
  std::vector<cv::Point2f> out;
  double x, y;
  while (file >> x >> y) out.emplace_back(static_cast<float>(x), static_cast<float>(y));
  if (out.empty()) throw std::runtime_error(path + ": no 'x y' pixels");
  return out;
}

ImageGeometry imageGeometryOf(const CameraCalibration& camera) {
  ImageGeometry g;
  g.center_px = {camera.center_u, camera.center_v};
  g.chassis_radius_px = camera.chassis_radius_px;
  g.mirror_radius_px = camera.mirror_radius_px;
  return g;
}

CameraCalibration importNubotMirror(const std::string& mirror_xml_path, const std::string& roi_xml_path, int width,
                                    int height, double height_m) {
  const std::string text = readText(mirror_xml_path);
  if (text.find("<opencv_storage>") == std::string::npos) {
    throw CalibrationError(mirror_xml_path + ": not an OpenCV XML file (no <opencv_storage>)");
  }
  CameraCalibration c;
  c.width = width;
  c.height = height;
  c.center_u = requireNumber(text, mirror_xml_path, "center_coloum");  // sic: NuBot's spelling
  c.center_v = requireNumber(text, mirror_xml_path, "center_row");
  const double a = requireNumber(text, mirror_xml_path, "para_a");
  const double b = requireNumber(text, mirror_xml_path, "para_b");
  c.bearing_sign = 1;
  c.bearing_offset_rad = 0.0;
  c.height_m = height_m;
  if (!(a > 0 && b > 0)) {
    throw CalibrationError(mirror_xml_path + ": para_a = " + fixed(a, 6) + ", para_b = " + fixed(b, 6) +
                           ": not a mirror fit of the form d = a tan(b r) (both must be positive)");
  }
  const double r_horizon = kHalfPi / b;
  double r_mirror = 0.98 * r_horizon;
  if (const auto max_radius = xmlNumber(text, mirror_xml_path, "max_radius"))
    r_mirror = std::min(r_mirror, *max_radius);
  double r_chassis = 0.0;
  if (!roi_xml_path.empty()) {
    const std::string roi = readText(roi_xml_path);
    r_mirror = std::min(r_mirror, requireNumber(roi, roi_xml_path, "big_radius"));
    r_chassis = requireNumber(roi, roi_xml_path, "small_radius");
  }
  // A metre-scale mirror fit reaches ground distances of a few metres at its rim; the other
  // models NuBot kept in this file (tiny a) do not.
  const double d_rim = a * std::tan(b * r_mirror);
  if (!(d_rim > 1.0 && d_rim < 100.0)) {
    throw CalibrationError(mirror_xml_path + ": para_a = " + fixed(a, 6) + ", para_b = " + fixed(b, 6) + " give " +
                           fixed(d_rim, 3) + " m at the mirror's rim (r = " + fixed(r_mirror, 1) +
                           " px): not a ground distance in metres of the form a tan(b r)");
  }
  r_chassis = std::max(r_chassis, 1.0);
  if (!(r_chassis < r_mirror)) throw CalibrationError(roi_xml_path + ": small_radius must be below big_radius");
  c.chassis_radius_px = r_chassis;
  c.mirror_radius_px = r_mirror;
  constexpr int kSamples = 48;
  for (int i = 0; i < kSamples; ++i) {
    const double t = static_cast<double>(i) / (kSamples - 1);
    const double r = r_chassis + (r_mirror - r_chassis) * (1.0 - std::pow(1.0 - t, 1.6));
    const double e = std::max(kMinElevation, -std::atan(height_m / (a * std::tan(b * r))));
    if (!c.elevation_map.empty() && !(e > c.elevation_map.back().second)) continue;
    c.elevation_map.emplace_back(r, e);
  }
  return c;
}

}  // namespace core
}  // namespace act_color
