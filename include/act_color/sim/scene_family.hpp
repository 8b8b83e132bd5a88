#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "act_color/core/calibration.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scenario.hpp"

namespace act_color {
namespace sim {

// The randomized scene family (domain randomization): every seed draws a camera (mirror profile,
// mount height, image size, centre, bearings, own chassis and mirror struts), a field (6 x 4 m
// lab field to 18 x 12 m), a hall (clutter near the class colors, people, near and far walls,
// materials), photometry (gain, affine brightness/contrast, gamma, white balance, saturation,
// black level, clipping, noise, blur, vignetting, light from one side, spots) and a sequence of
// events (sudden and slow changes of light, auto-exposure swings, a wrong pose, driving).
// Deterministic in (seed, length). Nothing in the ACT core is tuned to it: act_eval tunes on
// seeds kTuningSeeds and reports on kReportSeeds.
struct FamilyScene {
  uint32_t seed = 0;
  std::string summary;            // one line: camera, field, hall, photometry, events
  core::Calibration calibration;  // the true camera and field (ACT is told exactly this)
  RendererOptions renderer;       // hall, materials, robot parts for Renderer(calibration, renderer)
  Scenario scenario;              // frames, the poses ACT is told, events
};

FamilyScene makeFamilyScene(uint32_t seed, ScenarioLength length = ScenarioLength::kSmall);

// The fixed split of issue 11: tune on [0, 100), report on [1000, 1100).
constexpr uint32_t kTuningSeedsBegin = 0, kTuningSeedsEnd = 100;
constexpr uint32_t kReportSeedsBegin = 1000, kReportSeedsEnd = 1100;

}  // namespace sim
}  // namespace act_color
