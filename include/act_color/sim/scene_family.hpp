#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

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

// How the family's sudden changes of light act: kGlobal, on the whole image (tone curves: a camera
// setting, all the hall's lamps); kLocal, on one part of the field and hall (the light beyond a
// line across the field multiplied by 0.25-0.6 or 1.4-1.8: lamps over one half off, a window's
// sun gone or out; events "local:<axis><side><line m>*<factor>"). Everything else about a scene,
// its other events included, is the same either way.
enum class LightEvents { kGlobal, kLocal };

// `ball_looks` false: the ball orange, plain and where it was, no team markers, no poster of the
// ball's color (the scenes as they were before issue 13; act_calibrate's simulator check was
// developed on those).
FamilyScene makeFamilyScene(uint32_t seed, ScenarioLength length = ScenarioLength::kSmall, bool ball_looks = true,
                            LightEvents light_events = LightEvents::kGlobal);

// The kinds of the family's events (ScenarioFrame::events), in a fixed order. The first five are
// the named sudden changes (tone curves from the event's frame on): "darken" (the paper's
// brightness and contrast to 50%, ToneCurve::brightnessContrast(0.5, 0.5)), "gain_0.5",
// "gamma_1.6", "warm_white_balance" (ToneCurve::whiteBalance(-2000)), "brighten" (gain 1.5-1.6).
// Then "tone" (events "tone:<description>", a ToneCurve::random), "slow_change" (light level
// ramp over ~30 frames, 90 in kFull), "auto_exposure" (exposure swinging 0.7-1.3, then settling),
// "wrong_pose" (told pose 2.5 m off and rotated 165 degrees for some frames, paper 3.3) and
// "drive" (a static robot starts driving; told poses get a few cm of noise); "local" (events
// "local:..." of LightEvents::kLocal, in place of the sudden changes).
const std::vector<std::string>& familyEventKinds();
// The kind of an event name: the text before ':' ("tone:gain0.62" -> "tone").
std::string familyEventKind(const std::string& event);
// True for the five named sudden changes.
bool isNamedToneChange(const std::string& event);
// True for every sudden change of light: the named ones, "tone" and "local".
bool isSuddenChange(const std::string& event);

// The fixed split of issue 11: tune on [0, 100), report on [1000, 1100).
constexpr uint32_t kTuningSeedsBegin = 0, kTuningSeedsEnd = 100;
constexpr uint32_t kReportSeedsBegin = 1000, kReportSeedsEnd = 1100;

}  // namespace sim
}  // namespace act_color
