#include "act_color/core/class_cluster.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace act_color {
namespace core {
void ClassCluster::reset(double max_value) {
  mean_ = Eigen::Vector3d::Constant(0.5 * max_value);  // eq. 2
  sigma_max_ = std::sqrt(3.0) / 2.0 * max_value;       // eq. 3
  sigma_ = sigma_max_;
  last_samples_ = 0;
  trained_ = false;
}

int ClassCluster::update(const std::vector<Eigen::Vector3f>& colors, const ClusterParams& params) {
  last_samples_ = static_cast<unsigned>(colors.size());
  if (colors.empty()) return 0;
  const double m = static_cast<double>(colors.size());
  Eigen::Vector3d sample_mean = Eigen::Vector3d::Zero();
  for (const auto& c : colors) sample_mean += c.cast<double>();
  sample_mean /= m;
  const double eta = params.eta;
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

void ClassCluster::applyLightChange(const Eigen::Vector3d& mean, double sigma_scale, const ClusterParams& params) {
  if (!trained_) return;
  mean_ = mean.cwiseMax(0.0).cwiseMin(params.max_value);
  sigma_ = std::min(std::max(sigma_ * sigma_scale, params.sigma_min), sigma_max_);
}

void ClassCluster::set(const Eigen::Vector3d& mean, double sigma, bool trained) {
  mean_ = mean;
  sigma_ = sigma;
  trained_ = trained;
}

}  // namespace core
}  // namespace act_color
