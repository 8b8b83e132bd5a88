// Issue 12, item 3: the pixels that show the own robot (mirror struts) are learned from frames
// with poses, kept as the calibration's self mask (a PNG beside it), and train nothing.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <string>
#include <vector>

#include "act_color/core/act_trainer.hpp"
#include "act_color/core/expected_class_model.hpp"
#include "act_color/core/omni_camera_model.hpp"
#include "act_color/core/self_mask_learner.hpp"
#include "act_color/sim/family_evaluation.hpp"
#include "act_color/sim/scene_family.hpp"
#include "sim_test_util.hpp"

namespace act_color {
namespace {

// Pixels the renderer draws as struts (core::kNotImaged and the chassis left out).
std::vector<uint8_t> strutPixels(const sim::FamilyScene& scene) {
  const auto& cam = scene.calibration.camera;
  const core::OmniCameraModel model(cam);
  std::vector<uint8_t> truth(static_cast<size_t>(cam.width) * cam.height, 0);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const auto region = model.ray(u, v).region;
      if (region == core::PixelRegion::kNotImaged || region == core::PixelRegion::kChassis) continue;
      const double r = std::hypot(u - cam.center_u, v - cam.center_v);
      const double b = std::atan2(v - cam.center_v, u - cam.center_u);
      for (const auto& s : scene.renderer.struts) {
        if (std::abs(std::remainder(b - s.bearing_rad, 2 * M_PI)) <= s.half_width_rad && r >= s.inner_radius_px &&
            r <= s.outer_radius_px) {
          truth[static_cast<size_t>(v) * cam.width + u] = 1;
        }
      }
    }
  }
  return truth;
}

// ACT over the scene's frames, every frame also given to the learner.
std::vector<uint8_t> learn(const sim::FamilyScene& scene, int* frames_counted) {
  const sim::Renderer renderer(scene.calibration, scene.renderer);
  core::ActTrainer trainer(scene.calibration);
  core::SelfMaskLearner learner(scene.calibration);
  for (size_t i = 0; i < scene.scenario.frames.size(); ++i) {
    const sim::LabeledFrame frame = renderer.render(scene.scenario.frames[i].scene);
    const auto view = core::ImageView::fromMat(frame.rgb, core::PixelFormat::kRgb8);
    const core::Pose2D& pose = scene.scenario.frames[i].told_pose;
    if (i == 0) trainer.bootstrap(view, pose, core::kDefaultBootstrapCycles - 1);
    trainer.cycle(view, pose);
    learner.add(view, pose, trainer.lut());
  }
  *frames_counted = learner.frames();
  return learner.mask();
}

struct Coverage {
  double struts = 0;  // fraction of the strut pixels masked
  double others = 0;  // fraction of the other imaged pixels masked
};

Coverage coverage(const sim::FamilyScene& scene, const std::vector<uint8_t>& mask) {
  const auto truth = strutPixels(scene);
  const core::OmniCameraModel model(scene.calibration.camera);
  double struts = 0, struts_masked = 0, others = 0, others_masked = 0;
  for (size_t i = 0; i < truth.size(); ++i) {
    if (model.ray(i).region == core::PixelRegion::kNotImaged) continue;
    if (truth[i]) {
      ++struts;
      struts_masked += mask[i];
    } else {
      ++others;
      others_masked += mask[i];
    }
  }
  return {struts > 0 ? struts_masked / struts : 0.0, others_masked / others};
}

// The pixels a mask keeps from training: the mask and its 8-neighbours (PixelRegion::kSelf).
std::vector<uint8_t> trainsNothing(const sim::FamilyScene& scene, const std::vector<uint8_t>& mask) {
  core::CameraCalibration camera = scene.calibration.camera;
  camera.self_mask = mask;
  const core::OmniCameraModel model(camera);
  std::vector<uint8_t> out(mask.size(), 0);
  for (size_t i = 0; i < out.size(); ++i) out[i] = model.ray(i).region == core::PixelRegion::kSelf;
  return out;
}

TEST(SelfMask, TheStrutsOfADrivingRobotAreLearnedAndNothingElse) {
  // Tuning seed 0: 4 struts, two robots and two people, static and then driving.
  const sim::FamilyScene scene = sim::makeFamilyScene(0);
  ASSERT_EQ(scene.renderer.struts.size(), 4u);
  int frames = 0;
  const auto mask = learn(scene, &frames);
  const Coverage c = coverage(scene, mask), kept = coverage(scene, trainsNothing(scene, mask));
  std::printf("4 struts, %d poses: %.2f of the strut pixels masked (%.2f with their edges), %.4f of the others\n",
              frames, c.struts, kept.struts, c.others);
  EXPECT_GE(frames, 4);
  // Where a strut crosses the hall nothing is expected, and too few poses tell the pixels that keep
  // their color: about half of the strut pixels lie over the field.
  EXPECT_GT(kept.struts, 0.40);
  EXPECT_LT(c.others, 0.01);
  EXPECT_LT(kept.others, 0.01);  // the struts' blurred edges (one pixel all round)
}

TEST(SelfMask, ABallLyingOnTheFieldIsNotTheRobotsFromOneImage) {
  // One image of tuning seed 0 (4 struts), with a ball and its shadow painted on the carpet between
  // two struts: 40 px along the radius (longer than the strut rule's run) and 16 px across. From one
  // pose shape alone cannot tell it from a strut, but carpet is expected all round it, while a
  // strut runs on into the hall (the real image nubot_3_new: its ball was masked and never trained).
  const sim::FamilyScene scene = sim::makeFamilyScene(0);
  const auto& cam = scene.calibration.camera;
  const sim::Renderer renderer(scene.calibration, scene.renderer);
  const sim::ScenarioFrame& f = scene.scenario.frames.front();
  cv::Mat rgb = renderer.render(f.scene).rgb.clone();
  const double bearing = scene.renderer.struts[0].bearing_rad + M_PI / 4;  // between two struts
  const double r0 = cam.chassis_radius_px + 0.35 * (cam.mirror_radius_px - cam.chassis_radius_px);
  const core::ExpectedClassModel model(scene.calibration);
  const core::PoseTransform transform(f.told_pose);
  std::vector<size_t> ball;
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const double du = u - cam.center_u, dv = v - cam.center_v;
      const double along = du * std::cos(bearing) + dv * std::sin(bearing) - r0;
      const double across = -du * std::sin(bearing) + dv * std::cos(bearing);
      if (std::abs(along) > 20 || std::abs(across) > 8) continue;
      const size_t i = static_cast<size_t>(v) * cam.width + u;
      const uint8_t expected = model.geometricClass(i, transform);
      ASSERT_TRUE(expected == core::kGreen || expected == core::kWhite) << "the ball must lie on the field";
      rgb.at<cv::Vec3b>(v, u) = along < 0 ? cv::Vec3b(230, 200, 40) : cv::Vec3b(60, 60, 30);  // ball, shadow
      ball.push_back(i);
    }
  }
  const auto view = core::ImageView::fromMat(rgb, core::PixelFormat::kRgb8);
  core::ActTrainer trainer(scene.calibration);
  trainer.bootstrap(view, f.told_pose, core::kDefaultBootstrapCycles);
  core::SelfMaskLearner learner(scene.calibration);
  learner.add(view, f.told_pose, trainer.lut());
  const auto mask = learner.mask();
  size_t masked = 0;
  for (const size_t i : ball) masked += mask[i];
  EXPECT_EQ(masked, 0u) << "of " << ball.size() << " ball pixels";
  const Coverage kept = coverage(scene, trainsNothing(scene, mask));
  std::printf("one image: %.2f of the strut pixels kept from training, %.4f of the others\n", kept.struts, kept.others);
  EXPECT_GT(kept.struts, 0.40);
}

TEST(SelfMask, ADriveFollowsTheStrutsOverTheHall) {
  // Tuning seed 27: four bright metal struts from the chassis out over the hall. Over the field
  // they show neither carpet nor line; over the hall nothing is expected, but from pose to pose
  // they keep their color while the hall's pixels change.
  const sim::FamilyScene scene = sim::makeFamilyScene(27);
  ASSERT_EQ(scene.renderer.struts.size(), 4u);
  const auto mask = sim::learnSelfMaskOnDrive(scene, sim::kDrivePoses);
  const Coverage drive = coverage(scene, mask), kept = coverage(scene, trainsNothing(scene, mask));
  const Coverage few = coverage(
      scene, trainsNothing(scene, sim::learnSelfMaskOnDrive(scene, core::SelfMaskLearner::kMinPosesForConstancy - 1)));
  std::printf("%d poses: %.2f of the strut pixels masked (%.2f with their edges), %.4f of the others; %d poses: %.2f\n",
              sim::kDrivePoses, drive.struts, kept.struts, drive.others,
              core::SelfMaskLearner::kMinPosesForConstancy - 1, few.struts);
  EXPECT_GT(drive.struts, 0.65);
  EXPECT_GT(kept.struts, 0.90);
  EXPECT_LT(drive.others, 0.001);  // labelled black: the struts' pixels only
  // Too few poses to tell constant pixels: the parts over the field only.
  EXPECT_LT(few.struts, 0.75);
}

TEST(SelfMask, StrutsOverTheHallOnlyAreLearnedFromADrive) {
  // Tuning seed 34: four struts that start beyond the carpet's edge, so nothing is ever expected
  // at their pixels. Over a drive they keep their color while the hall's pixels change, and they
  // are narrow across the radius, where a wall of one color is not.
  const sim::FamilyScene scene = sim::makeFamilyScene(34);
  ASSERT_EQ(scene.renderer.struts.size(), 4u);
  const Coverage c = coverage(scene, sim::learnSelfMaskOnDrive(scene, sim::kDrivePoses));
  std::printf("%d poses: %.2f of the strut pixels masked, %.4f of the others\n", sim::kDrivePoses, c.struts, c.others);
  EXPECT_GT(c.struts, 0.90);
  EXPECT_LT(c.others, 0.001);
  // A drive that never turns cannot tell them from a pole far to the side: nothing is learned.
  const Coverage straight = coverage(scene, sim::learnSelfMaskOnDrive(scene, sim::kDrivePoses, false));
  EXPECT_EQ(straight.struts, 0.0);
}

TEST(SelfMask, TheMaskIsHandedOverFromTheEighthPoseOnWhenItChanged) {
  // Tuning seed 27's drive (four struts over field and hall), as the trainer's ~learn_self_mask and
  // act_replay --learn-self-mask use it: a mask to use from kMinPosesForConstancy poses on, again
  // only when it changed, and a team's own mask in the calibration kept in it.
  const sim::FamilyScene scene = sim::makeFamilyScene(27);
  core::Calibration calibration = scene.calibration;
  const auto& cam = calibration.camera;
  const size_t pixels = static_cast<size_t>(cam.width) * cam.height;
  calibration.camera.self_mask.assign(pixels, 0);
  // A pixel a team masked by hand, halfway between the chassis and the mirror's rim.
  const auto team_v = static_cast<size_t>(cam.center_v + 0.5 * (cam.chassis_radius_px + cam.mirror_radius_px));
  const size_t team_pixel = team_v * cam.width + static_cast<size_t>(cam.center_u);
  calibration.camera.self_mask[team_pixel] = 1;
  calibration.camera.self_mask_file = "team.png";
  const sim::Renderer renderer(calibration, scene.renderer);
  core::ActTrainer trainer(calibration);
  core::SelfMaskLearner learner(calibration);
  core::SelfMaskHandOver hand_over(calibration);
  sim::Scene drive = scene.scenario.frames.front().scene;
  const std::vector<core::Pose2D> poses = sim::drivePoses(scene, sim::kDrivePoses);
  ASSERT_EQ(poses.size(), static_cast<size_t>(sim::kDrivePoses));
  std::vector<int> handed_at;
  std::optional<core::Calibration> last;
  for (size_t k = 0; k < poses.size(); ++k) {
    drive.robot_pose = poses[k];
    drive.noise_seed = sim::kDriveNoiseSeed + static_cast<uint32_t>(k);
    const sim::LabeledFrame frame = renderer.render(drive);
    const auto view = core::ImageView::fromMat(frame.rgb, core::PixelFormat::kRgb8);
    if (k == 0) trainer.bootstrap(view, poses[k], core::kDefaultBootstrapCycles);
    trainer.cycle(view, poses[k]);
    learner.add(view, poses[k], trainer.lut());
    if (std::optional<core::Calibration> next = hand_over.next(learner)) {
      handed_at.push_back(learner.frames());
      last = std::move(next);
    }
    EXPECT_FALSE(hand_over.next(learner)) << "handed over twice for one pose";
  }
  std::printf("handed over at poses");
  for (const int p : handed_at) std::printf(" %d", p);
  std::printf(" of %d\n", learner.frames());
  ASSERT_FALSE(handed_at.empty());
  EXPECT_EQ(handed_at.front(), core::SelfMaskLearner::kMinPosesForConstancy);
  EXPECT_LT(handed_at.size(), static_cast<size_t>(learner.frames() - handed_at.front() + 1));  // not at every pose
  const std::vector<uint8_t>& used = last->camera.self_mask;
  ASSERT_EQ(used.size(), pixels);
  EXPECT_EQ(used[team_pixel], 1) << "the calibration's own mask is kept";
  EXPECT_TRUE(last->camera.self_mask_file.empty());
  EXPECT_EQ(hand_over.pixels(), static_cast<size_t>(std::count(used.begin(), used.end(), 1)));
  const Coverage c = coverage(scene, used);
  EXPECT_GT(c.struts, 0.65);
  EXPECT_LT(c.others, 0.001);
  // The trainer takes the model built with it; the struts then train nothing.
  trainer.replaceModel(core::ExpectedClassModel(*last));
  EXPECT_EQ(trainer.model().camera().calibration().self_mask, used);
}

TEST(SelfMask, NoStrutsNoMask) {
  // Tuning seed 17: no struts, a person and four robots, driving.
  const sim::FamilyScene scene = sim::makeFamilyScene(17);
  ASSERT_TRUE(scene.renderer.struts.empty());
  int frames = 0;
  const auto mask = learn(scene, &frames);
  // Robots standing at the field's edge are long along the radius in the image, like a strut, and
  // few poses do not tell them apart: some of their pixels are taken.
  EXPECT_LT(coverage(scene, mask).others, 0.01);
}

TEST(SelfMask, TheMaskIsSavedWithTheCalibrationAndTrainsNothing) {
  char pattern[] = "/tmp/act_self_mask_XXXXXX";
  const std::string dir = mkdtemp(pattern);
  core::Calibration cal = sim_test::defaultCalibration();
  auto& cam = cal.camera;
  cam.self_mask.assign(static_cast<size_t>(cam.width) * cam.height, 0);
  // A strut: a 6 px wide bar from the chassis to the rim, to the right of the centre.
  for (int u = static_cast<int>(cam.center_u) + 30; u < cam.width; ++u) {
    for (int dv = -3; dv < 3; ++dv) cam.self_mask[static_cast<size_t>(cam.center_v + dv) * cam.width + u] = 1;
  }
  cam.self_mask_file = "strut_mask.png";
  core::saveSelfMask(cam, dir + "/strut_mask.png");
  std::ofstream(dir + "/cal.yaml") << core::toYaml(cal);
  const core::Calibration loaded = core::loadCalibration(dir + "/cal.yaml");
  EXPECT_EQ(loaded.camera.self_mask_file, "strut_mask.png");
  EXPECT_EQ(loaded.camera.self_mask, cam.self_mask);
  EXPECT_EQ(core::toYaml(loaded), core::toYaml(cal));
  // Masked pixels train nothing and are never off the field.
  const core::ExpectedClassModel model(loaded);
  const core::PoseTransform pose(core::Pose2D{0.0, 0.0, 0.0});
  size_t masked = 0;
  for (size_t i = 0; i < loaded.camera.self_mask.size(); ++i) {
    if (!loaded.camera.self_mask[i] || model.camera().ray(i).region == core::PixelRegion::kNotImaged) continue;
    ++masked;
    EXPECT_EQ(model.camera().ray(i).region, core::PixelRegion::kSelf);
    EXPECT_EQ(model.geometricClass(i, pose), core::kNotImaged);
    EXPECT_FALSE(model.offField(i, pose));
  }
  EXPECT_GT(masked, 1000u);
  // A mask of another size, or one that is not there, is an error naming the key.
  cv::imwrite(dir + "/small.png", cv::Mat(10, 10, CV_8UC1, cv::Scalar(255)));
  auto errorOf = [&](const std::string& file) -> std::string {
    core::Calibration c = cal;
    c.camera.self_mask_file = file;
    std::ofstream(dir + "/bad.yaml") << core::toYaml(c);
    try {
      core::loadCalibration(dir + "/bad.yaml");
    } catch (const core::CalibrationError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(errorOf("small.png").find("camera.self_mask: '" + dir + "/small.png' is 10x10 px"), std::string::npos);
  EXPECT_NE(errorOf("missing.png").find("camera.self_mask: cannot open '" + dir + "/missing.png'"), std::string::npos)
      << errorOf("missing.png");
  for (const char* f : {"strut_mask.png", "small.png", "cal.yaml", "bad.yaml"}) std::remove((dir + "/" + f).c_str());
  rmdir(dir.c_str());
}

}  // namespace
}  // namespace act_color
