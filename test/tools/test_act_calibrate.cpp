// act_calibrate as a user runs it: a simulated field image fitted into a file that loads, images
// without a field refused (non-zero exit, nothing written), the NuBot import, the --family check.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "act_color/core/calibration.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scene_family.hpp"
#include "tool_test_util.hpp"

namespace core = act_color::core;
namespace sim = act_color::sim;

namespace {

std::string tempDir() { return act_color_tool_test::tempDir("act_calibrate_test"); }

using act_color_tool_test::ToolRun;
ToolRun run(const std::string& arguments) {
  return act_color_tool_test::runTool("act_calibrate", arguments, tempDir());
}

using act_color_tool_test::exists;

}  // namespace

TEST(ActCalibrate, FitsASimulatedImageIntoAFileThatLoads) {
  const sim::FamilyScene scene = sim::makeFamilyScene(1002u, sim::ScenarioLength::kSmall,
                                                      /*ball_looks=*/false);  // 480x480, quick to render and fit
  cv::Mat bgr;
  cv::cvtColor(sim::Renderer(scene.calibration, scene.renderer).render(scene.scenario.frames.front().scene).rgb, bgr,
               cv::COLOR_RGB2BGR);
  const std::string image = tempDir() + "/field.png", truth = tempDir() + "/truth.yaml";
  ASSERT_TRUE(cv::imwrite(image, bgr));
  std::ofstream(truth) << core::toYaml(scene.calibration);
  const core::Pose2D pose = scene.scenario.frames.front().scene.robot_pose;
  const std::string out = tempDir() + "/fitted.yaml", overlay = tempDir() + "/overlay.png";
  const ToolRun r =
      run("--image " + image + " --field " + truth + " --pose " + std::to_string(pose.x_m + 0.2) + "," +
          std::to_string(pose.y_m) + "," + std::to_string(pose.theta_rad) + " --bearing-sign " +
          std::to_string(scene.calibration.camera.bearing_sign) + " --output " + out + " --overlay " + overlay);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("residual: median"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("pose: "), std::string::npos) << r.output;
  core::Calibration fitted;
  ASSERT_NO_THROW(fitted = core::loadCalibration(out)) << r.output;
  EXPECT_EQ(fitted.camera.width, 480);
  EXPECT_NEAR(fitted.camera.center_u, scene.calibration.camera.center_u, 2.0);
  EXPECT_NEAR(fitted.camera.center_v, scene.calibration.camera.center_v, 2.0);
  EXPECT_EQ(fitted.field.length_m, scene.calibration.field.length_m);
  const cv::Mat shown = cv::imread(overlay);
  EXPECT_EQ(shown.cols, 480);
  // The calibration just written, checked against the same image, has the same residual.
  const ToolRun check = run("--check " + out + " --image " + image + " --pose " + std::to_string(pose.x_m) + "," +
                            std::to_string(pose.y_m) + "," + std::to_string(pose.theta_rad));
  EXPECT_EQ(check.exit_code, 0) << check.output;
  EXPECT_NE(check.output.find("line pixels found: median"), std::string::npos) << check.output;
}

TEST(ActCalibrate, RefusesImagesWithoutAField) {
  const std::string grey = tempDir() + "/grey.png", noise = tempDir() + "/noise.png";
  cv::imwrite(grey, cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(128)));
  cv::Mat random(480, 640, CV_8UC3);
  cv::randu(random, cv::Scalar::all(0), cv::Scalar::all(255));
  cv::imwrite(noise, random);
  for (const std::string& image : {grey, noise}) {
    const std::string out = tempDir() + "/refused.yaml";
    const ToolRun r = run("--image " + image + " --preset msl2007 --output " + out);
    EXPECT_EQ(r.exit_code, 1) << r.output;
    EXPECT_NE(r.output.find("nothing written"), std::string::npos) << r.output;
    EXPECT_FALSE(exists(out)) << image;
  }
  EXPECT_EQ(run("--image " + grey + " --preset nope").exit_code, 1);
  EXPECT_EQ(run("--bogus").exit_code, 2);
  EXPECT_EQ(run("--image " + grey).exit_code, 2);  // no field
}

TEST(ActCalibrate, ImportsANubotMirrorFit) {
  const std::string mirror = tempDir() + "/mirror_calib.xml", roi = tempDir() + "/ROI.xml";
  std::ofstream(mirror) << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<opencv_storage>\n"
                           "   <center_coloum>2.4088e+02</center_coloum>\n   <center_row>1.979e+02</center_row>\n"
                           "   <para_a>5.229</para_a>\n   <para_b>3.192e-03</para_b>\n</opencv_storage>\n";
  std::ofstream(roi) << "<?xml version=\"1.0\"?>\n<opencv_storage>\n<big_radius>194</big_radius>\n"
                        "<small_radius>32</small_radius>\n</opencv_storage>\n";
  const std::string out = tempDir() + "/nubot.yaml";
  const ToolRun r = run("--nubot " + mirror + " --roi " + roi + " --size 480x480 --preset lab6x4 --output " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  core::Calibration c;
  ASSERT_NO_THROW(c = core::loadCalibration(out));
  EXPECT_DOUBLE_EQ(c.camera.center_u, 240.88);
  EXPECT_DOUBLE_EQ(c.camera.mirror_radius_px, 194.0);
  EXPECT_EQ(c.field.length_m, 6.0);
  // A malformed value: the key is named, nothing is written.
  const std::string bad = tempDir() + "/bad.xml", bad_out = tempDir() + "/bad.yaml";
  std::ofstream(bad) << "<opencv_storage><center_coloum>240.9</center_coloum><center_row>1.9x</center_row>"
                        "<para_a>5.2</para_a><para_b>0.0032</para_b></opencv_storage>";
  const ToolRun b = run("--nubot " + bad + " --size 480x480 --preset lab6x4 --output " + bad_out);
  EXPECT_EQ(b.exit_code, 1);
  EXPECT_NE(b.output.find("center_row"), std::string::npos) << b.output;
  EXPECT_FALSE(exists(bad_out));
}

// A real camera on a full 18 x 12 m field, the robot 3 m from the halfway line and from the side
// line (NuBot's 2014 image, test/data/real/nubot_2014): fitted at that rough pose, the team's own
// hand-picked line pixels lie on the model's lines (issue 12: 90% within 0.08 m); at the default
// pose, the centre spot, it is refused.
TEST(ActCalibrate, FitsARealCameraAwayFromTheCentreSpot) {
  const std::string dir = std::string(ACT_SOURCE_DIR) + "/test/data/real/nubot_2014";
  const std::string image = " --image " + dir + "/pic_save2.png --whites " + dir + "/whites.txt";
  const std::string out = tempDir() + "/nubot_2014.yaml";
  const ToolRun r = run(image + " --preset msl2007 --pose 3,-3,0 --output " + out);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string whites = "whites " + dir + "/whites.txt: median ";
  const size_t at = r.output.find(whites);
  ASSERT_NE(at, std::string::npos) << r.output;
  const std::string inliers = "inliers (<= 0.08 m) ";
  const size_t fraction = r.output.find(inliers, at);
  ASSERT_NE(fraction, std::string::npos) << r.output;
  EXPECT_GE(std::stod(r.output.substr(fraction + inliers.size())), 0.90) << r.output;
  EXPECT_NO_THROW(core::loadCalibration(out));
  const ToolRun centre = run(image + " --preset msl2007 --output " + tempDir() + "/centre.yaml");
  EXPECT_NE(centre.exit_code, 0) << centre.output;
  EXPECT_FALSE(exists(tempDir() + "/centre.yaml"));
}

// --family: the calibrator on the simulator's cameras against their truth; one table row per seed
// and a count (seed 1003 is one of the cameras it fits within the targets).
TEST(ActCalibrate, ChecksItselfOnTheSimulatorsCameras) {
  const ToolRun r = run("--family 1003-1003");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("| 1003 | within the targets |"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("1 of 1 cameras within the targets"), std::string::npos) << r.output;
  EXPECT_EQ(run("--family 5-3").exit_code, 2);
  EXPECT_EQ(run("--family x").exit_code, 2);
  EXPECT_EQ(run("--family 1-2 --preset lab6x4").exit_code, 2);
}
