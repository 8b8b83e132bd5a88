#include "act_color/core/class_cluster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace act_color {
namespace core {
namespace {

// For normally distributed colors (chi distribution, 3 degrees of freedom) the root mean square
// distance from the mean, eq. 5's sigma, is 1.126 times the median distance and 0.804 times the
// 80th percentile.
constexpr double kRmsPerMedian = 1.126;
constexpr double kRmsPerQuantile80 = 0.804;
// A tail of colors (the 80th percentile) may widen sigma to at most this many times what the
// median says: a minority of outliers (a robot in front of a goal) cannot take the cluster over.
constexpr double kMaxTailGrowth = 3.0;

}  // namespace

void ClassCluster::reset(double max_value) {
  mean_ = Eigen::Vector3d::Constant(0.5 * max_value);  // eq. 2
  sigma_max_ = std::sqrt(3.0) / 2.0 * max_value;       // eq. 3
  sigma_ = sigma_max_;
  last_samples_ = 0;
  trained_ = false;
  misfit_cycles_ = 0;
}

int ClassCluster::update(const std::vector<Eigen::Vector3f>& colors, const ClusterParams& params) {
  last_samples_ = static_cast<unsigned>(colors.size());
  if (colors.empty()) return 0;
  const double m = static_cast<double>(colors.size());
  Eigen::Vector3d sample_mean = Eigen::Vector3d::Zero();
  for (const auto& c : colors) sample_mean += c.cast<double>();
  sample_mean /= m;
  // Seeding (an extension, see ClusterParams) is eq. 4-5 with eta = 0 for the first update.
  const bool seed = params.seed_from_first_samples && !trained_ && colors.size() >= 2;
  const double eta = seed ? 0.0 : params.eta;
  mean_ = (eta * mean_ + sample_mean) / (eta + 1.0);  // eq. 4
  if (colors.size() >= 2) {
    double sum_sq = 0.0;
    for (const auto& c : colors) sum_sq += (c.cast<double>() - mean_).squaredNorm();
    sigma_ = (eta * sigma_ + std::sqrt(sum_sq / (m - 1.0))) / (eta + 1.0);  // eq. 5
  }
  sigma_ = std::max(sigma_, params.sigma_min);
  // Section 2.2: after a change of light the cluster may be too small for the new colors.
  int doublings = 0;
  while ((sample_mean - mean_).norm() > params.zeta * sigma_ && sigma_ < sigma_max_) {
    sigma_ = std::min(2.0 * sigma_, sigma_max_);
    ++doublings;
  }
  trained_ = true;
  return doublings;
}

unsigned ClassCluster::updateFromInliers(const std::vector<Eigen::Vector3f>& colors, const ClusterParams& params) {
  if (!trained_) {
    if (colors.size() < 2) {
      last_samples_ = 0;
      return 0;
    }
    seedRobustly(colors, params);
    return last_samples_;
  }
  inliers_.clear();
  const double radius = params.zeta * sigma_;
  for (const auto& c : colors) {
    if ((c.cast<double>() - mean_).norm() < radius) inliers_.push_back(c);
  }
  if (inliers_.size() < 2) {
    last_samples_ = 0;
    return 0;
  }
  // eq. 4 from the inliers.
  Eigen::Vector3d inlier_mean = Eigen::Vector3d::Zero();
  for (const auto& c : inliers_) inlier_mean += c.cast<double>();
  inlier_mean /= static_cast<double>(inliers_.size());
  mean_ = (params.eta * mean_ + inlier_mean) / (params.eta + 1.0);
  // eq. 5 with the spread of all colors by their median distance (robust to up to half of them
  // being outliers): the inliers alone could never show that a cluster seeded too small is too
  // small. The spread may at most double sigma in one cycle, so that one frame of wrong colors
  // cannot blow the cluster up.
  distances_.clear();
  for (const auto& c : colors) distances_.push_back((c.cast<double>() - mean_).norm());
  const size_t q80 = distances_.size() * 4 / 5, q50 = distances_.size() / 2;
  std::nth_element(distances_.begin(), distances_.begin() + q80, distances_.end());
  std::nth_element(distances_.begin(), distances_.begin() + q50, distances_.begin() + q80);
  const double by_median = kRmsPerMedian * distances_[q50];
  const double by_q80 = std::min(kRmsPerQuantile80 * distances_[q80], kMaxTailGrowth * by_median);
  const double spread = std::min(std::max(by_median, by_q80), 2.0 * sigma_);
  sigma_ = std::max((params.eta * sigma_ + spread) / (params.eta + 1.0), params.sigma_min);
  last_samples_ = static_cast<unsigned>(inliers_.size());
  return last_samples_;
}

bool ClassCluster::reacquireIfLost(const std::vector<Eigen::Vector3f>& colors, const ClusterParams& params) {
  constexpr size_t kMinColorsToJudge = 4;
  if (params.reacquire_cycles <= 0 || !trained_ || colors.size() < kMinColorsToJudge) return false;
  const double radius = params.zeta * sigma_;
  size_t fitting = 0;
  for (const auto& c : colors) fitting += (c.cast<double>() - mean_).norm() < radius;
  misfit_cycles_ = 4 * fitting < colors.size() ? misfit_cycles_ + 1 : 0;
  if (misfit_cycles_ < params.reacquire_cycles) return false;
  seedRobustly(colors, params);
  return true;
}

void ClassCluster::seedRobustly(const std::vector<Eigen::Vector3f>& colors, const ClusterParams& params) {
  std::vector<float> channel(colors.size());
  Eigen::Vector3d median;
  for (int c = 0; c < 3; ++c) {
    for (size_t i = 0; i < colors.size(); ++i) channel[i] = colors[i][c];
    std::nth_element(channel.begin(), channel.begin() + channel.size() / 2, channel.end());
    median[c] = channel[channel.size() / 2];
  }
  std::vector<double> distance(colors.size());
  for (size_t i = 0; i < colors.size(); ++i) distance[i] = (colors[i].cast<double>() - median).norm();
  std::nth_element(distance.begin(), distance.begin() + distance.size() / 2, distance.end());
  mean_ = median;
  sigma_ = std::max(kRmsPerMedian * distance[distance.size() / 2], params.sigma_min);
  last_samples_ = static_cast<unsigned>(colors.size());
  trained_ = true;
  misfit_cycles_ = 0;
}

void ClassCluster::applyLightChange(const Eigen::Vector3d& mean, double sigma_scale, const ClusterParams& params) {
  if (!trained_) return;
  mean_ = mean.cwiseMax(0.0).cwiseMin(params.max_value);
  sigma_ = std::min(std::max(sigma_ * sigma_scale, params.sigma_min), sigma_max_);
  misfit_cycles_ = 0;
}

void ClassCluster::set(const Eigen::Vector3d& mean, double sigma, bool trained) {
  mean_ = mean;
  sigma_ = sigma;
  trained_ = trained;
}

}  // namespace core
}  // namespace act_color
