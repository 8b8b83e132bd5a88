#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

#include "act_color/core/calibration.hpp"
#include "act_color/core/expected_class_model.hpp"
#include "act_color/sim/scene_family.hpp"
#include "act_color/sim/tone_curve.hpp"
#include "sim_test_util.hpp"

namespace act_color {
namespace {

using sim::FamilyScene;
using sim::makeFamilyScene;
using sim::ToneCurve;

bool isMonotone(const ToneCurve& curve) {
  for (const ToneCurve::Table& t : curve.tables()) {
    if (!std::is_sorted(t.begin(), t.end())) return false;
  }
  return true;
}

int rounded(double value) { return static_cast<int>(std::clamp(std::lround(value), 0L, 255L)); }

bool sameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() &&
         std::equal(a.datastart, a.dataend, b.datastart);  // continuous: freshly allocated
}

TEST(ToneCurve, NamedKindsFollowTheirFormulas) {
  EXPECT_TRUE(ToneCurve().isIdentity());
  const ToneCurve paper = ToneCurve::brightnessContrast(0.5, 0.5);
  const ToneCurve half = ToneCurve::gain(Eigen::Vector3d::Constant(0.5));
  const ToneCurve bright = ToneCurve::gain(Eigen::Vector3d::Constant(1.6));
  const ToneCurve gamma = ToneCurve::gamma(1.6);
  const ToneCurve black = ToneCurve::blackLevel(10.0);
  for (int c = 0; c < 3; ++c) {
    // The paper's darkening (3.2) compresses the range to about [32, 96].
    EXPECT_NEAR(paper.map(c, 0), 32, 1);
    EXPECT_NEAR(paper.map(c, 255), 96, 1);
    EXPECT_EQ(bright.map(c, 255), 255) << "clipped";
    EXPECT_EQ(black.map(c, 0), 10);
    EXPECT_EQ(black.map(c, 255), 255);
    for (int v = 0; v < 256; ++v) {
      EXPECT_EQ(paper.map(c, v), rounded(((v - 127.5) * 0.5 + 127.5) * 0.5));
      EXPECT_EQ(half.map(c, v), rounded(0.5 * v));
      EXPECT_EQ(bright.map(c, v), rounded(1.6 * v));
      EXPECT_EQ(gamma.map(c, v), rounded(255.0 * std::pow(v / 255.0, 1.6)));
      EXPECT_EQ(black.map(c, v), rounded(10.0 + 245.0 * v / 255.0));
    }
  }
  for (const ToneCurve& curve : {paper, half, bright, gamma, black}) EXPECT_TRUE(isMonotone(curve));
  // Warm: red up, blue down, green kept; cold the other way round.
  const ToneCurve warm = ToneCurve::whiteBalance(-2000.0), cold = ToneCurve::whiteBalance(2000.0);
  EXPECT_GT(warm.map(0, 128), 140);
  EXPECT_EQ(warm.map(1, 128), 128);
  EXPECT_LT(warm.map(2, 128), 116);
  EXPECT_LT(cold.map(0, 128), 128);
  EXPECT_EQ(cold.map(1, 128), 128);
  EXPECT_GT(cold.map(2, 128), 128);
  EXPECT_TRUE(ToneCurve::whiteBalance(0.0).isIdentity());
}

TEST(ToneCurve, CompositionApplicationAndRandomCurves) {
  const ToneCurve a = ToneCurve::gain(Eigen::Vector3d(0.8, 0.9, 1.1));
  const ToneCurve b = ToneCurve::gamma(1.3);
  const ToneCurve ab = a.then(b);
  for (int c = 0; c < 3; ++c) {
    for (int v = 0; v < 256; ++v) EXPECT_EQ(ab.map(c, v), b.map(c, a.map(c, v)));
  }
  cv::Mat image(3, 4, CV_8UC3);
  for (int i = 0; i < 36; ++i) image.data[i] = static_cast<uint8_t>(7 * i);
  const cv::Mat before = image.clone();
  ab.apply(image);
  for (int i = 0; i < 36; ++i) EXPECT_EQ(image.data[i], ab.map(i % 3, before.data[i]));

  ToneCurve::Table falling;
  for (int v = 0; v < 256; ++v) falling[v] = static_cast<uint8_t>(255 - v);
  EXPECT_THROW(ToneCurve({falling, falling, falling}), std::invalid_argument);

  std::mt19937 rng(42);
  for (int n = 0; n < 200; ++n) {
    std::string description;
    const ToneCurve zero = ToneCurve::random(rng, 0.0, &description);
    EXPECT_TRUE(zero.isIdentity()) << description;
    const double strength = n / 199.0;
    EXPECT_TRUE(isMonotone(ToneCurve::random(rng, strength, &description))) << description;
    EXPECT_FALSE(description.empty());
    // Strength 1: mid-grey green goes to about the paper's darkening or a 1.6x brightening.
    const ToneCurve full = ToneCurve::random(rng, 1.0, &description);
    const int mid = full.map(1, 128);
    EXPECT_TRUE(mid <= 75 || mid >= 190) << description << ": 128 -> " << mid;
  }
}

TEST(SceneFamily, DefaultOptionsRenderAsTheHallSeedConstructor) {
  const core::Calibration cal = sim_test::defaultCalibration();
  sim::RendererOptions options;
  options.hall_seed = 11;
  const sim::Renderer a(cal, 11u), b(cal, options);
  sim::Scene scene;
  scene.robot_pose = {1.0, -2.0, 0.7};
  scene.robots = {{2.0, -1.0, 0.25, 0.8}};
  scene.ball = sim::Ball{0.0, -2.5, 0.11};
  const sim::LabeledFrame fa = a.render(scene), fb = b.render(scene);
  EXPECT_TRUE(sameBytes(fa.rgb, fb.rgb));
  EXPECT_TRUE(sameBytes(fa.labels, fb.labels));
}

TEST(SceneFamily, IsDeterministic) {
  // Seeds of the tuning split, small images for speed.
  uint32_t seed = sim::kTuningSeedsBegin;
  while (makeFamilyScene(seed).calibration.camera.width > 640) ++seed;
  const FamilyScene a = makeFamilyScene(seed), b = makeFamilyScene(seed);
  EXPECT_EQ(a.summary, b.summary);
  EXPECT_EQ(core::toYaml(a.calibration), core::toYaml(b.calibration));
  ASSERT_EQ(a.scenario.frames.size(), b.scenario.frames.size());
  for (size_t i = 0; i < a.scenario.frames.size(); ++i) {
    EXPECT_EQ(a.scenario.frames[i].events, b.scenario.frames[i].events);
    EXPECT_EQ(a.scenario.frames[i].told_pose.x_m, b.scenario.frames[i].told_pose.x_m);
  }
  const sim::LabeledFrame fa = sim::Renderer(a.calibration, a.renderer).render(a.scenario.frames[0].scene);
  const sim::LabeledFrame fb = sim::Renderer(b.calibration, b.renderer).render(b.scenario.frames[0].scene);
  EXPECT_TRUE(sameBytes(fa.rgb, fb.rgb));
  EXPECT_TRUE(sameBytes(fa.labels, fb.labels));
  EXPECT_NE(makeFamilyScene(seed + 1).summary, a.summary);
}

// Promises of every scene of both splits (no rendering: fast).
TEST(SceneFamily, CalibrationsValidateAndScenesKeepTheirPromises) {
  std::vector<uint32_t> seeds;
  for (uint32_t s = sim::kTuningSeedsBegin; s < sim::kTuningSeedsEnd; ++s) seeds.push_back(s);
  for (uint32_t s = sim::kReportSeedsBegin; s < sim::kReportSeedsEnd; ++s) seeds.push_back(s);
  int named = 0;
  for (const uint32_t seed : seeds) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const FamilyScene f = makeFamilyScene(seed);
    EXPECT_EQ(f.seed, seed);
    EXPECT_FALSE(f.summary.empty());
    EXPECT_NO_THROW(core::validateCalibration(f.calibration, "family"));
    EXPECT_NO_THROW(core::parseCalibration(core::toYaml(f.calibration), "family"));
    const core::CameraCalibration& c = f.calibration.camera;
    EXPECT_GE(c.elevation_map.size(), 24u);
    EXPECT_LE(c.elevation_map.size(), 40u);
    EXPECT_LE(c.elevation_map.back().second, 0.25 + 1e-9);
    EXPECT_GT(c.elevation_map.back().second, 0.0);
    EXPECT_EQ(c.elevation_map.back().first, c.mirror_radius_px);
    EXPECT_GE(c.center_u - c.mirror_radius_px, 0.0);
    EXPECT_LE(c.center_u + c.mirror_radius_px, c.width);
    EXPECT_GE(c.center_v - c.mirror_radius_px, 0.0);
    EXPECT_LE(c.center_v + c.mirror_radius_px, c.height);
    EXPECT_NEAR(c.chassis_radius_px / c.mirror_radius_px, 0.13, 0.05 + 1.0 / c.mirror_radius_px);
    EXPECT_GE(c.height_m, 0.5);
    EXPECT_LE(c.height_m, 0.9);
    EXPECT_LE(f.renderer.struts.size(), 4u);

    const core::FieldCalibration& field = f.calibration.field;
    const double carpet_x = field.length_m / 2 + field.margin_m, carpet_y = field.width_m / 2 + field.margin_m;
    const auto& frames = f.scenario.frames;
    EXPECT_GE(frames.size(), 40u);
    EXPECT_LE(frames.size(), 60u);
    std::vector<int> event_frames;
    int events = 0;
    bool has_named = false;
    for (size_t i = 0; i < frames.size(); ++i) {
      if (!frames[i].events.empty()) event_frames.push_back(static_cast<int>(i));
      events += static_cast<int>(frames[i].events.size());
      for (const std::string& e : frames[i].events) {
        EXPECT_NE(std::find(sim::familyEventKinds().begin(), sim::familyEventKinds().end(), sim::familyEventKind(e)),
                  sim::familyEventKinds().end())
            << e;
        has_named |= sim::isNamedToneChange(e);
      }
      const core::Pose2D& truth = frames[i].scene.robot_pose;
      EXPECT_LT(std::abs(truth.x_m), field.length_m / 2);
      EXPECT_LT(std::abs(truth.y_m), field.width_m / 2);
      EXPECT_LT(std::abs(frames[i].told_pose.x_m), carpet_x);
      EXPECT_LT(std::abs(frames[i].told_pose.y_m), carpet_y);
      for (const sim::RobotObstacle& r : frames[i].scene.robots) {
        EXPECT_GE(std::hypot(r.x_m - truth.x_m, r.y_m - truth.y_m), 0.9 - 1e-9);
      }
      if (frames[i].scene.ball) {
        EXPECT_GE(std::hypot(frames[i].scene.ball->x_m - truth.x_m, frames[i].scene.ball->y_m - truth.y_m), 0.5);
      }
      for (const sim::Person& p : frames[i].scene.people) {
        EXPECT_TRUE(std::abs(p.x_m) > carpet_x + p.radius_m || std::abs(p.y_m) > carpet_y + p.radius_m);
        EXPECT_GE(p.height_m, 1.5);
        EXPECT_LE(p.height_m, 1.9);
      }
    }
    named += has_named;
    EXPECT_GE(events, 1);
    EXPECT_LE(events, 3);
    ASSERT_FALSE(event_frames.empty());
    EXPECT_GE(event_frames.front(), 14);
    for (size_t k = 0; k < event_frames.size(); ++k) {
      const int next = k + 1 < event_frames.size() ? event_frames[k + 1] : static_cast<int>(frames.size());
      EXPECT_GE(next - event_frames[k], 20);
    }
  }
  EXPECT_NEAR(named, static_cast<int>(seeds.size()) / 2, static_cast<int>(seeds.size()) / 10);

  for (const uint32_t seed : {3u, 4u}) {
    const FamilyScene full = makeFamilyScene(seed, sim::ScenarioLength::kFull);
    EXPECT_GE(full.scenario.frames.size(), 120u);
    EXPECT_LE(full.scenario.frames.size(), 180u);
    EXPECT_EQ(core::toYaml(full.calibration), core::toYaml(makeFamilyScene(seed).calibration));
  }
}

// Truth: the geometric class wherever nothing but the static world is seen; struts black; robots,
// the ball and people only add black, orange and (off the carpet) unknown.
TEST(SceneFamily, TruthIsTheGeometricClassButForStrutsRobotsBallAndPeople) {
  int scenes = 0;
  for (uint32_t seed = sim::kTuningSeedsBegin; seed < sim::kTuningSeedsEnd && scenes < 2; ++seed) {
    const FamilyScene f = makeFamilyScene(seed);
    const sim::Scene& full = f.scenario.frames.back().scene;
    if (f.renderer.struts.empty() || full.people.empty() || f.calibration.camera.width > 640) continue;
    ++scenes;
    SCOPED_TRACE(f.summary);
    sim::Scene bare = full;
    bare.robots.clear();
    bare.ball.reset();
    bare.people.clear();
    sim::RendererOptions no_struts = f.renderer;
    no_struts.struts.clear();
    const sim::Renderer with(f.calibration, f.renderer), without(f.calibration, no_struts);
    const sim::LabeledFrame lf_full = with.render(full), lf_bare = without.render(bare);
    const core::ExpectedClassModel& model = without.model();
    const core::PoseTransform pose(full.robot_pose);
    const core::CameraCalibration& c = f.calibration.camera;
    size_t mismatches = 0, strut_pixels = 0, strut_not_black = 0, bad_changes = 0, changes = 0;
    for (size_t i = 0; i < model.pixels(); ++i) {
      const uint8_t geometric = model.geometricClass(i, pose);
      mismatches += lf_bare.labels.data[i] != geometric;
      if (geometric == core::kNotImaged) continue;
      const double du = static_cast<double>(i % c.width) - c.center_u;
      const double dv = static_cast<double>(i / c.width) - c.center_v;
      const double r = std::hypot(du, dv);
      bool in_strut = false;
      for (const sim::Strut& s : f.renderer.struts) {
        in_strut |= r >= s.inner_radius_px && r <= s.outer_radius_px &&
                    std::abs(std::remainder(std::atan2(dv, du) - s.bearing_rad, 2 * M_PI)) <= s.half_width_rad;
      }
      const uint8_t label = lf_full.labels.data[i];
      if (in_strut) {
        ++strut_pixels;
        strut_not_black += label != core::kBlack;
      } else if (label != lf_bare.labels.data[i]) {
        ++changes;
        const bool ok = label == core::kBlack || label == core::kOrange ||
                        (label == core::kUnknown && lf_bare.labels.data[i] == core::kUnknown);
        bad_changes += !ok;
      }
    }
    EXPECT_EQ(mismatches, 0u);
    EXPECT_GT(strut_pixels, 50u);
    EXPECT_EQ(strut_not_black, 0u);
    EXPECT_GT(changes, 0u) << "robots are seen";
    EXPECT_EQ(bad_changes, 0u);
  }
  EXPECT_EQ(scenes, 2);
}

// Coverage of the first 20 report seeds (looked at, not tuned on).
TEST(SceneFamily, TheReportSeedsCoverTheFamily) {
  std::set<std::string> sizes, kinds, profiles;
  std::set<int> signs;
  std::set<bool> struts;
  for (uint32_t seed = sim::kReportSeedsBegin; seed < sim::kReportSeedsBegin + 20; ++seed) {
    const FamilyScene f = makeFamilyScene(seed);
    const double pixels = static_cast<double>(f.calibration.camera.width) * f.calibration.camera.height;
    sizes.insert(pixels <= 580.0 * 580.0 ? "small" : pixels <= 800.0 * 600.0 ? "medium" : "large");
    signs.insert(f.calibration.camera.bearing_sign);
    struts.insert(!f.renderer.struts.empty());
    for (const auto& frame : f.scenario.frames) {
      for (const std::string& e : frame.events) kinds.insert(sim::familyEventKind(e));
    }
    for (const char* p : {"tan", "hyperbolic", "polynomial", "piecewise"}) {
      if (f.summary.find(std::string(" ") + p + " mirror") != std::string::npos) profiles.insert(p);
    }
  }
  EXPECT_EQ(sizes.size(), 3u);
  EXPECT_EQ(signs.size(), 2u);
  EXPECT_EQ(struts.size(), 2u);
  EXPECT_EQ(profiles.size(), 4u);
  for (const std::string& kind : sim::familyEventKinds())
    EXPECT_EQ(kinds.count(kind), kind == "local" ? 0u : 1u) << kind;
}

// LightEvents::kLocal: the same scenes with each sudden change made local. Everything else is the
// global scene's; the light changes on one side of a line across the field and not on the other.
TEST(SceneFamily, LocalChangesLightOnePartAndLeaveTheRestOfTheScene) {
  int local_events = 0;
  for (uint32_t seed = 0; seed < 10; ++seed) {
    const FamilyScene global = makeFamilyScene(seed);
    const FamilyScene local = makeFamilyScene(seed, sim::ScenarioLength::kSmall, true, sim::LightEvents::kLocal);
    EXPECT_EQ(global.calibration.camera.width, local.calibration.camera.width);
    ASSERT_EQ(global.scenario.frames.size(), local.scenario.frames.size()) << seed;
    for (size_t i = 0; i < global.scenario.frames.size(); ++i) {
      const auto& g = global.scenario.frames[i];
      const auto& l = local.scenario.frames[i];
      EXPECT_DOUBLE_EQ(g.scene.robot_pose.x_m, l.scene.robot_pose.x_m);
      EXPECT_DOUBLE_EQ(g.told_pose.theta_rad, l.told_pose.theta_rad);
      ASSERT_EQ(g.events.size(), l.events.size());
      for (size_t k = 0; k < g.events.size(); ++k) {
        const bool sudden = sim::isNamedToneChange(g.events[k]) || sim::familyEventKind(g.events[k]) == "tone";
        EXPECT_EQ(sim::familyEventKind(l.events[k]), sudden ? "local" : g.events[k]) << l.events[k];
        local_events += sudden;
      }
      // No global tone change; one zone per local change so far, on everything in it.
      EXPECT_TRUE(l.scene.lighting.transfer.isIdentity());
      const size_t added = l.scene.lighting.shadows.size() - g.scene.lighting.shadows.size();
      size_t so_far = 0;
      for (size_t j = 0; j <= i; ++j) {
        for (const std::string& e : local.scenario.frames[j].events) so_far += sim::familyEventKind(e) == "local";
      }
      EXPECT_EQ(added, so_far);
      for (size_t z = g.scene.lighting.shadows.size(); z < l.scene.lighting.shadows.size(); ++z) {
        const sim::Shadow& zone = l.scene.lighting.shadows[z];
        EXPECT_FALSE(zone.floor_only);
        EXPECT_TRUE((zone.factor >= 0.25 && zone.factor <= 0.6) || (zone.factor >= 1.4 && zone.factor <= 1.8));
        // The line crosses the field: some of the field lies on each side.
        const core::FieldCalibration& f = local.calibration.field;
        const bool x_line = zone.y_min_m < -100 && zone.y_max_m > 100;
        const double line = x_line ? (zone.x_min_m > -100 ? zone.x_min_m : zone.x_max_m)
                                   : (zone.y_min_m > -100 ? zone.y_min_m : zone.y_max_m);
        EXPECT_LT(std::abs(line), 0.31 * (x_line ? f.length_m : f.width_m));
      }
    }
  }
  EXPECT_GE(local_events, 5);
}

}  // namespace
}  // namespace act_color
