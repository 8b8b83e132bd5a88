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
};

// Mean and standard deviation of the colors of one class, tracked over cycles (eq. 2-5).
class ClassCluster {
 public:
  ClassCluster() { reset(255.0); }

  // eq. 2 and 3: the centre of the color cube, sigma covering all of it.
  void reset(double max_value);

  // One cycle with the colors expected to belong to the class (eq. 4, 5), then sigma_min and the
  // doubling rule: while the colors' mean lies beyond zeta * sigma of the cluster mean, sigma is
  // doubled (up to its initial value) so that the cluster grows to include them.
  // Returns the number of doublings; does nothing for an empty set.
  int update(const std::vector<Eigen::Vector3f>& colors, const ClusterParams& params);

  const Eigen::Vector3d& mean() const { return mean_; }
  double sigma() const { return sigma_; }
  unsigned lastSampleCount() const { return last_samples_; }
  bool trained() const { return trained_; }

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
};

}  // namespace core
}  // namespace act_color
