#include "act_color/sim/real_image_suite.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "act_color/core/expected_class_model.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/core/self_mask_learner.hpp"
#include "act_color/core/table_ceiling.hpp"
#include "act_color/sim/scenario.hpp"
#include "act_color/sim/tone_curve.hpp"

namespace act_color {
namespace sim {
namespace {

ToneCurve variantCurve(const std::string& name) {
  if (name == "wrong_pose") return ToneCurve();  // the light stays; the pose changes
  if (name == "gain_0.5") return ToneCurve::gain(Eigen::Vector3d::Constant(0.5));
  if (name == "darken") return ToneCurve::brightnessContrast(0.5, 0.5);  // the paper's darkening
  if (name == "gamma_1.6") return ToneCurve::gamma(1.6);
  if (name == "warm_white_balance") return ToneCurve::whiteBalance(-2000.0);
  return ToneCurve::gain(Eigen::Vector3d::Constant(1.5));  // "brighten"
}

// Sensor noise of a real camera, fresh in every frame: Gaussian, 2 DN.
constexpr double kNoiseDn = 2.0;
// Pixels this close to another expected class do not count for green recall or for the hall.
constexpr int kMarginPx = 3;
// Frames the "before" and "after" figures are averaged over.
constexpr int kAveragedFrames = 10;
// The real-image targets (issue 12's "Checked by", first set in issue 6): the "any fixed table" rows
// and formatRealImageTargets.
constexpr double kTargetWhiteRecall = 0.50, kTargetGreenRecall = 0.88, kTargetHallInField = 0.15;
constexpr int kTargetWhiteBackCycles = 12;

// Pixels expected `k` whose (2 kMarginPx + 1)^2 neighbourhood is all expected `k`.
std::vector<int> interiorPixels(const cv::Mat& expected, uint8_t k, int step) {
  cv::Mat is_k = expected == k;
  cv::erode(is_k, is_k, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * kMarginPx + 1, 2 * kMarginPx + 1)));
  std::vector<int> out;
  for (int v = 0; v < is_k.rows; v += step) {
    for (int u = 0; u < is_k.cols; u += step) {
      if (is_k.at<uint8_t>(v, u)) out.push_back(v * is_k.cols + u);
    }
  }
  return out;
}

}  // namespace

const std::vector<std::string>& realImageVariants() {
  static const std::vector<std::string> names = {"gain_0.5",           "darken",   "gamma_1.6",
                                                 "warm_white_balance", "brighten", "wrong_pose"};
  return names;
}

std::vector<uint8_t> readNubotTable(const std::string& path) {
  std::vector<uint8_t> table(64 * 64 * 64);
  std::ifstream in(path, std::ios::binary);
  if (!in.read(reinterpret_cast<char*>(table.data()), static_cast<std::streamsize>(table.size()))) return {};
  if (in.peek() != std::ifstream::traits_type::eof()) return {};
  return table;
}

RealImageResult evaluateRealImage(const RealImage& image,
                                  const std::vector<std::pair<std::string, core::ActParams>>& modes, uint32_t seed) {
  RealImageResult result;
  result.name = image.name;
  // The fit, or the calibration given measured on the image, and the hand-picked pixels measured.
  const core::MirrorCalibrator calibrator(image.calibration ? image.calibration->field : image.field, image.calibrator);
  if (image.calibration) {
    const core::CameraCalibration& camera = image.calibration->camera;
    if (image.bgr.cols != camera.width || image.bgr.rows != camera.height) {
      result.why = "the image is " + std::to_string(image.bgr.cols) + "x" + std::to_string(image.bgr.rows) +
                   ", the calibration is for " + std::to_string(camera.width) + "x" + std::to_string(camera.height);
      return result;
    }
    // The calibration as given, measured on the image's line pixels as act_calibrate --check does.
    result.fit.calibration = *image.calibration;
    result.fit.pose = image.calibrator.pose;
    result.fit.profile = "given";
    result.fit.line_pixels = calibrator.findLinePixels(image.bgr, core::imageGeometryOf(camera));
    result.fit.residual = calibrator.residual(camera, result.fit.pose, result.fit.line_pixels);
    result.fitted = true;
  } else {
    try {
      result.fit = calibrator.fit(image.bgr);
      result.fitted = true;
    } catch (const std::exception& e) {
      result.why = e.what();
      return result;
    }
  }
  core::Calibration cal = result.fit.calibration;
  const core::Pose2D pose = result.fit.pose;
  // The hand-picked line pixels measured as act_calibrate --whites measures them: picked on another
  // image (nubot_2014's are pic_save2's), few lie on the model's lines, and white recall on them
  // means nothing.
  if (!image.whites.empty()) {
    result.whites_on_lines = calibrator.residual(cal.camera, pose, image.whites).inlier_fraction;
  }
  // The paper's wrong pose (3.2): 2.5 m away, towards the field's centre along its length, and
  // rotated by 165 degrees.
  const core::Pose2D wrong_pose = wrongPose(pose, pose.x_m >= 0 ? M_PI : 0.0);
  cv::Mat rgb;
  cv::cvtColor(image.bgr, rgb, cv::COLOR_BGR2RGB);
  // The own robot's parts (item 3) from this one image: ACT's start-up table at the fitted pose,
  // then the pixels that show neither carpet nor line where the pose expects one, in the shape of
  // a strut or touching the chassis. They train nothing and are left out of the figures. A given
  // calibration's own mask is kept.
  if (cal.camera.self_mask.empty()) {
    core::ActTrainer trainer(cal);
    const core::ImageView view = core::ImageView::fromMat(rgb, core::PixelFormat::kRgb8);
    trainer.bootstrap(view, pose, core::kDefaultBootstrapCycles);
    core::SelfMaskLearner learner(cal);
    learner.add(view, pose, trainer.lut());
    cal.camera.self_mask = learner.mask();
    cal.camera.self_mask_file = "self_mask.png";
  }
  result.self_mask = cal.camera.self_mask;
  // Expected classes at the fitted pose (without eq. 1: the geometry alone).
  const core::ExpectedClassModel model(cal);
  const core::PoseTransform transform(pose);
  cv::Mat expected(rgb.rows, rgb.cols, CV_8UC1);
  for (int v = 0; v < rgb.rows; ++v) {
    for (int u = 0; u < rgb.cols; ++u) {
      expected.at<uint8_t>(v, u) = model.geometricClass(static_cast<size_t>(v) * rgb.cols + u, transform);
    }
  }
  // Green recall inside the field proper (within the outer lines: the margin's width is not known
  // for a lab field, and there the carpet may end before the model's does).
  cv::Mat field_carpet = expected.clone();
  const core::FieldCalibration& f = cal.field;
  for (int v = 0; v < rgb.rows; ++v) {
    for (int u = 0; u < rgb.cols; ++u) {
      const core::PixelRay& ray = model.camera().ray(u, v);
      if (field_carpet.at<uint8_t>(v, u) != core::kGreen || ray.region != core::PixelRegion::kFloor) continue;
      double fx, fy;
      transform.apply(ray.ground_x_m, ray.ground_y_m, &fx, &fy);
      if (std::abs(fx) > f.length_m / 2 || std::abs(fy) > f.width_m / 2)
        field_carpet.at<uint8_t>(v, u) = core::kUnknown;
    }
  }
  const std::vector<int> carpet = interiorPixels(field_carpet, core::kGreen, 2);
  const std::vector<int> hall = interiorPixels(expected, core::kUnknown, 2);
  std::vector<cv::Point> whites;  // inside the image, as pixel indices
  for (const cv::Point2f& p : image.whites) {
    const cv::Point q(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)));
    if (q.x >= 0 && q.y >= 0 && q.x < rgb.cols && q.y < rgb.rows) whites.push_back(q);
  }
  result.whites = whites.size();

  // NuBot's fixed table: green of the carpet and of the hall (its only field class) on an image.
  constexpr uint8_t kNubotGreen = 2, kNubotBlack = 1;
  auto nubotClass = [&](const cv::Mat& image_rgb, int index) {
    const cv::Vec3b c = image_rgb.at<cv::Vec3b>(index / image_rgb.cols, index % image_rgb.cols);
    return image.nubot_table[(c[2] / 4) * 4096 + (c[1] / 4) * 64 + c[0] / 4];
  };
  auto nubotFigures = [&](const cv::Mat& image_rgb) {
    RealFrameFigures fig{-1, -1, -1};
    if (image.nubot_table.empty()) return fig;
    size_t green = 0, in_field = 0;
    for (const int i : carpet) green += nubotClass(image_rgb, i) == kNubotGreen;
    for (const int i : hall) in_field += nubotClass(image_rgb, i) == kNubotGreen;
    fig.green_recall = carpet.empty() ? 0.0 : static_cast<double>(green) / carpet.size();
    fig.hall_in_field = hall.empty() ? 0.0 : static_cast<double>(in_field) / hall.size();
    return fig;
  };

  const core::Segmenter segmenter(cal.camera);
  for (const std::string& variant : realImageVariants()) {
    const ToneCurve curve = variantCurve(variant);
    cv::Mat changed = rgb.clone();
    curve.apply(changed);
    const RealFrameFigures nubot_before = nubotFigures(rgb), nubot_after = nubotFigures(changed);
    // The frames (their noise too) are the same in every mode: the bound is taken in the first.
    core::RecallCost white_before, white_after, green_before, green_after;
    for (const auto& [mode_name, params] : modes) {
      const bool first_mode = &mode_name == &modes.front().first;
      core::ActTrainer trainer(cal, params);
      cv::RNG rng(seed);
      std::vector<RealFrameFigures> figures;
      cv::Mat frame_last, labels_last, labels;
      for (int f = 0; f < kRealFramesBefore + kRealFramesAfter; ++f) {
        cv::Mat frame = (f < kRealFramesBefore ? rgb : changed).clone();
        cv::Mat noise(frame.size(), CV_16SC3);
        rng.fill(noise, cv::RNG::NORMAL, 0.0, kNoiseDn);
        cv::Mat noisy;
        frame.convertTo(noisy, CV_16SC3);
        noisy += noise;
        noisy.convertTo(frame, CV_8UC3);  // saturates
        const core::ImageView view = core::ImageView::fromMat(frame, core::PixelFormat::kRgb8);
        const bool averaged = f >= kRealFramesBefore - kAveragedFrames && f < kRealFramesBefore;
        if (first_mode && (averaged || f >= kRealFramesAfter + kRealFramesBefore - kAveragedFrames)) {
          core::RecallCost& white = averaged ? white_before : white_after;
          core::RecallCost& green = averaged ? green_before : green_after;
          auto color = [&](int i) { return frame.ptr<uint8_t>(i / frame.cols) + 3 * (i % frame.cols); };
          for (const cv::Point& p : whites) white.addWanted(color(p.y * frame.cols + p.x));
          for (const int i : carpet) green.addWanted(color(i));
          for (const int i : hall) {
            white.addUnwanted(color(i));
            green.addUnwanted(color(i));
          }
        }
        if (f == 0) trainer.bootstrap(view, pose, core::kDefaultBootstrapCycles - 1);
        const bool pose_wrong =
            variant == "wrong_pose" && f >= kRealFramesBefore && f < kRealFramesBefore + kRealWrongPoseFrames;
        const core::CycleStats stats = trainer.cycle(view, pose_wrong ? wrong_pose : pose);
        const core::ColorLut& lut = trainer.lut();
        // The labels as the segmentation gives them: the table's, white and black beyond the
        // carpet's edge unknown (ActParams::carpet_edge), and the ball's image where the cycle saw
        // it (below). The figures read the table, but a color the carpet's edge took out counts as
        // unknown.
        segmenter.classify(lut, view, labels);
        trainer.unlabelBeyondCarpet(labels);
        auto classOf = [&](int index) {
          const cv::Vec3b c = frame.at<cv::Vec3b>(index / frame.cols, index % frame.cols);
          const uint8_t k = lut.classOf(c[0], c[1], c[2]);
          const bool taken_out =
              (k == core::kWhite || k == core::kBlack) && labels.ptr<uint8_t>()[index] == core::kUnknown;
          return taken_out ? uint8_t{core::kUnknown} : k;
        };
        RealFrameFigures fig;
        if (!whites.empty()) {
          size_t white = 0;
          for (const cv::Point& p : whites) white += classOf(p.y * frame.cols + p.x) == core::kWhite;
          fig.white_recall = static_cast<double>(white) / whites.size();
        }
        size_t green = 0, in_field = 0, black = 0, goal = 0;
        for (const int i : carpet) green += classOf(i) == core::kGreen;
        for (const int i : hall) {
          const uint8_t k = classOf(i);
          in_field += k == core::kGreen || k == core::kWhite;
          black += k == core::kBlack;
          goal += k == core::kYellow || k == core::kBlue;
        }
        fig.green_recall = carpet.empty() ? 0.0 : static_cast<double>(green) / carpet.size();
        fig.hall_in_field = hall.empty() ? 0.0 : static_cast<double>(in_field) / hall.size();
        fig.hall_as_black = hall.empty() ? 0.0 : static_cast<double>(black) / hall.size();
        fig.hall_as_goal = hall.empty() ? 0.0 : static_cast<double>(goal) / hall.size();
        trainer.labelBall(stats, labels);  // the ball's figures, and the pictures
        if (image.ball) {
          size_t inside = 0, inside_ball = 0, predicted = 0, predicted_near = 0;
          for (int i = 0; i < frame.rows * frame.cols; ++i) {
            const int u = i % frame.cols, v = i / frame.cols;
            if (expected.at<uint8_t>(v, u) == core::kNotImaged) continue;
            const bool ball = labels.at<uint8_t>(v, u) == core::kOrange;
            if (image.ball->contains(u, v, -2.0)) {
              ++inside;
              inside_ball += ball;
            }
            if (ball) {
              ++predicted;
              predicted_near += image.ball->contains(u, v, 3.0);
            }
          }
          fig.ball_recall = inside ? static_cast<double>(inside_ball) / inside : 0.0;
          fig.ball_precision = predicted ? static_cast<double>(predicted_near) / predicted : -1.0;
          fig.ball_seen = stats.ball.seen && image.ball->contains(stats.ball.u, stats.ball.v, 3.0) ? 1.0 : 0.0;
        }
        figures.push_back(fig);
        if (first_mode && f == kRealFramesBefore + kRealFramesAfter - 1) {
          frame_last = frame.clone();
          labels_last = labels.clone();
        }
        if (result.labels_before.empty() && f == kRealFramesBefore - 1) {
          result.frame_before = frame.clone();
          result.labels_before = labels.clone();
          if (!image.nubot_table.empty()) {
            size_t imaged = 0, green = 0, black = 0;
            for (int i = 0; i < frame.rows * frame.cols; ++i) {
              if (expected.at<uint8_t>(i / frame.cols, i % frame.cols) == core::kNotImaged) continue;
              const uint8_t ours = result.labels_before.at<uint8_t>(i / frame.cols, i % frame.cols);
              const uint8_t theirs = nubotClass(frame, i);
              ++imaged;
              green += (ours == core::kGreen) == (theirs == kNubotGreen);
              black += (ours == core::kBlack) == (theirs == kNubotBlack);
            }
            result.nubot_green_agreement = imaged ? static_cast<double>(green) / imaged : 0.0;
            result.nubot_black_agreement = imaged ? static_cast<double>(black) / imaged : 0.0;
          }
        }
      }
      auto mean = [&](int first, int count) {
        RealFrameFigures m;
        m.white_recall = 0;
        for (int f = first; f < first + count; ++f) {
          m.white_recall += figures[f].white_recall;
          m.green_recall += figures[f].green_recall;
          m.hall_in_field += figures[f].hall_in_field;
          m.hall_as_black += figures[f].hall_as_black;
          m.hall_as_goal += figures[f].hall_as_goal;
        }
        m.white_recall /= count;
        m.green_recall /= count;
        m.hall_in_field /= count;
        m.hall_as_black /= count;
        m.hall_as_goal /= count;
        if (whites.empty()) m.white_recall = -1;
        if (image.ball) {
          // Precision over the frames with ball pixels.
          double recall = 0, precision = 0, seen = 0;
          int with_pixels = 0;
          for (int f = first; f < first + count; ++f) {
            recall += figures[f].ball_recall;
            seen += figures[f].ball_seen;
            if (figures[f].ball_precision >= 0) {
              precision += figures[f].ball_precision;
              ++with_pixels;
            }
          }
          m.ball_recall = recall / count;
          m.ball_seen = seen / count;
          m.ball_precision = with_pixels ? precision / with_pixels : -1.0;
        }
        return m;
      };
      RealVariantResult row;
      row.variant = variant;
      row.mode = mode_name;
      row.before = mean(kRealFramesBefore - kAveragedFrames, kAveragedFrames);
      row.after = mean(kRealFramesBefore + kRealFramesAfter - kAveragedFrames, kAveragedFrames);
      if (!whites.empty()) {
        int last_below = -1;
        for (int f = kRealFramesBefore; f < kRealFramesBefore + kRealFramesAfter; ++f) {
          if (figures[f].white_recall < row.before.white_recall - 0.05) last_below = f - kRealFramesBefore;
        }
        const int cycles = last_below + 2;  // the first frame of the change is cycle 1
        row.white_recovery_cycles = last_below == kRealFramesAfter - 1 ? -1 : cycles;
      }
      row.frames = figures;
      row.frame_last = frame_last;
      row.labels_last = labels_last;
      row.nubot_before = nubot_before;
      row.nubot_after = nubot_after;
      row.table_hall_as_white_before = white_before.leastUnwantedShare(kTargetWhiteRecall);
      row.table_hall_as_white_after = white_after.leastUnwantedShare(kTargetWhiteRecall);
      row.table_hall_as_green_before = green_before.leastUnwantedShare(kTargetGreenRecall);
      row.table_hall_as_green_after = green_after.leastUnwantedShare(kTargetGreenRecall);
      if (first_mode) {
        if (!whites.empty()) {
          row.table_hall_as_white_at_mode_before = white_before.leastUnwantedShare(row.before.white_recall);
          row.table_hall_as_white_at_mode_after = white_after.leastUnwantedShare(row.after.white_recall);
        }
        row.table_hall_as_green_at_mode_before = green_before.leastUnwantedShare(row.before.green_recall);
        row.table_hall_as_green_at_mode_after = green_after.leastUnwantedShare(row.after.green_recall);
      }
      result.rows.push_back(row);
    }
  }
  return result;
}

bool BallMark::contains(double x, double y, double grow_px) const {
  const double c = std::cos(angle_deg * M_PI / 180.0), s = std::sin(angle_deg * M_PI / 180.0);
  const double du = x - u, dv = y - v;
  const double p = (c * du + s * dv) / std::max(0.5, a + grow_px), q = (-s * du + c * dv) / std::max(0.5, b + grow_px);
  return p * p + q * q <= 1.0;
}

bool readBallMark(const std::string& path, BallMark* mark) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    BallMark m;
    if (!(fields >> m.u >> m.v >> m.a >> m.b >> m.angle_deg) || !(m.a > 0) || !(m.b > 0)) return false;
    *mark = m;
    return true;
  }
  return false;
}

namespace {

// Below this fraction of the hand-picked pixels on the model's lines the report warns that they may
// be of another image (the calibrator holds 0.85-1.00 of the team's pixels on the images they were
// picked on).
constexpr double kWhitesOnLinesWarning = 0.5;

// ", 94% within 0.08 m of the model's lines", with a warning when few are: they may be another
// image's.
std::string whitesOnLines(const RealImageResult& r) {
  if (r.whites_on_lines < 0) return "";
  char text[160];
  std::snprintf(text, sizeof(text), " (%.0f%% within 0.08 m of the model's lines%s)", 100.0 * r.whites_on_lines,
                r.whites_on_lines < kWhitesOnLinesWarning ? ": picked on another image or another field?" : "");
  return text;
}

}  // namespace

std::string formatRealImageReport(const std::vector<RealImageResult>& results) {
  std::ostringstream out;
  char line[512];
  for (const RealImageResult& r : results) {
    if (!r.fitted) {
      out << r.name << ": not fitted (" << r.why << ")\n\n";
      continue;
    }
    const core::CameraCalibration& camera = r.fit.calibration.camera;
    std::string fitted = r.fit.profile == "given" ? "the calibration given" : r.fit.profile + " profile";
    if (camera.tiltRad() > 0) {
      std::snprintf(line, sizeof(line), " tilted %.1f deg", camera.tiltRad() * 180 / M_PI);
      fitted += line;
    }
    std::snprintf(line, sizeof(line),
                  "%s: %s, residual %.3f m, pose (%.2f, %.2f, %.1f deg), %zu hand-picked white pixels%s, "
                  "self mask %.1f%% of the image\n\n",
                  r.name.c_str(), fitted.c_str(), r.fit.residual.median_m, r.fit.pose.x_m, r.fit.pose.y_m,
                  r.fit.pose.theta_rad * 180.0 / M_PI, r.whites, whitesOnLines(r).c_str(),
                  r.self_mask.empty() ? 0.0
                                      : 100.0 * std::count(r.self_mask.begin(), r.self_mask.end(), uint8_t{1}) /
                                            static_cast<double>(r.self_mask.size()));
    out << line;
    if (r.nubot_green_agreement >= 0) {
      std::snprintf(line, sizeof(line),
                    "NuBot's hand-made table (CTableBGR.dat): agrees with ACT's on green in %.0f%% and on black in "
                    "%.0f%% of the imaged pixels (defaults, last frame before the change)\n\n",
                    100.0 * r.nubot_green_agreement, 100.0 * r.nubot_black_agreement);
      out << line;
    }
    out << "| variant | mode | white before / after | white back in | green before / after | hall in a field class "
           "before / after | hall as black before / after | hall as a goal before / after |\n"
           "|---|---|---|---|---|---|---|---|\n";
    for (size_t n = 0; n < r.rows.size(); ++n) {
      const RealVariantResult& row = r.rows[n];
      // A row of any fixed table's least hall at the white and green recalls given (before, after):
      // each class's least share of the hall; their sum bounds the hall in a field class from below
      // (a cell holds one class). Without hand-picked white pixels (white share -1) green alone.
      using Pair = std::pair<double, double>;
      auto boundRow = [&](const std::string& label, Pair white_recall, Pair green_recall, Pair white_hall,
                          Pair green_hall) {
        const bool with_white = white_hall.first >= 0;
        char parts[96] = "least; green", white_col[48] = "-";
        if (with_white) {
          std::snprintf(parts, sizeof(parts), "least; white %.2f / %.2f, green %.2f / %.2f", white_hall.first,
                        white_hall.second, green_hall.first, green_hall.second);
          std::snprintf(white_col, sizeof(white_col), "%.2f / %.2f", white_recall.first, white_recall.second);
        }
        std::snprintf(line, sizeof(line), "| %s | %s | %s | - | %.2f / %.2f | %.2f / %.2f (%s) | - | - |\n",
                      row.variant.c_str(), label.c_str(), white_col, green_recall.first, green_recall.second,
                      green_hall.first + std::max(0.0, white_hall.first),
                      green_hall.second + std::max(0.0, white_hall.second), parts);
        out << line;
      };
      char white[64], back[32];
      if (row.before.white_recall < 0) {
        std::snprintf(white, sizeof(white), "-");
        std::snprintf(back, sizeof(back), "-");
      } else {
        std::snprintf(white, sizeof(white), "%.2f / %.2f", row.before.white_recall, row.after.white_recall);
        if (row.white_recovery_cycles < 0) {
          std::snprintf(back, sizeof(back), "never");
        } else {
          std::snprintf(back, sizeof(back), "%d", row.white_recovery_cycles);
        }
      }
      std::snprintf(line, sizeof(line),
                    "| %s | %s | %s | %s | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f |\n",
                    row.variant.c_str(), row.mode.c_str(), white, back, row.before.green_recall, row.after.green_recall,
                    row.before.hall_in_field, row.after.hall_in_field, row.before.hall_as_black,
                    row.after.hall_as_black, row.before.hall_as_goal, row.after.hall_as_goal);
      out << line;
      const bool last_of_variant = n + 1 == r.rows.size() || r.rows[n + 1].variant != row.variant;
      if (last_of_variant && row.nubot_before.green_recall >= 0) {
        std::snprintf(line, sizeof(line),
                      "| %s | NuBot's table | - | - | %.2f / %.2f | %.2f / %.2f (green) | - | - |\n",
                      row.variant.c_str(), row.nubot_before.green_recall, row.nubot_after.green_recall,
                      row.nubot_before.hall_in_field, row.nubot_after.hall_in_field);
        out << line;
      }
      if (last_of_variant && row.table_hall_as_green_before >= 0) {
        boundRow("any fixed table", {kTargetWhiteRecall, kTargetWhiteRecall}, {kTargetGreenRecall, kTargetGreenRecall},
                 {row.table_hall_as_white_before, row.table_hall_as_white_after},
                 {row.table_hall_as_green_before, row.table_hall_as_green_after});
      }
      // The same bound at the first mode's own recalls: how much of its hall figure a fixed table
      // could avoid without losing white or green.
      const RealVariantResult* first = &row;
      while (first != r.rows.data() && (first - 1)->variant == row.variant) --first;
      if (last_of_variant && first->table_hall_as_green_at_mode_before >= 0) {
        boundRow("any fixed table at the recalls of " + first->mode,
                 {first->before.white_recall, first->after.white_recall},
                 {first->before.green_recall, first->after.green_recall},
                 {first->table_hall_as_white_at_mode_before, first->table_hall_as_white_at_mode_after},
                 {first->table_hall_as_green_at_mode_before, first->table_hall_as_green_at_mode_after});
      }
    }
    out << "\n";
    if (!r.rows.empty() && r.rows.front().before.ball_recall >= 0) {
      out << "The ball marked by eye (ball.txt; issue 13), means over the last 10 frames before the change "
             "(frames 11-20) and of the sequence (51-60):\n\n"
             "| variant | mode | ball recall before / after | precision before / after | seen before / after |\n"
             "|---|---|---|---|---|\n";
      auto share = [](double v) {
        char b[16];
        std::snprintf(b, sizeof(b), v < 0 ? "-" : "%.2f", v);  // -: no pixel classified as the ball
        return std::string(b);
      };
      for (const RealVariantResult& row : r.rows) {
        std::snprintf(line, sizeof(line), "| %s | %s | %.2f / %.2f | %s / %s | %.2f / %.2f |\n", row.variant.c_str(),
                      row.mode.c_str(), row.before.ball_recall, row.after.ball_recall,
                      share(row.before.ball_precision).c_str(), share(row.after.ball_precision).c_str(),
                      row.before.ball_seen, row.after.ball_seen);
        out << line;
      }
      out << "\n";
    }
  }
  return out.str();
}

std::string formatRealImageTargets(const std::vector<RealImageResult>& results) {
  // Per image and mode, of its changes of light: how many meet white, green, hall, white back, all.
  struct Tally {
    std::array<int, 5> met{};
    int changes = 0, with_white = 0;
    void add(const Tally& t) {
      for (size_t k = 0; k < met.size(); ++k) met[k] += t.met[k];
      changes += t.changes;
      with_white += t.with_white;
    }
  };
  auto row = [](const std::string& image, const std::string& mode, const Tally& t) {
    auto cell = [](int met, int of) {
      return of == 0 ? std::string("-") : std::to_string(met) + "/" + std::to_string(of);
    };
    return "| " + image + " | " + mode + " | " + cell(t.met[0], t.with_white) + " | " + cell(t.met[1], t.changes) +
           " | " + cell(t.met[2], t.changes) + " | " + cell(t.met[3], t.with_white) + " | " +
           cell(t.met[4], t.changes) + " |\n";
  };
  auto figures = [](const char* what, double before, double after) {
    char text[64];
    std::snprintf(text, sizeof(text), "%s %.2f / %.2f", what, before, after);
    return std::string(text);
  };
  std::vector<std::string> modes;  // in the order they first appear
  std::map<std::string, Tally> totals;
  std::map<std::string, std::vector<std::string>> misses;
  std::string rows;
  for (const RealImageResult& r : results) {
    if (!r.fitted) continue;
    std::map<std::string, Tally> tallies;
    for (const RealVariantResult& v : r.rows) {
      if (v.variant == "wrong_pose") continue;
      if (std::find(modes.begin(), modes.end(), v.mode) == modes.end()) modes.push_back(v.mode);
      const bool white = v.before.white_recall >= 0;
      const std::array<bool, 4> ok = {
          !white || std::min(v.before.white_recall, v.after.white_recall) >= kTargetWhiteRecall,
          std::min(v.before.green_recall, v.after.green_recall) >= kTargetGreenRecall,
          std::max(v.before.hall_in_field, v.after.hall_in_field) <= kTargetHallInField,
          !white || (v.white_recovery_cycles >= 0 && v.white_recovery_cycles <= kTargetWhiteBackCycles)};
      const bool all = ok[0] && ok[1] && ok[2] && ok[3];
      Tally& t = tallies[v.mode];
      ++t.changes;
      t.with_white += white;
      t.met[0] += white && ok[0];
      t.met[1] += ok[1];
      t.met[2] += ok[2];
      t.met[3] += white && ok[3];
      t.met[4] += all;
      if (all) continue;
      std::vector<std::string> why;
      if (!ok[0]) why.push_back(figures("white", v.before.white_recall, v.after.white_recall));
      if (!ok[1]) why.push_back(figures("green", v.before.green_recall, v.after.green_recall));
      if (!ok[2]) why.push_back(figures("hall", v.before.hall_in_field, v.after.hall_in_field));
      if (!ok[3]) {
        why.push_back(v.white_recovery_cycles < 0 ? "white never back"
                                                  : "white back in " + std::to_string(v.white_recovery_cycles));
      }
      std::string miss = r.name + ", " + v.variant + ": ";
      for (size_t n = 0; n < why.size(); ++n) miss += (n == 0 ? "" : ", ") + why[n];
      misses[v.mode].push_back(miss);
    }
    for (const std::string& mode : modes) {
      const auto it = tallies.find(mode);
      if (it == tallies.end()) continue;
      rows += row(r.name, mode, it->second);
      totals[mode].add(it->second);
    }
  }
  if (modes.empty()) return "";
  std::ostringstream out;
  char line[512];
  std::snprintf(line, sizeof(line),
                "Issue 12's targets on each change of light (not wrong_pose): white recall >= %.2f on the hand-picked "
                "pixels, green >= %.2f, hall in a field class <= %.2f, before and after; white back within %d "
                "cycles. Changes that meet them:\n\n",
                kTargetWhiteRecall, kTargetGreenRecall, kTargetHallInField, kTargetWhiteBackCycles);
  out << line << "| image | mode | white | green | hall | white back | all |\n|---|---|---|---|---|---|---|\n" << rows;
  for (const std::string& mode : modes) out << row("all images", mode, totals[mode]);
  out << "\n";
  for (const std::string& mode : modes) {
    if (misses[mode].empty()) continue;
    out << mode << ", the changes that miss (" << misses[mode].size() << "):\n";
    for (const std::string& miss : misses[mode]) out << "- " << miss << "\n";
    out << "\n";
  }
  return out.str();
}

std::string formatRealImageFrames(const std::vector<RealImageResult>& results) {
  std::ostringstream out;
  auto series = [&](const char* what, const std::vector<RealFrameFigures>& frames, double RealFrameFigures::*field) {
    out << "  " << what << ":";
    for (const RealFrameFigures& f : frames) {
      if (f.*field < 0) {
        out << " -";
      } else {
        out << " " << static_cast<int>(std::lround(100.0 * (f.*field)));
      }
    }
    out << "\n";
  };
  for (const RealImageResult& r : results) {
    for (const RealVariantResult& row : r.rows) {
      out << r.name << " " << row.variant << " " << row.mode << " (change from frame " << kRealFramesBefore + 1
          << ")\n";
      series("white", row.frames, &RealFrameFigures::white_recall);
      series("green", row.frames, &RealFrameFigures::green_recall);
      series("hall ", row.frames, &RealFrameFigures::hall_in_field);
      series("black", row.frames, &RealFrameFigures::hall_as_black);
      series("goal ", row.frames, &RealFrameFigures::hall_as_goal);
    }
  }
  return out.str();
}

}  // namespace sim
}  // namespace act_color
