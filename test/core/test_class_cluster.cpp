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
  ClassCluster c;
  c.update({{10, 10, 10}, {30, 30, 30}}, p);
  EXPECT_TRUE(c.mean().isApprox(Eigen::Vector3d::Constant(20)));
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
  ClassCluster c;
  const double sigma0 = c.sigma();
  EXPECT_EQ(c.update({}, p), 0);
  EXPECT_FALSE(c.trained());
  EXPECT_DOUBLE_EQ(c.sigma(), sigma0);
  c.update({{0, 0, 0}}, p);  // m = 1: mean moves, sigma (1/(m-1)) cannot be estimated
  EXPECT_TRUE(c.mean().isApprox(Eigen::Vector3d::Constant(102.0)));
  EXPECT_DOUBLE_EQ(c.sigma(), sigma0);
}
