#include "act_color/sim/flicker_evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "act_color/core/segmenter.hpp"
#include "act_color/sim/tone_curve.hpp"

namespace act_color {
namespace sim {

FlickerFrames steadyLightFrames(const FamilyScene& scene, size_t count, uint32_t noise_offset) {
  const Renderer renderer(scene.calibration, scene.renderer);
  const Lighting light = scene.scenario.frames[0].scene.lighting;
  FlickerFrames out;
  for (size_t i = 0; i < count; ++i) {
    Scene s = scene.scenario.frames[std::min(i, scene.scenario.frames.size() - 1)].scene;
    s.lighting = light;
    s.noise_seed = static_cast<uint32_t>(i + 1) + noise_offset;
    out.frames.push_back(renderer.render(s));
    out.poses.push_back(s.robot_pose);
  }
  return out;
}

FlickerRun playWithGains(const FamilyScene& scene, const FlickerFrames& frames, const std::vector<double>& gains,
                         const core::ActParams& params) {
  core::ActTrainer trainer(scene.calibration, params);
  const core::Segmenter segmenter(scene.calibration.camera);
  FlickerRun run;
  cv::Mat labels;
  for (size_t i = 0; i < frames.frames.size(); ++i) {
    cv::Mat rgb = frames.frames[i].rgb.clone();
    if (gains[i] != 1.0) ToneCurve::gain(Eigen::Vector3d::Constant(gains[i])).apply(rgb);
    const core::ImageView view = core::ImageView::fromMat(rgb, core::PixelFormat::kRgb8);
    if (i == 0) {
      trainer.bootstrap(view, frames.poses[i], core::kDefaultBootstrapCycles);
    } else {
      const core::CycleStats stats = trainer.cycle(view, frames.poses[i]);
      run.light_changes += stats.light_change;
      run.restores += stats.light_restored;
    }
    run.fill.push_back(trainer.lut().mappedCells() / static_cast<double>(trainer.lut().size()));
    segmenter.classify(trainer.lut(), view, labels);
    run.per_frame.emplace_back();
    run.per_frame.back().add(labels, frames.frames[i].labels);
  }
  return run;
}

std::vector<double> everyNthFrame(size_t count, int period, double gain) {
  std::vector<double> gains(count, 1.0);
  for (size_t i = 0; period > 0 && i < count; ++i) {
    if (static_cast<int>(i % static_cast<size_t>(period)) == period - 1) gains[i] = gain;
  }
  return gains;
}

std::vector<double> exposureSwing(size_t count, size_t first, double amplitude, double hz) {
  std::vector<double> gains(count, 1.0);
  for (size_t i = first; i < count; ++i) {
    gains[i] = 1.0 + amplitude * std::sin(2.0 * M_PI * hz * static_cast<double>(i - first) / 30.0 + 0.5);
  }
  return gains;
}

const std::vector<double>& steadyReferenceGains() {
  // Every 0.025: a frame is compared with a light at most 0.0125 from its own. At every 0.1, the
  // frames of an exposure alternating between 0.856 and 1.144 were compared with steady runs at 0.9
  // and 1.1, whose white precision differs by up to 0.04 from runs at their own gains (tuning
  // scene 3), more than the target allows; the controls (fresh noise) differ by at most 0.015.
  static const std::vector<double> gains = [] {
    std::vector<double> g;
    for (int i = 0; i <= 24; ++i) g.push_back(0.7 + 0.025 * i);
    return g;
  }();
  return gains;
}

int steadyReferenceFor(double gain) {
  if (!(gain >= 0.65 && gain <= 1.35)) return -1;
  const std::vector<double>& levels = steadyReferenceGains();
  size_t best = 0;
  for (size_t l = 1; l < levels.size(); ++l) {
    if (std::abs(levels[l] - gain) < std::abs(levels[best] - gain)) best = l;
  }
  return static_cast<int>(best);
}

std::vector<FlickerRun> playSteadyReferences(const FamilyScene& scene, const FlickerFrames& frames,
                                             const core::ActParams& params, const std::vector<double>* compared_gains) {
  const std::vector<double>& levels = steadyReferenceGains();
  std::vector<bool> needed(levels.size(), compared_gains == nullptr);
  if (compared_gains != nullptr) {
    for (const double gain : *compared_gains) {
      const int l = steadyReferenceFor(gain);
      if (l >= 0) needed[static_cast<size_t>(l)] = true;
    }
  }
  std::vector<FlickerRun> references(levels.size());
  for (size_t l = 0; l < levels.size(); ++l) {
    if (needed[l])
      references[l] = playWithGains(scene, frames, std::vector<double>(frames.frames.size(), levels[l]), params);
  }
  return references;
}

FlickerComparison compareWithSteadyLight(const FlickerRun& run, const std::vector<double>& gains,
                                         const std::vector<FlickerRun>& references, size_t first) {
  FlickerComparison out;
  int compared = 0;
  for (size_t i = first; i < run.fill.size(); ++i) {
    const int level = steadyReferenceFor(gains[i]);
    if (level < 0) continue;
    const FlickerRun& reference = references.at(static_cast<size_t>(level));
    if (reference.fill.size() <= i) throw std::invalid_argument("no steady reference played for this gain");
    const double ratio = run.fill[i] / std::max(reference.fill[i], 1e-9);
    out.fill_max_ratio = std::max(out.fill_max_ratio, ratio);
    out.fill_mean_ratio += ratio;
    out.run.merge(run.per_frame[i]);
    out.reference.merge(reference.per_frame[i]);
    ++compared;
  }
  if (compared > 0) out.fill_mean_ratio /= compared;
  out.worst_precision_drop = -1.0;
  for (const int k : core::trainableClasses()) {
    const double drop = out.reference.precision(k) - out.run.precision(k);
    if (std::isfinite(drop) && drop > out.worst_precision_drop) {
      out.worst_precision_drop = drop;
      out.worst_class = k;
    }
  }
  return out;
}

}  // namespace sim
}  // namespace act_color
