// ActParams::carpet_edge on scenes of the randomized family (tuning split): white beyond the
// carpet's edge is the hall's clutter, and so is black there where no robot stands on the carpet,
// so labelling them unknown raises their precision and costs the lines and robots nothing.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>

#include "act_color/core/act_trainer.hpp"
#include "act_color/core/metrics.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/core/types.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scene_family.hpp"

namespace act_color {
namespace {

TEST(CarpetEdgeOnTheFamily, HallWhiteAndBlackGoTheLinesAndRobotsStay) {
  std::array<double, 2> precision_gain{};
  for (uint32_t seed = sim::kTuningSeedsBegin; seed < sim::kTuningSeedsBegin + 6; ++seed) {
    const sim::FamilyScene scene = sim::makeFamilyScene(seed);
    const sim::Renderer renderer(scene.calibration, scene.renderer);
    const core::Segmenter segmenter(scene.calibration.camera);
    core::ActTrainer trainer(scene.calibration);
    ASSERT_TRUE(trainer.params().carpet_edge);
    core::ClassificationMetrics table, edge;
    cv::Mat labels;
    const size_t frames = std::min<size_t>(scene.scenario.frames.size(), 20);
    for (size_t i = 0; i < frames; ++i) {
      const sim::ScenarioFrame& f = scene.scenario.frames[i];
      const sim::LabeledFrame frame = renderer.render(f.scene);
      const auto view = core::ImageView::fromMat(frame.rgb, core::PixelFormat::kRgb8);
      if (i == 0) trainer.bootstrap(view, f.told_pose, core::kDefaultBootstrapCycles - 1);
      trainer.cycle(view, f.told_pose);
      if (i < 10) continue;  // after the start's adaptation
      segmenter.classify(trainer.lut(), view, labels);
      table.add(labels, frame.labels);
      trainer.unlabelBeyondCarpet(labels);
      edge.add(labels, frame.labels);
    }
    for (size_t j = 0; j < 2; ++j) {
      const int k = j == 0 ? core::kWhite : core::kBlack;
      std::printf("seed %u: %s recall %.4f -> %.4f, precision %.3f -> %.3f\n", seed, core::className(k),
                  table.recall(k), edge.recall(k), table.precision(k), edge.precision(k));
      EXPECT_GE(edge.recall(k), table.recall(k) - 0.01) << "seed " << seed;
      EXPECT_GE(edge.precision(k), table.precision(k)) << "seed " << seed;
      precision_gain[j] += edge.precision(k) - table.precision(k);
    }
  }
  EXPECT_GT(precision_gain[0] / 6, 0.05);  // white
  EXPECT_GT(precision_gain[1] / 6, 0.05);  // black
  // Off (the paper's algorithm and ~carpet_edge false): nothing changes.
  const sim::FamilyScene scene = sim::makeFamilyScene(sim::kTuningSeedsBegin);
  core::ActParams off;
  off.carpet_edge = false;
  const core::ActTrainer on_trainer(scene.calibration), off_trainer(scene.calibration, off);
  // Carpet to 2 m, white beyond.
  const core::OmniCameraModel& camera = on_trainer.model().camera();
  cv::Mat labels(camera.height(), camera.width(), CV_8UC1, cv::Scalar(core::kWhite));
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      const core::PixelRay& ray = camera.ray(u, v);
      if (ray.region == core::PixelRegion::kFloor && std::hypot(ray.ground_x_m, ray.ground_y_m) < 2.0) {
        labels.at<uint8_t>(v, u) = core::kGreen;
      }
    }
  }
  cv::Mat copy = labels.clone();
  EXPECT_EQ(off_trainer.unlabelBeyondCarpet(copy), 0u);
  EXPECT_EQ(cv::countNonZero(copy != labels), 0);
  EXPECT_GT(on_trainer.unlabelBeyondCarpet(copy), 1000u);
  EXPECT_FALSE(core::ActParams::paper().carpet_edge);
}

}  // namespace
}  // namespace act_color
