// act_real_eval as a team runs it on its own camera: an image of its field in a folder, the field
// from its calibration file and the robot's rough pose; the report of every change of light and
// a picture of the image classified before the changes and after each.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "act_color/core/calibration.hpp"
#include "act_color/sim/real_image_suite.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scene_family.hpp"
#include "tool_test_util.hpp"

namespace core = act_color::core;
namespace sim = act_color::sim;

namespace {

std::string tempDir() { return act_color_tool_test::tempDir("act_real_eval_test"); }

act_color_tool_test::ToolRun run(const std::string& arguments) {
  return act_color_tool_test::runTool("act_real_eval", arguments, tempDir());
}

}  // namespace

TEST(ActRealEval, RunsOnAnImageOfYourFieldWithYourCalibration) {
  // A simulated camera and field (11 x 7.7 m: not a preset) stand in for the team's.
  const sim::FamilyScene scene = sim::makeFamilyScene(1002u, sim::ScenarioLength::kSmall, /*ball_looks=*/false);
  cv::Mat bgr;
  cv::cvtColor(sim::Renderer(scene.calibration, scene.renderer).render(scene.scenario.frames.front().scene).rgb, bgr,
               cv::COLOR_RGB2BGR);
  const std::string robots = tempDir() + "/robots";
  const std::string folder = robots + "/our_robot", field = robots + "/our_field.yaml";
  const std::string png = tempDir() + "/png/made";  // --png makes it
  ASSERT_EQ(mkdir(robots.c_str(), 0755), 0);
  ASSERT_EQ(mkdir(folder.c_str(), 0755), 0);
  ASSERT_TRUE(cv::imwrite(folder + "/pic_save0.png", bgr));
  ASSERT_TRUE(cv::imwrite(folder + "/at_the_corner.png", bgr));
  std::ofstream(field) << core::toYaml(scene.calibration);
  const core::Pose2D pose = scene.scenario.frames.front().scene.robot_pose;
  // Rough, as a team knows it: 0.2 m off.
  const std::string pose_arg =
      std::to_string(pose.x_m + 0.2) + "," + std::to_string(pose.y_m) + "," + std::to_string(pose.theta_rad);
  // The folder's own setup (act_real_eval.args) over the command line's: another image, the field
  // file beside it, the pose and the height; --dir finds the folder by it.
  std::ofstream(folder + "/act_real_eval.args")
      << "# our robot at the corner\n--image at_the_corner.png --field ../our_field.yaml\n--pose " << pose_arg
      << "\n--height-m " << scene.calibration.camera.height_m << "\n";
  const act_color_tool_test::ToolRun r = run("--dir " + robots + " --preset lab6x4 --pose 0,0,0 --png " + png);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("our_robot/at_the_corner.png: "), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("not fitted"), std::string::npos) << r.output;
  for (const std::string& variant : sim::realImageVariants()) {
    EXPECT_NE(r.output.find("| " + variant + " | defaults | - | - | "), std::string::npos) << variant << r.output;
    EXPECT_NE(r.output.find("| " + variant + " | paper | "), std::string::npos) << variant;
    const cv::Mat shown = cv::imread(png + "/our_robot_at_the_corner_" + variant + ".png");
    EXPECT_EQ(shown.cols, 2 * bgr.cols) << variant;  // the image beside its classes
    EXPECT_EQ(shown.rows, bgr.rows) << variant;
  }
  EXPECT_FALSE(cv::imread(png + "/our_robot_at_the_corner_classified.png").empty());
  ASSERT_EQ(std::remove((folder + "/act_real_eval.args").c_str()), 0);

  // The calibration file act_calibrate wrote for the camera (here: the truth), the robot where it is.
  const std::string exact =
      std::to_string(pose.x_m) + "," + std::to_string(pose.y_m) + "," + std::to_string(pose.theta_rad);
  const act_color_tool_test::ToolRun given = run(folder + " --calibration " + field + " --pose " + exact);
  ASSERT_EQ(given.exit_code, 0) << given.output;
  EXPECT_NE(given.output.find("our_robot/pic_save0.png: the calibration given, residual 0.0"), std::string::npos)
      << given.output;
  EXPECT_NE(given.output.find("| darken | defaults | - | - | "), std::string::npos) << given.output;
}

TEST(ActRealEval, RefusesWhatItCannotUse) {
  const std::string folder = tempDir() + "/refused";
  ASSERT_EQ(mkdir(folder.c_str(), 0755), 0);
  cv::imwrite(folder + "/pic_save0.png", cv::Mat(480, 480, CV_8UC3, cv::Scalar::all(128)));
  EXPECT_EQ(run(folder + " --preset lab6x4 --field " + folder + "/none.yaml").exit_code, 2);  // both
  EXPECT_EQ(run(folder + " --field " + folder + "/none.yaml").exit_code, 2);                  // no file
  EXPECT_EQ(run(folder + " --pose 1,2").exit_code, 2);
  EXPECT_EQ(run(folder + " --height-m -1").exit_code, 2);
  EXPECT_EQ(run(folder + " --bogus").exit_code, 2);
  EXPECT_EQ(run(tempDir() + "/no_such_folder").exit_code, 1);
  // A folder's setup file with what is no folder option, or two fields: refused, naming the file.
  const std::string long_comment = "#" + std::string(5000, 'x');
  for (const std::string& setup :
       {std::string("--png /tmp"), std::string("--pose 1,2"), std::string("--preset lab6x4 --preset msl2007"),
        std::string("--image"), long_comment}) {
    std::ofstream(folder + "/act_real_eval.args") << setup << "\n";
    const act_color_tool_test::ToolRun r = run(folder);
    EXPECT_EQ(r.exit_code, 1) << setup;
    EXPECT_NE(r.output.find("refused/act_real_eval.args: "), std::string::npos) << setup << r.output;
  }
  std::remove((folder + "/act_real_eval.args").c_str());
  // A calibration comes with its field and camera height.
  const std::string cal = tempDir() + "/other_camera.yaml";
  core::Calibration other = sim::makeFamilyScene(1003u, sim::ScenarioLength::kSmall, false).calibration;
  other.camera.width = 640;  // another image size than the folder's
  std::ofstream(cal) << core::toYaml(other);
  EXPECT_EQ(run(folder + " --calibration " + cal + " --preset lab6x4").exit_code, 2);
  EXPECT_EQ(run(folder + " --calibration " + cal + " --height-m 0.7").exit_code, 2);
  const act_color_tool_test::ToolRun sized = run(folder + " --calibration " + cal);
  EXPECT_EQ(sized.exit_code, 0) << sized.output;
  EXPECT_NE(sized.output.find("not fitted (the image is 480x480, the calibration is for 640x"), std::string::npos)
      << sized.output;
  // A grey image has no field to fit: said so, no figures.
  const act_color_tool_test::ToolRun grey = run(folder);
  EXPECT_EQ(grey.exit_code, 0) << grey.output;
  EXPECT_NE(grey.output.find("refused/pic_save0.png: not fitted"), std::string::npos) << grey.output;
}
