#pragma once

#include <Eigen/Core>
#include <vector>

namespace act_color {
namespace core {

// Parameters of the cluster update (paper, section 2.2).
struct ClusterParams {
  double eta = 4.0;          // memory of the running mean and sigma (eq. 4, 5)
  double sigma_min = 6.0;    // lower bound of sigma, channel units
  double zeta = 2.5;         // a cluster "includes" colors within zeta * sigma
  double max_value = 255.0;  // C_max
  // Extension: the first update of an untrained cluster takes the colors' own mean and spread
  // instead of blending them with eq. 2-3 (whose sigma covers the whole color cube, so that every
  // outlier of the first cycles would be added). false: the paper's eq. 4-5 from the start.
  bool seed_from_first_samples = true;
  // Extension (re-acquisition) for updateFromInliers: when fewer than a quarter of the class's
  // colors fit the cluster for this many cycles in a row, the expected pixels show something the
  // cluster no longer describes (the light changed in a way no model foresaw): the cluster is
  // seeded again from them. 0: never.
  int reacquire_cycles = 0;
};

// Mean and standard deviation of the colors of one class, tracked over cycles (eq. 2-5).
class ClassCluster {
 public:
  ClassCluster() { reset(255.0); }

  // eq. 2 and 3: the centre of the color cube, sigma covering all of it.
  void reset(double max_value);

  // One cycle with the colors expected to belong to the class (eq. 4, 5; see
  // ClusterParams::seed_from_first_samples for the first one), then sigma_min and the
  // doubling rule: while the colors' mean lies beyond zeta * sigma of the cluster mean, sigma is
  // doubled (up to its initial value) so that the cluster grows to include them.
  // Returns the number of doublings; does nothing for an empty set.
  int update(const std::vector<Eigen::Vector3f>& colors, const ClusterParams& params);

  const Eigen::Vector3d& mean() const { return mean_; }
  double sigma() const { return sigma_; }
  unsigned lastSampleCount() const { return last_samples_; }
  bool trained() const { return trained_; }

  // Extension (ActParams::robust_clusters) for classes whose expected pixels may show something
  // else (a robot in front of a goal, a wrong pose): an untrained cluster is seeded from the
  // per-channel median and the median distance; a trained one moves its mean by eq. 4 towards the
  // colors within zeta * sigma (at least two) and its sigma by eq. 5 towards the spread of all
  // colors (the larger of the estimates from the median and from the 80th percentile distance, the
  // latter at most 3 times the former, and at most twice sigma), without doubling. Returns the
  // inliers used.
  unsigned updateFromInliers(const std::vector<Eigen::Vector3f>& colors, const ClusterParams& params);

  // ClusterParams::reacquire_cycles: counts the cycles in a row in which fewer than a quarter of
  // `colors` (all colors expected for the class, at least 4) lie within zeta * sigma, and seeds the
  // cluster again from them (per-channel median, median distance) when they reach the limit.
  // Returns true when it did. Untrained clusters are left to their first update.
  bool reacquireIfLost(const std::vector<Eigen::Vector3f>& colors, const ClusterParams& params);

  // A global change of light (LightModel): the mean moves to where the light maps it, sigma
  // scales with the map's slope there.
  void applyLightChange(const Eigen::Vector3d& mean, double sigma_scale, const ClusterParams& params);

  // For restoring a saved state.
  void set(const Eigen::Vector3d& mean, double sigma, bool trained);

 private:
  Eigen::Vector3d mean_;
  double sigma_ = 0.0;
  double sigma_max_ = 0.0;
  unsigned last_samples_ = 0;
  bool trained_ = false;
  int misfit_cycles_ = 0;  // cycles in a row with too few inliers (ClusterParams::reacquire_cycles)
  // Seeds the cluster from the per-channel median and the median distance of `colors` (>= 2).
  void seedRobustly(const std::vector<Eigen::Vector3f>& colors, const ClusterParams& params);
  std::vector<Eigen::Vector3f> inliers_;  // scratch
  std::vector<double> distances_;         // scratch
};

}  // namespace core
}  // namespace act_color
