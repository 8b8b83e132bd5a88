#include "act_color/sim/family_evaluation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

#include "act_color/core/segmenter.hpp"
#include "act_color/core/self_mask_learner.hpp"
#include "act_color/core/table_ceiling.hpp"
#include "act_color/sim/renderer.hpp"

namespace act_color {
namespace sim {
namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// input | each mode's labels | truth, in the palette, as BGR for imwrite.
void writePanel(const std::string& path, const cv::Mat& rgb, const std::vector<cv::Mat>& labels, const cv::Mat& truth) {
  std::vector<cv::Mat> panels{rgb.clone()};
  for (const cv::Mat& l : labels) {
    cv::Mat colored;
    core::colorizeLabels(l, colored);
    panels.push_back(colored);
  }
  cv::Mat colored_truth;
  core::colorizeLabels(truth, colored_truth);
  panels.push_back(colored_truth);
  cv::Mat row;
  cv::hconcat(panels, row);
  cv::cvtColor(row, row, cv::COLOR_RGB2BGR);
  if (!cv::imwrite(path, row)) throw std::runtime_error(path + ": cannot be written");
}

// Segments that start with a sudden change of light, global or local (settle cycles are measured
// after those; a slow ramp, an exposure swing, a wrong pose or driving change what the frames show
// all along).
bool startsWithSuddenChange(const std::string& event) {
  size_t begin = 0;
  while (begin <= event.size()) {
    const size_t end = std::min(event.find('+', begin), event.size());
    const std::string part = event.substr(begin, end - begin);
    if (isSuddenChange(part)) return true;
    begin = end + 1;
  }
  return false;
}

// Cycles class k took to settle in a segment, as the report counts them: only after a sudden change
// of light and for a class the segment shows (else -1); the segment's length when never settled.
int settleCycles(const core::SegmentSummary& ss, int k) {
  if (ss.first_frame == 0 || !startsWithSuddenChange(ss.event) || std::isnan(ss.final_recall[k])) return -1;
  return ss.settle_cycles[k] < 0 ? static_cast<int>(ss.frames) : ss.settle_cycles[k];
}

// The same for the cycles until recall first comes within the tolerance (reach_cycles).
int reachCycles(const core::SegmentSummary& ss, int k) {
  if (settleCycles(ss, k) < 0) return -1;
  return ss.reach_cycles[k] < 0 ? static_cast<int>(ss.frames) : ss.reach_cycles[k];
}

// The trained classes and the ball.
const std::vector<int>& reportedClasses() {
  static const std::vector<int> classes = [] {
    std::vector<int> k = core::trainableClasses();
    k.push_back(core::kOrange);
    return k;
  }();
  return classes;
}

double f1(double recall, double precision) {
  if (std::isnan(recall)) return std::nan("");
  if (std::isnan(precision) || recall + precision <= 0) return 0.0;
  return 2 * recall * precision / (recall + precision);
}

Distribution distribution(std::vector<double> values, bool higher_is_better) {
  Distribution d;
  d.count = values.size();
  if (values.empty()) return d;
  std::sort(values.begin(), values.end());
  if (!higher_is_better) std::reverse(values.begin(), values.end());
  // values[0] is now the worst.
  auto quantile = [&](double q) {
    const double pos = q * static_cast<double>(values.size() - 1);
    const size_t lo = static_cast<size_t>(std::floor(pos));
    const size_t hi = std::min(values.size() - 1, lo + 1);
    return values[lo] + (pos - lo) * (values[hi] - values[lo]);
  };
  d.worst = values.front();
  d.p10 = quantile(0.1);
  d.median = quantile(0.5);
  return d;
}

}  // namespace

std::vector<EvalMode> evalModes(bool ablations) {
  std::vector<EvalMode> modes = {{"defaults", core::ActParams()}, {"paper", core::ActParams::paper()}};
  if (!ablations) return modes;
  const std::vector<std::pair<std::string, std::function<void(core::ActParams&)>>> off = {
      {"add_neighbourhood_cells", [](core::ActParams& p) { p.add_neighbourhood_cells = 0; }},
      {"light_compensation", [](core::ActParams& p) { p.light_compensation = false; }},
      {"removal_protect_cycles", [](core::ActParams& p) { p.removal_protect_cycles = 0; }},
      {"robot_height_m", [](core::ActParams& p) { p.robot_height_m = 0; }},
      {"robots_train_black", [](core::ActParams& p) { p.robots_train_black = false; }},
      {"nearest_mean", [](core::ActParams& p) { p.nearest_mean = false; }},
      {"evidence_removal_ratio", [](core::ActParams& p) { p.evidence_removal_ratio = 0; }},
      {"learned_boundary", [](core::ActParams& p) { p.learned_boundary = false; }},
      {"lattice_sampling", [](core::ActParams& p) { p.lattice_sampling = false; }},
      {"pose_check", [](core::ActParams& p) { p.pose_check = false; }},
      {"carpet_edge", [](core::ActParams& p) { p.carpet_edge = false; }},
  };
  for (const auto& [name, apply] : off) {
    EvalMode m{"no_" + name, core::ActParams()};
    apply(m.params);
    modes.push_back(m);
  }
  return modes;
}

std::vector<core::Pose2D> drivePoses(const FamilyScene& scene, int poses, bool turning) {
  std::vector<core::Pose2D> drive;
  if (scene.scenario.frames.empty()) return drive;
  const Scene& first = scene.scenario.frames.front().scene;
  const core::FieldCalibration& field = scene.calibration.field;
  std::mt19937 rng(scene.seed * 7919u + 17u);
  const double half_x = 0.45 * field.length_m, half_y = 0.45 * field.width_m;
  std::uniform_real_distribution<double> x(-half_x, half_x), y(-half_y, half_y), theta(-M_PI, M_PI);
  // Where the own robot (some 0.25 m in radius) can stand: off the other robots and the ball.
  auto free = [&](double px, double py) {
    for (const RobotObstacle& r : first.robots) {
      if (std::hypot(px - r.x_m, py - r.y_m) < r.radius_m + 0.3) return false;
    }
    return !first.ball || std::hypot(px - first.ball->x_m, py - first.ball->y_m) >= 0.4;
  };
  for (int tries = 0; static_cast<int>(drive.size()) < poses && tries < 50 * poses; ++tries) {
    core::Pose2D pose{x(rng), y(rng), theta(rng)};
    if (!turning) pose.theta_rad = 0.0;
    if (free(pose.x_m, pose.y_m)) drive.push_back(pose);
  }
  return drive;
}

std::vector<uint8_t> learnSelfMaskOnDrive(const FamilyScene& scene, int poses, bool turning) {
  if (scene.scenario.frames.empty()) return {};
  core::Calibration calibration = scene.calibration;
  calibration.camera.self_mask.clear();
  calibration.camera.self_mask_file.clear();
  const Renderer renderer(calibration, scene.renderer);
  core::ActTrainer trainer(calibration, core::ActParams());
  core::SelfMaskLearner learner(calibration);
  Scene drive = scene.scenario.frames.front().scene;
  const std::vector<core::Pose2D> at = drivePoses(scene, poses, turning);
  for (size_t k = 0; k < at.size(); ++k) {
    drive.robot_pose = at[k];
    drive.noise_seed = kDriveNoiseSeed + static_cast<uint32_t>(k);
    const LabeledFrame frame = renderer.render(drive);
    const core::ImageView view = core::ImageView::fromMat(frame.rgb, core::PixelFormat::kRgb8);
    if (k == 0) trainer.bootstrap(view, at[k], core::kDefaultBootstrapCycles);
    for (int c = 0; c < kDriveCyclesPerPose; ++c) trainer.cycle(view, at[k]);
    learner.add(view, at[k], trainer.lut());
  }
  return learner.mask();
}

SceneResult evaluateScene(const FamilyScene& scene, const std::vector<EvalMode>& modes, const EvalOptions& options) {
  SceneResult result;
  result.seed = scene.seed;
  result.summary = scene.summary;
  const Renderer renderer(scene.calibration, scene.renderer);
  core::Calibration calibration = scene.calibration;
  const std::vector<uint8_t> struts = renderer.strutMask();
  if (options.self_mask == SelfMaskSource::kStruts) calibration.camera.self_mask = struts;
  if (options.self_mask == SelfMaskSource::kLearnedOnDrive)
    calibration.camera.self_mask = learnSelfMaskOnDrive(scene, kDrivePoses);
  for (size_t i = 0; i < calibration.camera.self_mask.size(); ++i) {
    const bool strut = i < struts.size() && struts[i];
    result.self_mask_pixels += calibration.camera.self_mask[i];
    result.self_mask_on_struts += calibration.camera.self_mask[i] && strut;
  }
  result.strut_pixels = static_cast<size_t>(std::count(struts.begin(), struts.end(), uint8_t{1}));
  const core::Segmenter segmenter(calibration.camera);
  std::vector<core::ActTrainer> trainers;
  std::vector<core::RunEvaluation> evaluations;
  std::vector<cv::Mat> labels(modes.size());
  for (const EvalMode& m : modes) {
    result.mode_names.push_back(m.name);
    trainers.emplace_back(calibration, m.params);
    evaluations.emplace_back(options.adapt_frames);
  }
  core::TableCeiling ceiling;
  std::vector<core::FalsePixelSources> false_pixels(options.false_pixels ? modes.size() : 0);
  result.false_pixels.resize(false_pixels.size());
  // The ceiling and the false pixels of the segment that ends.
  auto closeSegment = [&]() {
    result.ceiling.push_back(ceiling.metrics());
    if (!false_pixels.empty()) {
      const core::ColorLut majority = ceiling.table();
      for (size_t m = 0; m < modes.size(); ++m) {
        result.false_pixels[m].push_back(false_pixels[m].sources(majority));
        false_pixels[m].clear();
      }
    }
    ceiling.clear();
  };
  size_t segment_start = 0;
  result.ball.assign(modes.size(), BallFigures{});
  size_t ball_first_in_view = SIZE_MAX;
  const auto& frames = scene.scenario.frames;
  for (size_t i = 0; i < frames.size(); ++i) {
    const ScenarioFrame& f = frames[i];
    if (!f.events.empty() && i > 0) {
      closeSegment();
      segment_start = i;
    }
    const auto t0 = Clock::now();
    const LabeledFrame frame = renderer.render(f.scene);
    const auto t1 = Clock::now();
    const core::ImageView view = core::ImageView::fromMat(frame.rgb, core::PixelFormat::kRgb8);
    const uint64_t ball_truth = static_cast<uint64_t>(cv::countNonZero(frame.labels == core::kOrange));
    if (ball_truth >= kMinBallTruthPixels && ball_first_in_view == SIZE_MAX) ball_first_in_view = i;
    const bool count_ball =
        !f.scene.ball || (ball_first_in_view != SIZE_MAX && i >= ball_first_in_view + kBallFramesInView);
    for (size_t m = 0; m < modes.size(); ++m) {
      for (const std::string& e : f.events) evaluations[m].markEvent(e);
      if (i == 0) trainers[m].bootstrap(view, f.told_pose, std::max(0, options.bootstrap_cycles - 1));
      const core::CycleStats stats = trainers[m].cycle(view, f.told_pose);
      segmenter.classify(trainers[m].lut(), view, labels[m]);
      trainers[m].unlabelBeyondCarpet(labels[m]);
      trainers[m].labelBall(stats, labels[m]);
      evaluations[m].addFrame(labels[m], frame.labels);
      BallFigures& b = result.ball[m];
      b.ball_in_scene = f.scene.ball.has_value();
      if (!count_ball) continue;
      ++b.frames;
      const cv::Mat predicted = (labels[m] == core::kOrange) & (frame.labels != core::kNotImaged);
      const uint64_t n_predicted = static_cast<uint64_t>(cv::countNonZero(predicted));
      if (!f.scene.ball) {
        b.frames_with_ball_pixels += n_predicted > 0;
        continue;
      }
      b.truth += ball_truth;
      b.predicted += n_predicted;
      b.hits += static_cast<uint64_t>(cv::countNonZero(predicted & (frame.labels == core::kOrange)));
      if (ball_truth < kMinBallTruthPixels) continue;
      ++b.frames_in_view;
      if (!stats.ball.seen) continue;
      ++b.sightings;
      // The truth in base_link.
      const core::Pose2D& pose = f.scene.robot_pose;
      const double dx = f.scene.ball->x_m - pose.x_m, dy = f.scene.ball->y_m - pose.y_m;
      const double c = std::cos(pose.theta_rad), s = std::sin(pose.theta_rad);
      const double bx = c * dx + s * dy, by = -s * dx + c * dy;
      const double error = std::hypot(stats.ball.x_m - bx, stats.ball.y_m - by);
      b.position_errors_m.push_back(error);
      b.position_ok += error <= 0.15 + 0.05 * std::hypot(bx, by);
    }
    const auto t2 = Clock::now();
    if (i - segment_start >= options.adapt_frames) {
      ceiling.add(view, frame.labels);
      for (size_t m = 0; m < false_pixels.size(); ++m) false_pixels[m].add(view, labels[m], frame.labels);
    }
    result.render_seconds += seconds(t1 - t0);
    result.act_seconds += seconds(t2 - t1);
    const bool segment_ends = i + 1 == frames.size() || !frames[i + 1].events.empty();
    if (!options.png_dir.empty() && segment_ends) {
      char name[96];
      std::snprintf(name, sizeof(name), "/scene_%05u_frame_%03zu.png", scene.seed, i);
      writePanel(options.png_dir + name, frame.rgb, labels, frame.labels);
    }
  }
  closeSegment();
  result.frames = frames.size();
  result.adapt_frames = options.adapt_frames;
  for (const core::RunEvaluation& e : evaluations) result.segments.push_back(e.segments());
  return result;
}

FamilyReport summarize(const std::vector<SceneResult>& results) {
  FamilyReport r;
  if (results.empty()) return r;
  r.mode_names = results.front().mode_names;
  const size_t modes = r.mode_names.size();
  const size_t with_ceiling = modes + 1;
  using Values = std::array<std::vector<double>, core::kNumClasses>;
  std::vector<Values> recall(with_ceiling), precision(with_ceiling), recall_gap(modes), precision_gap(modes),
      settle(modes), reach(modes), false_shared(modes), false_hall(modes), false_other(modes), false_top(modes);
  r.f1_below_paper.assign(modes, {});
  r.f1_worst_vs_paper.assign(modes, {});
  r.worst_recall_seed.assign(modes, {});
  r.worst_precision_seed.assign(modes, {});
  std::vector<std::array<double, core::kNumClasses>> worst_recall(modes), worst_precision(modes);
  for (auto& w : worst_recall) w.fill(2.0);
  for (auto& w : worst_precision) w.fill(2.0);
  const size_t paper =
      static_cast<size_t>(std::find(r.mode_names.begin(), r.mode_names.end(), "paper") - r.mode_names.begin());
  for (const SceneResult& s : results) {
    for (size_t seg = 0; seg < s.ceiling.size(); ++seg) {
      const core::ClassificationMetrics& ceil = s.ceiling[seg];
      const core::SegmentSummary& reference = s.segments[0][seg];
      const double frames_after =
          std::max(1.0, static_cast<double>(reference.frames) - static_cast<double>(s.adapt_frames));
      for (int k : reportedClasses()) {
        if (ceil.truthCount(k) < kMinTruthPixelsPerFrame * frames_after) continue;
        const double ceil_recall = ceil.recall(k), ceil_precision = ceil.precision(k);
        recall[modes][k].push_back(ceil_recall);
        if (!std::isnan(ceil_precision)) precision[modes][k].push_back(ceil_precision);
        for (size_t m = 0; m < modes; ++m) {
          const core::SegmentSummary& ss = s.segments[m][seg];
          const double rec = ss.adapted.recall(k), prec = ss.adapted.precision(k);
          recall[m][k].push_back(rec);
          recall_gap[m][k].push_back(ceil_recall - rec);
          if (rec < worst_recall[m][k]) {
            worst_recall[m][k] = rec;
            r.worst_recall_seed[m][k] = s.seed;
          }
          const double p = std::isnan(prec) ? 0.0 : prec;
          precision[m][k].push_back(p);
          if (!std::isnan(ceil_precision)) precision_gap[m][k].push_back(ceil_precision - p);
          if (p < worst_precision[m][k]) {
            worst_precision[m][k] = p;
            r.worst_precision_seed[m][k] = s.seed;
          }
          if (paper < modes) {
            const core::SegmentSummary& ps = s.segments[paper][seg];
            const double diff = f1(rec, prec) - f1(ps.adapted.recall(k), ps.adapted.precision(k));
            if (diff < -0.02) ++r.f1_below_paper[m][k];
            r.f1_worst_vs_paper[m][k] = std::min(r.f1_worst_vs_paper[m][k], diff);
          }
          if (const int cycles = settleCycles(ss, k); cycles >= 0) settle[m][k].push_back(cycles);
          if (const int cycles = reachCycles(ss, k); cycles >= 0) reach[m][k].push_back(cycles);
          if (m < s.false_pixels.size() && seg < s.false_pixels[m].size()) {
            const core::FalsePixels& fp = s.false_pixels[m][seg][k];
            const double n = std::max<double>(1.0, static_cast<double>(fp.classified));
            false_shared[m][k].push_back(fp.shared / n);
            false_hall[m][k].push_back(fp.hall / n);
            false_other[m][k].push_back(fp.other / n);
            false_top[m][k].push_back(fp.top / n);
          }
        }
      }
    }
  }
  r.ball_recall.resize(modes);
  r.ball_precision.resize(modes);
  r.ball_position_ok.resize(modes);
  r.ball_seen.resize(modes);
  r.no_ball_false_frames.resize(modes);
  r.no_ball_scenes_over_1pct.assign(modes, 0);
  for (size_t m = 0; m < modes; ++m) {
    std::vector<double> rec, prec, pos, seen, false_frames;
    for (const SceneResult& s : results) {
      if (m >= s.ball.size()) continue;
      const BallFigures& b = s.ball[m];
      if (!b.ball_in_scene) {
        if (b.frames == 0) continue;
        const double fraction = static_cast<double>(b.frames_with_ball_pixels) / b.frames;
        false_frames.push_back(fraction);
        r.no_ball_scenes_over_1pct[m] += fraction > 0.01;
        continue;
      }
      if (b.truth < kMinBallTruthPixels * 5) continue;  // in view too briefly to be scored
      rec.push_back(b.recall());
      prec.push_back(b.predicted ? b.precision() : 0.0);
      seen.push_back(b.frames_in_view ? static_cast<double>(b.sightings) / b.frames_in_view : 0.0);
      pos.push_back(b.sightings ? static_cast<double>(b.position_ok) / b.sightings : 0.0);
    }
    r.ball_recall[m] = distribution(rec, true);
    r.ball_precision[m] = distribution(prec, true);
    r.ball_position_ok[m] = distribution(pos, true);
    r.ball_seen[m] = distribution(seen, true);
    r.no_ball_false_frames[m] = distribution(false_frames, false);
  }
  auto fill = [](const std::vector<Values>& v, bool higher_is_better) {
    std::vector<std::array<Distribution, core::kNumClasses>> out(v.size());
    for (size_t m = 0; m < v.size(); ++m) {
      for (int k = 0; k < core::kNumClasses; ++k) out[m][k] = distribution(v[m][k], higher_is_better);
    }
    return out;
  };
  r.recall = fill(recall, true);
  r.precision = fill(precision, true);
  r.recall_gap = fill(recall_gap, false);
  r.precision_gap = fill(precision_gap, false);
  r.settle = fill(settle, false);
  r.reach = fill(reach, false);
  if (!results.front().false_pixels.empty()) {
    r.false_shared = fill(false_shared, false);
    r.false_hall = fill(false_hall, false);
    r.false_other = fill(false_other, false);
    r.false_top = fill(false_top, false);
  }
  return r;
}

std::string formatReport(const FamilyReport& r) {
  std::string out;
  char line[512];
  if (r.mode_names.empty()) return "no scenes\n";
  const size_t modes = r.mode_names.size();
  auto dist = [](const Distribution& d) {
    char b[64];
    if (d.count == 0) return std::string("      -       ");
    std::snprintf(b, sizeof(b), "%.2f %.2f %.2f", d.median, d.p10, d.worst);
    return std::string(b);
  };
  auto table = [&](const char* title, const std::vector<std::array<Distribution, core::kNumClasses>>& d,
                   bool with_ceiling, const char* columns) {
    std::snprintf(line, sizeof(line), "%s (%s; units: scene segments after adaptation)\n", title, columns);
    out += line;
    std::snprintf(line, sizeof(line), "  %-7s %5s", "class", "units");
    out += line;
    const size_t n = with_ceiling ? modes + 1 : modes;
    for (size_t m = 0; m < n; ++m) {
      std::snprintf(line, sizeof(line), " | %-14s", m < modes ? r.mode_names[m].c_str() : "ceiling");
      out += line;
    }
    out += "\n";
    for (int k : reportedClasses()) {
      std::snprintf(line, sizeof(line), "  %-7s %5zu", core::className(k), d[0][k].count);
      out += line;
      for (size_t m = 0; m < n; ++m) out += " | " + dist(d[m][k]);
      out += "\n";
    }
  };
  table("recall", r.recall, true, "median p10 worst");
  table("precision", r.precision, true, "median p10 worst");
  table("recall gap to the ceiling", r.recall_gap, false, "median p90 worst; ceiling - mode");
  table("precision gap to the ceiling", r.precision_gap, false, "median p90 worst; ceiling - mode");
  table("cycles to settle after a sudden change of light", r.settle, false,
        "median p90 worst; within 0.02 of the final recall; never settled = segment length");
  table("cycles until recall first comes within 0.02 of its final level after such a change", r.reach, false,
        "median p90 worst; it may leave it again (settle counts the last return); never = segment length");
  if (!r.false_shared.empty()) {
    const char* columns = "median p90 worst; share of the pixels classified as the class";
    table("false pixels in cells the ceiling gives the class too", r.false_shared, false, columns);
    table("false pixels in cells of the hall (the ceiling's unknown)", r.false_hall, false, columns);
    table("false pixels in cells of another class", r.false_other, false, columns);
    table("false pixels in a cell at the top of a channel (clipped)", r.false_top, false, columns);
  }
  out += "F1 below the paper's F1 - 0.02 (units; worst F1 difference)\n";
  for (size_t m = 0; m < modes; ++m) {
    std::snprintf(line, sizeof(line), "  %-26s", r.mode_names[m].c_str());
    out += line;
    for (int k : reportedClasses()) {
      std::snprintf(line, sizeof(line), " %s %zu (%+.2f)", core::className(k), r.f1_below_paper[m][k],
                    r.f1_worst_vs_paper[m][k]);
      out += line;
    }
    out += "\n";
  }
  std::snprintf(line, sizeof(line),
                "ball (issue 13; units: scenes; from %zu frames after the ball came into view; median p10 worst)\n",
                kBallFramesInView);
  out += line;
  for (size_t m = 0; m < modes; ++m) {
    std::snprintf(line, sizeof(line),
                  "  %-26s scenes %zu: recall %s  precision %s  seen %s  position ok %s | no ball: scenes %zu, "
                  "frames with ball pixels median %.3f worst %.3f, scenes over 1%% %zu\n",
                  r.mode_names[m].c_str(), r.ball_recall[m].count, dist(r.ball_recall[m]).c_str(),
                  dist(r.ball_precision[m]).c_str(), dist(r.ball_seen[m]).c_str(), dist(r.ball_position_ok[m]).c_str(),
                  r.no_ball_false_frames[m].count, r.no_ball_false_frames[m].median, r.no_ball_false_frames[m].worst,
                  r.no_ball_scenes_over_1pct[m]);
    out += line;
  }
  out += "worst recall / precision at seed\n";
  for (size_t m = 0; m < modes; ++m) {
    std::snprintf(line, sizeof(line), "  %-26s", r.mode_names[m].c_str());
    out += line;
    for (int k : reportedClasses()) {
      std::snprintf(line, sizeof(line), " %s %u/%u", core::className(k), r.worst_recall_seed[m][k],
                    r.worst_precision_seed[m][k]);
      out += line;
    }
    out += "\n";
  }
  return out;
}

std::string formatScene(const SceneResult& s) {
  std::string out;
  char line[256];
  // The summary can be longer than the line buffer (composed light events): appended whole.
  std::snprintf(line, sizeof(line), "seed %u (%zu frames, render %.1f s, ACT %.1f s): ", s.seed, s.frames,
                s.render_seconds, s.act_seconds);
  out += line;
  out += s.summary;
  out += "\n";
  if (s.self_mask_pixels > 0) {
    std::snprintf(line, sizeof(line), "  self mask %zu px, %zu of them on the %zu px of the struts\n",
                  s.self_mask_pixels, s.self_mask_on_struts, s.strut_pixels);
    out += line;
  }
  for (size_t seg = 0; seg < s.ceiling.size(); ++seg) {
    std::snprintf(line, sizeof(line), "  segment '%s' F1", s.segments[0][seg].event.c_str());
    out += line;
    for (int k : reportedClasses()) {
      if (s.ceiling[seg].truthCount(k) == 0) continue;
      std::snprintf(line, sizeof(line), "  %s", core::className(k));
      out += line;
      for (size_t m = 0; m < s.mode_names.size(); ++m) {
        const auto& a = s.segments[m][seg].adapted;
        std::snprintf(line, sizeof(line), " %.2f", f1(a.recall(k), a.precision(k)));
        out += line;
      }
      std::snprintf(line, sizeof(line), " [%.2f]", f1(s.ceiling[seg].recall(k), s.ceiling[seg].precision(k)));
      out += line;
    }
    out += "\n";
    // Cycles to settle per mode, as the report counts them.
    const core::SegmentSummary& first = s.segments[0][seg];
    if (first.first_frame == 0 || !startsWithSuddenChange(first.event)) continue;
    out += "    settle";
    for (int k : reportedClasses()) {
      if (s.ceiling[seg].truthCount(k) == 0 || settleCycles(first, k) < 0) continue;
      std::snprintf(line, sizeof(line), "  %s", core::className(k));
      out += line;
      for (size_t m = 0; m < s.mode_names.size(); ++m) {
        std::snprintf(line, sizeof(line), " %d", settleCycles(s.segments[m][seg], k));
        out += line;
      }
    }
    out += "\n";
  }
  for (size_t m = 0; m < s.ball.size(); ++m) {
    const BallFigures& b = s.ball[m];
    if (b.ball_in_scene) {
      std::snprintf(line, sizeof(line),
                    "  ball %-10s frames %zu (in view %zu): recall %.2f precision %.2f, seen %zu, position ok %zu\n",
                    s.mode_names[m].c_str(), b.frames, b.frames_in_view, b.recall(), b.precision(), b.sightings,
                    b.position_ok);
    } else {
      std::snprintf(line, sizeof(line), "  no ball %-10s frames %zu, with ball pixels %zu\n", s.mode_names[m].c_str(),
                    b.frames, b.frames_with_ball_pixels);
    }
    out += line;
  }
  return out;
}

}  // namespace sim
}  // namespace act_color
