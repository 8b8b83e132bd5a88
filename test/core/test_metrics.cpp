#include <gtest/gtest.h>

#include <cmath>

#include "act_color/core/metrics.hpp"
#include "act_color/core/run_evaluation.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/core/table_ceiling.hpp"

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

TEST(TableCeiling, MajorityOfTheTruthPerColorCell) {
  // Five pixels of one color: three green, two white in truth -> the cell is green; a second color
  // only white; a third color only outside the mirror (skipped).
  cv::Mat rgb(1, 8, CV_8UC3);
  const cv::Vec3b a(40, 140, 50), b(230, 230, 230), c(10, 10, 200);
  for (int u = 0; u < 5; ++u) rgb.at<cv::Vec3b>(0, u) = a;
  rgb.at<cv::Vec3b>(0, 5) = b;
  rgb.at<cv::Vec3b>(0, 6) = c;
  rgb.at<cv::Vec3b>(0, 7) = c;
  const cv::Mat truth = (cv::Mat_<uint8_t>(1, 8) << 1, 1, 1, 2, 2, 2, 255, 255);
  TableCeiling ceiling;
  ceiling.add(ImageView::fromMat(rgb, PixelFormat::kRgb8), truth);
  EXPECT_EQ(ceiling.pixels(), 6u);
  const ColorLut table = ceiling.table();
  EXPECT_EQ(table.classOf(a[0], a[1], a[2]), kGreen);
  EXPECT_EQ(table.classOf(b[0], b[1], b[2]), kWhite);
  EXPECT_EQ(table.classOf(c[0], c[1], c[2]), kUnknown);
  // The table's own metrics: green 3/3 recall, 3/5 precision; white 1/3 recall, 1/1 precision.
  const ClassificationMetrics m = ceiling.metrics();
  EXPECT_DOUBLE_EQ(m.recall(kGreen), 1.0);
  EXPECT_DOUBLE_EQ(m.precision(kGreen), 0.6);
  EXPECT_DOUBLE_EQ(m.recall(kWhite), 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(m.precision(kWhite), 1.0);
  // The same as classifying the frame with the table.
  cv::Mat labels;
  Segmenter().classify(table, ImageView::fromMat(rgb, PixelFormat::kRgb8), labels);
  ClassificationMetrics direct;
  direct.add(labels, truth);
  EXPECT_EQ(direct.confusion(), m.confusion());
  ceiling.clear();
  EXPECT_EQ(ceiling.pixels(), 0u);
  EXPECT_THROW(ceiling.add(ImageView::fromMat(rgb, PixelFormat::kRgb8), cv::Mat::zeros(2, 8, CV_8UC1)),
               std::invalid_argument);
}

TEST(FalsePixelSources, TakesAClassifiersFalsePixelsApartByTheCeilingsCells) {
  // Four colors, every pixel classified white but one carpet pixel:
  //   w: truth white, white, hall      -> 1 false white in a white cell (the ceiling's too)
  //   h: truth hall, hall, white       -> 2 false whites in a hall cell
  //   g: truth green, green            -> 1 false white in a green cell (the other pixel is green)
  //   t: truth hall, clipped red       -> 1 false white in a hall cell at the top of a channel
  const cv::Vec3b w(230, 230, 230), h(200, 190, 180), g(40, 140, 50), t(255, 250, 240), n(0, 0, 0);
  const std::vector<cv::Vec3b> colors = {w, w, w, h, h, h, g, g, t, n};
  cv::Mat rgb(1, static_cast<int>(colors.size()), CV_8UC3);
  for (size_t u = 0; u < colors.size(); ++u) rgb.at<cv::Vec3b>(0, static_cast<int>(u)) = colors[u];
  const cv::Mat truth = (cv::Mat_<uint8_t>(1, 10) << 2, 2, 0, 0, 0, 2, 1, 1, 0, 255);
  const cv::Mat labels = (cv::Mat_<uint8_t>(1, 10) << 2, 2, 2, 2, 2, 2, 2, 1, 2, 2);
  const ImageView view = ImageView::fromMat(rgb, PixelFormat::kRgb8);
  TableCeiling ceiling;
  ceiling.add(view, truth);
  FalsePixelSources sources;
  sources.add(view, labels, truth);
  const auto fp = sources.sources(ceiling.table());
  EXPECT_EQ(fp[kWhite].classified, 8u);  // the pixel outside the mirror is skipped
  EXPECT_EQ(fp[kWhite].shared, 1u);
  EXPECT_EQ(fp[kWhite].hall, 3u);
  EXPECT_EQ(fp[kWhite].other, 1u);
  EXPECT_EQ(fp[kWhite].top, 1u);
  // The parts add up to 1 - precision.
  ClassificationMetrics m;
  m.add(labels, truth);
  const double false_share =
      static_cast<double>(fp[kWhite].shared + fp[kWhite].hall + fp[kWhite].other) / fp[kWhite].classified;
  EXPECT_DOUBLE_EQ(false_share, 1.0 - m.precision(kWhite));
  EXPECT_EQ(fp[kGreen].classified, 1u);
  EXPECT_EQ(fp[kGreen].shared + fp[kGreen].hall + fp[kGreen].other, 0u);
  sources.clear();
  EXPECT_EQ(sources.sources(ceiling.table())[kWhite].classified, 0u);
  EXPECT_THROW(sources.add(view, labels, cv::Mat::zeros(2, 10, CV_8UC1)), std::invalid_argument);
  EXPECT_THROW(sources.add(view, cv::Mat::zeros(1, 9, CV_8UC1), truth), std::invalid_argument);
}

TEST(RecallCost, LeastUnwantedShareOfAnyTableAtARecall) {
  // Three cells: a (wanted 6, unwanted 0), b (wanted 3, unwanted 1), c (wanted 1, unwanted 9).
  const uint8_t a[3] = {240, 240, 240}, b[3] = {200, 200, 200}, c[3] = {255, 255, 255};
  RecallCost cost;
  EXPECT_EQ(cost.leastUnwantedShare(0.5), -1.0);
  for (int i = 0; i < 6; ++i) cost.addWanted(a);
  EXPECT_EQ(cost.leastUnwantedShare(0.5), -1.0);  // nothing unwanted: no share to give
  for (int i = 0; i < 3; ++i) cost.addWanted(b);
  cost.addWanted(c);
  cost.addUnwanted(b);
  for (int i = 0; i < 9; ++i) cost.addUnwanted(c);
  EXPECT_DOUBLE_EQ(cost.leastUnwantedShare(0.5), 0.0);  // a alone holds 6 of the 10 wanted
  EXPECT_DOUBLE_EQ(cost.leastUnwantedShare(0.6), 0.0);
  // 0.8 and 0.9: a and the whole of b (a table has no part of a cell), one unwanted pixel.
  EXPECT_NEAR(cost.leastUnwantedShare(0.8), 1.0 / 10.0, 1e-12);
  EXPECT_NEAR(cost.leastUnwantedShare(0.9), 1.0 / 10.0, 1e-12);
  cost.addWanted(c);                                             // c: 2 wanted, 9 unwanted; 11 wanted in all
  EXPECT_NEAR(cost.leastUnwantedShare(0.8), 1.0 / 10.0, 1e-12);  // 9 of 11: a and b
  EXPECT_NEAR(cost.leastUnwantedShare(0.9), 1.0, 1e-12);         // 10 of 11: c too (a and c alone: 8)
  cost.clear();
  EXPECT_EQ(cost.leastUnwantedShare(0.5), -1.0);
}

TEST(RunEvaluation, ReachIsTheFirstFrameWithinTheToleranceSettleTheLastReturn) {
  // Ten line pixels a frame; after the event white's recall goes 0.5, 0.9, 0.7, 0.9, 0.9, 0.9, 0.9,
  // 0.9 (final: the last quarter's mean, 0.9): reached in 2 cycles, settled in 4.
  RunEvaluation evaluation;
  const cv::Mat truth(1, 10, CV_8UC1, cv::Scalar(kWhite));
  auto frame = [&](int white) {
    cv::Mat labels(1, 10, CV_8UC1, cv::Scalar(kGreen));
    labels.colRange(0, white).setTo(kWhite);
    evaluation.addFrame(labels, truth);
  };
  frame(9);
  evaluation.markEvent("darken");
  for (int white : {5, 9, 7, 9, 9, 9, 9, 9}) frame(white);
  const std::vector<SegmentSummary> segments = evaluation.segments();
  ASSERT_EQ(segments.size(), 2u);
  EXPECT_NEAR(segments[1].final_recall[kWhite], 0.9, 1e-12);
  EXPECT_EQ(segments[1].reach_cycles[kWhite], 2);
  EXPECT_EQ(segments[1].settle_cycles[kWhite], 4);
  EXPECT_EQ(segments[1].reach_cycles[kGreen], -1);  // no green in the truth
}
