#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "act_color/core/class_cluster.hpp"

using act_color::core::ClassCluster;
using act_color::core::ClusterParams;

TEST(ClassCluster, InitialisedAsEquationsTwoAndThree) {
  ClassCluster c;
  c.reset(255.0);
  EXPECT_TRUE(c.mean().isApprox(Eigen::Vector3d::Constant(127.5)));
  EXPECT_NEAR(c.sigma(), std::sqrt(3.0) / 2.0 * 255.0, 1e-9);
  EXPECT_FALSE(c.trained());
}

TEST(ClassCluster, UpdateIsEquationsFourAndFive) {
  ClassCluster c;
  ClusterParams p;  // eta 4
  p.sigma_min = 0.0;
  p.seed_from_first_samples = false;  // the paper's first update
  const std::vector<Eigen::Vector3f> colors = {{10, 20, 30}, {20, 20, 30}, {30, 20, 60}};
  const Eigen::Vector3d sample_mean(20, 20, 40);
  const Eigen::Vector3d mean = (4.0 * Eigen::Vector3d::Constant(127.5) + sample_mean) / 5.0;  // eq. 4
  double sum_sq = 0;
  for (const auto& col : colors) sum_sq += (col.cast<double>() - mean).squaredNorm();
  const double sigma0 = std::sqrt(3.0) / 2.0 * 255.0;
  const double sigma = (4.0 * sigma0 + std::sqrt(sum_sq / 2.0)) / 5.0;  // eq. 5, around the new mean
  EXPECT_EQ(c.update(colors, p), 0);
  EXPECT_TRUE(c.mean().isApprox(mean, 1e-12));
  EXPECT_NEAR(c.sigma(), sigma, 1e-9);
  EXPECT_EQ(c.lastSampleCount(), 3u);
  EXPECT_TRUE(c.trained());
}

TEST(ClassCluster, EtaSetsTheResponsiveness) {
  ClusterParams p;
  p.eta = 0.0;  // no memory: the mean is the samples' mean
  p.seed_from_first_samples = false;
  ClassCluster c;
  c.update({{10, 10, 10}, {30, 30, 30}}, p);
  EXPECT_TRUE(c.mean().isApprox(Eigen::Vector3d::Constant(20)));
}

TEST(ClassCluster, SeedingTakesTheFirstColorsStatistics) {
  ClusterParams p;  // seed_from_first_samples
  p.sigma_min = 0.0;
  ClassCluster c;
  c.update({{10, 10, 10}, {30, 30, 30}}, p);
  EXPECT_TRUE(c.mean().isApprox(Eigen::Vector3d::Constant(20)));
  EXPECT_NEAR(c.sigma(), std::sqrt(2 * 300.0), 1e-9);  // sqrt(sum |c - mu|^2 / (m - 1))
  // Later updates follow eq. 4 with eta.
  c.update({{70, 70, 70}, {70, 70, 70}}, p);
  EXPECT_TRUE(c.mean().isApprox(Eigen::Vector3d::Constant(30)));
}

TEST(ClassCluster, SigmaIsBoundedBelow) {
  ClusterParams p;
  p.sigma_min = 5.0;
  ClassCluster c;
  const std::vector<Eigen::Vector3f> same(10, Eigen::Vector3f(50, 120, 60));
  for (int i = 0; i < 200; ++i) c.update(same, p);
  EXPECT_NEAR(c.sigma(), 5.0, 1e-9);
  EXPECT_TRUE(c.mean().isApprox(Eigen::Vector3d(50, 120, 60), 1e-6));
}

TEST(ClassCluster, SigmaDoublesUntilNewColorsAreIncluded) {
  ClusterParams p;  // zeta 2.5, sigma_min 6
  ClassCluster c;
  std::mt19937 rng(1);
  std::normal_distribution<float> noise(0.f, 2.f);
  auto around = [&](float r, float g, float b) {
    std::vector<Eigen::Vector3f> v;
    for (int i = 0; i < 50; ++i) v.emplace_back(r + noise(rng), g + noise(rng), b + noise(rng));
    return v;
  };
  for (int i = 0; i < 100; ++i) c.update(around(60, 160, 60), p);
  EXPECT_NEAR(c.sigma(), 6.0, 1e-6);  // settled at sigma_min
  // Sudden change: without doubling, sigma would be (4 * 6 + ~69) / 5 = 18.6 and the new mean
  // (4/5 of 86 away from the cluster's) outside 2.5 sigma.
  const auto dark = around(30, 80, 30);
  const int doublings = c.update(dark, p);
  EXPECT_GE(doublings, 1);
  Eigen::Vector3d dark_mean = Eigen::Vector3d::Zero();
  for (const auto& d : dark) dark_mean += d.cast<double>();
  dark_mean /= dark.size();
  EXPECT_LE((dark_mean - c.mean()).norm(), p.zeta * c.sigma());
  EXPECT_GT((dark_mean - c.mean()).norm(), p.zeta * c.sigma() / 2.0);  // doubled no more than needed
}

TEST(ClassCluster, EmptyAndSingleSampleSets) {
  ClusterParams p;
  p.seed_from_first_samples = false;
  ClassCluster c;
  const double sigma0 = c.sigma();
  EXPECT_EQ(c.update({}, p), 0);
  EXPECT_FALSE(c.trained());
  EXPECT_DOUBLE_EQ(c.sigma(), sigma0);
  c.update({{0, 0, 0}}, p);  // m = 1: mean moves, sigma (1/(m-1)) cannot be estimated
  EXPECT_TRUE(c.mean().isApprox(Eigen::Vector3d::Constant(102.0)));
  EXPECT_DOUBLE_EQ(c.sigma(), sigma0);
}

namespace {

std::vector<Eigen::Vector3f> gaussianColors(const Eigen::Vector3f& mean, float sigma_per_channel, size_t n,
                                            uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.f, sigma_per_channel);
  std::vector<Eigen::Vector3f> colors;
  for (size_t i = 0; i < n; ++i) colors.push_back(mean + Eigen::Vector3f(noise(rng), noise(rng), noise(rng)));
  return colors;
}

}  // namespace

TEST(ClassCluster, RobustUpdateFollowsTheSpreadOfItsColors) {
  ClusterParams p;
  const Eigen::Vector3f mean(200, 200, 200);
  // Normal colors, 5 per channel: eq. 5's sigma (root mean square distance) is 5 sqrt(3) = 8.7.
  ClassCluster c;
  c.updateFromInliers(gaussianColors(mean, 5.f, 2000, 1), p);
  EXPECT_NEAR(c.mean()[0], 200.0, 0.5);
  EXPECT_NEAR(c.sigma(), 8.66, 0.5);
  for (int i = 0; i < 30; ++i) c.updateFromInliers(gaussianColors(mean, 5.f, 2000, 2 + i), p);
  EXPECT_NEAR(c.sigma(), 8.66, 0.5);
  // A quarter of the colors far out (the blurred edges of thin lines, mixed with the carpet): the
  // median alone would not see them; sigma grows to cover the 80th percentile.
  auto tailed = gaussianColors(mean, 5.f, 1500, 100);
  const auto tail = gaussianColors(Eigen::Vector3f(170, 190, 170), 3.f, 500, 101);
  tailed.insert(tailed.end(), tail.begin(), tail.end());
  for (int i = 0; i < 30; ++i) c.updateFromInliers(tailed, p);
  EXPECT_GT(c.sigma(), 15.0);
  // The mean follows the colors within zeta sigma only.
  EXPECT_GT(c.mean()[1], 190.0);
}

TEST(ClassCluster, RobustUpdateIgnoresAMinorityOfOutliers) {
  ClusterParams p;
  ClassCluster c;
  auto colors = gaussianColors(Eigen::Vector3f(60, 140, 60), 4.f, 700, 7);
  const auto outliers = gaussianColors(Eigen::Vector3f(20, 20, 20), 4.f, 300, 8);  // a robot in the goal
  colors.insert(colors.end(), outliers.begin(), outliers.end());
  for (int i = 0; i < 20; ++i) c.updateFromInliers(colors, p);
  EXPECT_NEAR(c.mean()[1], 140.0, 1.0);
  EXPECT_LT(c.sigma(), 40.0);  // the outliers, 130 away, stay beyond zeta sigma
}
