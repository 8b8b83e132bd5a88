#include <gtest/gtest.h>

#include <cmath>

#include "act_color/core/metrics.hpp"

using namespace act_color::core;

TEST(Metrics, RecallPrecisionFitness) {
  // truth:     green x4, white x2, not imaged x2
  // predicted: green x3 + white x1 on green; white x1 + green x1 on white; anything on not imaged
  cv::Mat truth = (cv::Mat_<uint8_t>(1, 8) << 1, 1, 1, 1, 2, 2, 255, 255);
  cv::Mat labels = (cv::Mat_<uint8_t>(1, 8) << 1, 1, 1, 2, 2, 1, 5, 5);
  ClassificationMetrics m;
  m.add(labels, truth);
  EXPECT_DOUBLE_EQ(m.recall(kGreen), 0.75);
  EXPECT_DOUBLE_EQ(m.precision(kGreen), 0.75);
  EXPECT_DOUBLE_EQ(m.recall(kWhite), 0.5);
  EXPECT_DOUBLE_EQ(m.precision(kWhite), 0.5);
  EXPECT_EQ(m.truthCount(kBlack), 0u);
  EXPECT_EQ(m.predictedCount(kBlack), 0u);  // not-imaged pixels are skipped
  EXPECT_TRUE(std::isnan(m.recall(kBlue)));
  EXPECT_TRUE(std::isnan(m.precision(kBlue)));
  // eq. 6: (1 - 0.75) + (1 - 0.5); absent classes add nothing.
  EXPECT_DOUBLE_EQ(m.fitness({kGreen, kWhite, kBlue}), 0.75);
  m.add(labels, truth);
  EXPECT_EQ(m.truthCount(kGreen), 8u);
  EXPECT_DOUBLE_EQ(m.recall(kGreen), 0.75);
  EXPECT_NE(m.report().find("green"), std::string::npos);
  m.clear();
  EXPECT_EQ(m.truthCount(kGreen), 0u);
}

TEST(Metrics, SizeMismatchThrows) {
  ClassificationMetrics m;
  EXPECT_THROW(m.add(cv::Mat::zeros(2, 2, CV_8UC1), cv::Mat::zeros(3, 2, CV_8UC1)), std::invalid_argument);
}
