// Issue 12, item 4: ACT on real images of real cameras (test/data/real, NuBot's lab field): the
// calibration fitted to each image, then ACT from it at the fitted pose and under five changes of
// light. Checked here is what holds today on the two images with hand-picked line pixels that the
// calibrator fits; README ("Real images") has every image and figure, the paper beside.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>

#include "act_color/sim/real_image_suite.hpp"
#include "sim_test_util.hpp"

namespace act_color {
namespace {

sim::RealImageResult run(const std::string& folder) {
  sim::RealImage image;
  image.name = folder;
  const std::string dir = sim_test::sourcePath("test/data/real/" + folder);
  image.bgr = cv::imread(dir + "/pic_save0.png", cv::IMREAD_COLOR);
  image.whites = core::readNubotWhites(dir + "/whites.txt");
  image.field = core::fieldPreset("lab6x4");
  sim::BallMark ball;
  if (sim::readBallMark(dir + "/ball.txt", &ball)) image.ball = ball;
  EXPECT_FALSE(image.bgr.empty());
  EXPECT_GT(image.whites.size(), 1000u);
  return sim::evaluateRealImage(image, {{"defaults", core::ActParams()}});
}

void expectHolds(const sim::RealImageResult& r) {
  ASSERT_TRUE(r.fitted) << r.why;
  EXPECT_LT(r.fit.residual.median_m, 0.05);
  // The team's hand-picked line pixels lie on the fitted model's lines (measured 0.99 on nubot_1
  // and 1.00 on nubot_1_bak_bak), and the report says so without a warning.
  EXPECT_GE(r.whites_on_lines, 0.9);
  ASSERT_EQ(r.rows.size(), sim::realImageVariants().size());
  const std::string report = sim::formatRealImageReport({r});
  std::printf("%s", report.c_str());
  EXPECT_NE(report.find("% within 0.08 m of the model's lines)"), std::string::npos) << report;
  EXPECT_EQ(report.find("another image"), std::string::npos) << report;
  // Pixels picked on another image (nubot_2014's whites.txt beside its pic_save0): warned of.
  sim::RealImageResult other = r;
  other.whites_on_lines = 0.12;
  EXPECT_NE(sim::formatRealImageReport({other}).find("(12% within 0.08 m of the model's lines: picked on another "
                                                     "image or another field?)"),
            std::string::npos);
  for (const auto& row : r.rows) {
    // Before the change: the issue's targets.
    EXPECT_GE(row.before.white_recall, 0.50) << row.variant;
    EXPECT_GE(row.before.green_recall, 0.88) << row.variant;
    EXPECT_LE(row.before.hall_in_field, 0.15) << row.variant;
    // Nor does black take the hall (a robot's class, counted apart; measured 0.12 on nubot_1 and
    // 0.08 on nubot_1_bak_bak, 0.10 and 0.04 before robots_train_black's carpet spread).
    EXPECT_LE(row.before.hall_as_black, 0.15) << row.variant;
    // Nor do the goals, after any change (outside the goals' own regions): since their colors go
    // by the majority of the evidence (kMajorityEvidenceRatio) at most 0.06 on nubot_1_bak_bak and
    // 0.05 on nubot_1; at the lines' ratio of 3, 0.12 on nubot_1_bak_bak after the darkening.
    if (row.mode == "defaults") {
      EXPECT_LE(row.after.hall_as_goal, 0.08) << row.variant;
      // Nor green and white after it, the 1.5x brightening's saturated walls too (issue 12's 0.15;
      // since ActParams::carpet_edge at most 0.11 on nubot_1_bak_bak and 0.05 on nubot_1).
      EXPECT_LE(row.after.hall_in_field, 0.15) << row.variant;
    }
    // The look at the image after the change (act_real_eval --png): the last frame and its labels.
    ASSERT_EQ(row.frame_last.size(), row.labels_last.size()) << row.variant;
    ASSERT_EQ(row.labels_last.type(), CV_8UC1) << row.variant;
    EXPECT_GT(cv::countNonZero(row.labels_last == core::kGreen), row.labels_last.total() / 10) << row.variant;
    // After it: white and green are not lost (the issue's 0.50 for white).
    EXPECT_GE(row.after.white_recall, 0.50) << row.variant;
    EXPECT_GE(row.after.green_recall, 0.80) << row.variant;
  }
}

// Issue 13's 0.80 for the ball marked in ball.txt: recall, precision and the share of frames with
// the ball reported inside the mark, before each change and after it.
void expectBallMeetsIssue13(const sim::RealImageResult& r) {
  ASSERT_TRUE(r.fitted) << r.why;
  ASSERT_EQ(r.rows.size(), sim::realImageVariants().size());
  for (const auto& row : r.rows) {
    EXPECT_GE(row.before.ball_recall, 0.80) << row.variant;
    EXPECT_GE(row.before.ball_precision, 0.80) << row.variant;
    EXPECT_GE(row.before.ball_seen, 0.80) << row.variant;
    EXPECT_GE(row.after.ball_recall, 0.80) << row.variant;
    EXPECT_GE(row.after.ball_precision, 0.80) << row.variant;
    EXPECT_GE(row.after.ball_seen, 0.80) << row.variant;
  }
}

// formatRealImageTargets on hand-made results: what counts as meeting issue 12's targets.
sim::RealVariantResult change(const std::string& variant, const std::string& mode, double white_before,
                              double white_after, double green_after, double hall_after, int back) {
  sim::RealVariantResult v;
  v.variant = variant;
  v.mode = mode;
  v.before.white_recall = white_before;
  v.after.white_recall = white_after;
  v.before.green_recall = 0.95;
  v.after.green_recall = green_after;
  v.before.hall_in_field = 0.05;
  v.after.hall_in_field = hall_after;
  v.white_recovery_cycles = back;
  return v;
}

TEST(RealImageTargets, CountsEachTargetAndNamesTheMisses) {
  sim::RealImageResult a;
  a.name = "cam_a";
  a.fitted = true;
  a.rows = {change("gain_0.5", "defaults", 0.80, 0.78, 0.90, 0.10, 3),     // meets all
            change("gain_0.5", "paper", 0.60, 0.40, 0.90, 0.10, -1),       // white after, never back
            change("darken", "defaults", 0.80, 0.80, 0.87, 0.10, 12),      // green after; 12 cycles is in time
            change("darken", "paper", 0.80, 0.80, 0.90, 0.16, 13),         // hall after, back too late
            change("wrong_pose", "defaults", 0.10, 0.10, 0.10, 0.90, -1),  // not a change of light
            change("wrong_pose", "paper", 0.10, 0.10, 0.10, 0.90, -1)};
  sim::RealImageResult b;  // no hand-picked pixels: white and its recovery are not measured
  b.name = "cam_b";
  b.fitted = true;
  b.rows = {change("brighten", "defaults", -1, -1, 0.95, 0.20, -1)};
  sim::RealImageResult c;
  c.name = "cam_c";
  c.why = "no fit";
  const std::string text = sim::formatRealImageTargets({a, b, c});
  auto has = [&](const std::string& part) { EXPECT_NE(text.find(part), std::string::npos) << part << "\n" << text; };
  // | image | mode | white | green | hall | white back | all |
  has("| cam_a | defaults | 2/2 | 1/2 | 2/2 | 2/2 | 1/2 |");
  has("| cam_a | paper | 1/2 | 2/2 | 1/2 | 0/2 | 0/2 |");
  has("| cam_b | defaults | - | 1/1 | 0/1 | - | 0/1 |");
  has("| all images | defaults | 2/2 | 2/3 | 2/3 | 2/2 | 1/3 |");
  has("| all images | paper | 1/2 | 2/2 | 1/2 | 0/2 | 0/2 |");
  has("defaults, the changes that miss (2):\n- cam_a, darken: green 0.95 / 0.87\n- cam_b, brighten: hall 0.05 / "
      "0.20\n");
  has("paper, the changes that miss (2):\n- cam_a, gain_0.5: white 0.60 / 0.40, white never back\n"
      "- cam_a, darken: hall 0.05 / 0.16, white back in 13\n");
  const size_t heading = text.find("(not wrong_pose)");  // named only where the heading leaves it out
  ASSERT_NE(heading, std::string::npos);
  EXPECT_EQ(text.find("wrong_pose", heading + 5 + 1), std::string::npos);
  EXPECT_EQ(text.find("cam_c"), std::string::npos);
  EXPECT_EQ(sim::formatRealImageTargets({c}), "");
}

TEST(RealImages, Nubot1) {
  const sim::RealImageResult r = run("nubot_1");
  expectHolds(r);
  // act_real_eval --frames: per variant a title and a line of every frame's figure per measure.
  std::istringstream frames(sim::formatRealImageFrames({r}));
  std::string line;
  int series = 0;
  while (std::getline(frames, line)) {
    if (line.rfind("  ", 0) != 0) continue;
    ++series;
    std::istringstream values(line.substr(line.find(':') + 1));
    std::string value;
    int count = 0;
    while (values >> value) {
      ++count;
      if (line.find("white") != std::string::npos) {
        EXPECT_NE(value, "-") << line;
      }
    }
    EXPECT_EQ(count, sim::kRealFramesBefore + sim::kRealFramesAfter) << line;
  }
  EXPECT_EQ(series, 5 * static_cast<int>(r.rows.size()));  // white, green, hall, black, goal
  // The least share of the hall any fixed table classifies white while half the hand-picked line
  // pixels are white, and green while 88% of the carpet is (core::RecallCost; measured white 0.01
  // before each change, 0.18 after the 1.5x brightening, whose saturated line cores share a cell
  // with the hall's saturated walls; green 0.00 before each change).
  for (const auto& row : r.rows) {
    EXPECT_LT(row.table_hall_as_white_before, 0.05) << row.variant;
    EXPECT_GE(row.table_hall_as_green_before, 0.0) << row.variant;
    EXPECT_LT(row.table_hall_as_green_before, 0.05) << row.variant;
    if (row.variant == "brighten") {
      EXPECT_GT(row.table_hall_as_white_after, 0.15);
    }
    // The same at ACT's own recalls (the defaults' white and green): the least hall figure any one
    // table gives over those frames (measured 0.01-0.03 before each change, 0.20 after the
    // brightening: issue 12's 0.15 is out of any fixed table's reach there, and the table alone gave
    // 0.23 at white recall 0.86). The labels are more than the table: white beyond the carpet's edge
    // is unknown (ActParams::carpet_edge), and after the brightening they show 0.04 of the hall.
    ASSERT_GE(row.table_hall_as_white_at_mode_after, 0.0) << row.variant;
    ASSERT_GE(row.table_hall_as_green_at_mode_after, 0.0) << row.variant;
    const double bound_after = row.table_hall_as_white_at_mode_after + row.table_hall_as_green_at_mode_after;
    if (row.variant == "brighten") {
      EXPECT_GT(bound_after, 0.15);
      EXPECT_LT(row.after.hall_in_field, 0.10);
    }
  }
}

TEST(RealImages, Nubot1BakBak) {
  const sim::RealImageResult r = run("nubot_1_bak_bak");
  expectHolds(r);
  // Issue 13 on a real camera: the yellow ball (marked by eye, ball.txt) is learned from the start
  // image alone, reported where it is, and found again after every change, by the issue's 0.80
  // (measured in the session of 2026-12-06 from 16:58: recall 0.95, precision 0.99, seen in 9 of
  // the last 10 frames before the changes, seeded in the 12th; after them recall 0.94-0.98,
  // precision 0.99-1.00, seen in all 10. Before the labelled image and the one-ball rule: 0.61 and
  // 0.90 before; after the paper's darkening recall 0.04 and never seen, before the ball's colors
  // moved with the light, then 0.69).
  expectBallMeetsIssue13(r);
}

TEST(RealImages, Nubot2Ball) {
  // Issue 13 on another image (480x480, another calibration folder): its yellow ball (ball.txt) is
  // learned from the start image and found again after every change, by the issue's 0.80 (measured
  // recall 0.96 and precision 0.98 before the changes, 0.85-0.98 and 0.95-1.00 after; seen in 9 of
  // the 10 frames before and all 10 after).
  expectBallMeetsIssue13(run("nubot_2"));
}

}  // namespace
}  // namespace act_color
