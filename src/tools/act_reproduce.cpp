// act_reproduce: the experiments of the paper's section 3 on the package's simulator, each as a
// CSV and a PNG plot, plus a summary (results/summary.txt) comparing with the paper's numbers.
//   act_reproduce [--calibration CAL.yaml] --output-dir DIR [--only fig1|fig23|fig4]
// Everything runs in-process (sim::Renderer, no bags); deterministic.
#include <iomanip>
#include <iostream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "act_color/core/act_trainer.hpp"
#include "act_color/core/calibration.hpp"
#include "act_color/core/metrics.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scenario.hpp"
#include "bench_util.hpp"

#ifndef ACT_SOURCE_DIR
#define ACT_SOURCE_DIR "."
#endif

namespace {

namespace core = act_color::core;
namespace sim = act_color::sim;
namespace tools = act_color::tools;
using core::ActParams;
using core::ActTrainer;
using core::ClassificationMetrics;
using core::ImageView;
using core::PixelFormat;

struct Mode {
  std::string name;  // "ours" or "paper"
  ActParams params;
};

std::vector<Mode> modes() {
  return {{"ours", ActParams()}, {"paper", ActParams::paper()}};  // paper: act_replay --paper
}

const std::vector<int>& trainable() { return core::trainableClasses(); }

const char* className(int k) {
  static const char* names[] = {"unknown", "green", "white", "yellow", "blue", "black", "orange"};
  return names[k];
}

cv::Scalar classColor(int k) {  // BGR, white drawn grey
  switch (k) {
    case core::kGreen:
      return {0, 150, 0};
    case core::kWhite:
      return {150, 150, 150};
    case core::kYellow:
      return {0, 190, 230};
    case core::kBlue:
      return {200, 40, 0};
    case core::kBlack:
      return {0, 0, 0};
    default:
      return {0, 0, 255};
  }
}

ImageView view(const cv::Mat& rgb) { return ImageView::fromMat(rgb, PixelFormat::kRgb8); }

ClassificationMetrics evaluate(const core::Segmenter& segmenter, const core::ColorLut& lut,
                               const sim::LabeledFrame& frame) {
  cv::Mat labels;
  segmenter.classify(lut, view(frame.rgb), labels);
  ClassificationMetrics m;
  m.add(labels, frame.labels);
  return m;
}

std::string fmt(double v, int precision = 3) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(precision) << v;
  return s.str();
}

void writeFile(const std::string& path, const std::string& text) {
  FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw std::runtime_error("cannot write " + path);
  std::fputs(text.c_str(), f);
  std::fclose(f);
  std::cerr << "act_reproduce: wrote " << path << "\n";
}

void writePng(const std::string& path, const cv::Mat& rgb_or_bgr) {
  if (!cv::imwrite(path, rgb_or_bgr)) throw std::runtime_error("cannot write " + path);
  std::cerr << "act_reproduce: wrote " << path << "\n";
}

// Paper 3.1, fig. 1: fitness (eq. 6) of the converged table against zeta (and xi) on a dark, a
// normal and a bright image, each trained `cycles` cycles at its right pose.
void fig1(const core::Calibration& cal, const sim::Renderer& renderer, const std::string& dir,
          std::ostringstream& summary) {
  const int cycles = 30;
  const sim::Scenario s = sim::makeScenario("static_darkening", sim::ScenarioLength::kSmall, cal, 1);
  sim::Scene normal = s.frames[0].scene;
  sim::Scene dark = normal, bright = normal;
  dark.lighting.brightness_contrast = 0.5;
  bright.lighting.level = 1.4;
  const std::vector<std::pair<std::string, sim::Scene>> images = {
      {"dark", dark}, {"normal", normal}, {"bright", bright}};
  std::vector<sim::LabeledFrame> frames;
  for (const auto& [name, scene] : images) frames.push_back(renderer.render(scene));
  const core::Segmenter segmenter(cal.camera);
  const core::Pose2D pose = s.frames[0].told_pose;

  auto fitnessOf = [&](const ActParams& p, const sim::LabeledFrame& f) {
    ActTrainer trainer(cal, p);
    trainer.bootstrap(view(f.rgb), pose, cycles);
    return evaluate(segmenter, trainer.lut(), f).fitness(trainable());
  };

  std::vector<double> zetas, xis;
  for (double z = 1.0; z <= 6.0 + 1e-9; z += 0.25) zetas.push_back(z);
  for (double x = 0.9; x <= 2.1 + 1e-9; x += 0.15) xis.push_back(x);
  // The paper's intervals of best fitness.
  const std::map<std::string, std::string> paper_zeta = {
      {"dark", "[1.75, 3.0]"}, {"normal", "[2.25, 3.25]"}, {"bright", "[2.25, 3.5]"}};

  std::ostringstream csv_z, csv_x;
  csv_z << "mode,image,zeta,xi,fitness\n";
  csv_x << "mode,image,zeta,xi,fitness\n";
  summary << "## Fig. 1: fitness (eq. 6, sum of 1 - recall over green, white, yellow, blue, black; 0 is "
             "perfect) after "
          << cycles << " cycles at the right pose\n\n";
  summary << "| mode | image | best fitness | zeta range within 0.05 of best | paper's zeta range | fitness at "
             "zeta 2.5 | xi range within 0.05 of best (zeta 2.5) |\n|---|---|---|---|---|---|---|\n";
  for (const Mode& mode : modes()) {
    std::vector<tools::Series> zs, xs;
    for (size_t i = 0; i < images.size(); ++i) {
      tools::Series sz{images[i].first, {}, {}, {}, false};
      sz.color = i == 0 ? cv::Scalar(120, 0, 0) : i == 1 ? cv::Scalar(0, 140, 0) : cv::Scalar(0, 140, 255);
      tools::Series sx = sz;
      // Fitness over the values of one parameter, the others at the mode's defaults.
      auto sweep = [&](const std::vector<double>& values, double ActParams::*param, tools::Series& series,
                       std::ostream& csv) {
        for (double value : values) {
          ActParams p = mode.params;
          p.*param = value;
          const double f = fitnessOf(p, frames[i]);
          series.x.push_back(value);
          series.y.push_back(f);
          csv << mode.name << "," << images[i].first << "," << p.zeta << "," << p.xi << "," << fmt(f, 5) << "\n";
        }
      };
      sweep(zetas, &ActParams::zeta, sz, csv_z);
      sweep(xis, &ActParams::xi, sx, csv_x);
      auto range = [](const tools::Series& se, double* best) {
        *best = *std::min_element(se.y.begin(), se.y.end());
        double lo = 1e9, hi = -1e9;
        for (size_t k = 0; k < se.x.size(); ++k) {
          if (se.y[k] <= *best + 0.05) {
            lo = std::min(lo, se.x[k]);
            hi = std::max(hi, se.x[k]);
          }
        }
        return "[" + fmt(lo, 2) + ", " + fmt(hi, 2) + "]";
      };
      double best_z = 0, best_x = 0;
      const std::string zr = range(sz, &best_z), xr = range(sx, &best_x);
      double at25 = 0;
      for (size_t k = 0; k < sz.x.size(); ++k) {
        if (std::abs(sz.x[k] - 2.5) < 1e-9) at25 = sz.y[k];
      }
      summary << "| " << mode.name << " | " << images[i].first << " | " << fmt(best_z) << " | " << zr << " | "
              << paper_zeta.at(images[i].first) << " | " << fmt(at25) << " | " << xr << " |\n";
      zs.push_back(sz);
      xs.push_back(sx);
    }
    double ymax = 0.5;
    for (const auto& se : zs) ymax = std::max(ymax, *std::max_element(se.y.begin(), se.y.end()));
    writePng(
        dir + "/fig1_zeta_" + mode.name + ".png",
        tools::plotLines("Fig. 1 (" + mode.name + "): fitness vs zeta, xi 1.35, " + std::to_string(cycles) + " cycles",
                         "zeta", "fitness (eq. 6, lower is better)", zs, 0.0, std::ceil(ymax * 2) / 2, 900, 560,
                         {{2.5, "paper: 2.5"}}));
    ymax = 0.5;
    for (const auto& se : xs) ymax = std::max(ymax, *std::max_element(se.y.begin(), se.y.end()));
    writePng(
        dir + "/fig1_xi_" + mode.name + ".png",
        tools::plotLines("Fig. 1 (" + mode.name + "): fitness vs xi, zeta 2.5, " + std::to_string(cycles) + " cycles",
                         "xi", "fitness (eq. 6, lower is better)", xs, 0.0, std::ceil(ymax * 2) / 2, 900, 560,
                         {{1.35, "paper: 1.35"}}));
  }
  summary << "\nPaper: zeta best in [1.75, 3.0] (dark), [2.25, 3.25] (normal), [2.25, 3.5] (bright); xi best in "
             "[1.2, 1.5] at zeta 2.5.\n\n";
  writeFile(dir + "/fig1_zeta.csv", csv_z.str());
  writeFile(dir + "/fig1_xi.csv", csv_x.str());
}

// Paper 3.2, figs. 2-3: a static robot, trained on the normal image, then brightness and contrast
// drop to 50%. Per-class recall per cycle with ACT and with the table frozen before the drop.
void fig23(const core::Calibration& cal, const sim::Renderer& renderer, const std::string& dir,
           std::ostringstream& summary) {
  const sim::Scenario s = sim::makeScenario("static_darkening", sim::ScenarioLength::kFull, cal, 1);
  size_t event = 0;
  for (size_t i = 0; i < s.frames.size(); ++i) {
    if (!s.frames[i].events.empty()) event = i;
  }
  const int before = 10, after = 40;
  std::vector<sim::LabeledFrame> frames;
  std::vector<core::Pose2D> poses;
  for (size_t i = event - before; i < event + after; ++i) {
    frames.push_back(renderer.render(s.frames[i].scene));
    poses.push_back(s.frames[i].told_pose);
  }
  const core::Segmenter segmenter(cal.camera);
  std::ostringstream csv;
  csv << "mode,table,cycle";
  for (int k : trainable()) csv << ",recall_" << className(k);
  csv << "\n";
  summary << "## Figs. 2-3: sudden 50% darkening of a static scene\n\n"
          << "Trained " << core::kDefaultBootstrapCycles << " cycles on the first normal frame plus " << before
          << " normal frames, then darkened frames (brightness and contrast 50%); each frame is trained on and "
             "then classified with the table (the contract's rule). Settle: cycles after the drop until the "
             "class's per-frame recall stays within 0.02 of its final value (mean over the last quarter), both "
             "ways (core::RunEvaluation, act_replay --brief, only counts frames below it).\n\n";
  summary << "| mode | table | green | white | yellow | blue | black | settle green/white | settle all (max) | "
             "final recall green/white/yellow/blue/black |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Mode& mode : modes()) {
    ActTrainer trainer(cal, mode.params);
    trainer.bootstrap(view(frames[0].rgb), poses[0], core::kDefaultBootstrapCycles);
    core::ColorLut frozen;
    std::vector<tools::Series> series;
    std::map<int, tools::Series> act_series, static_series;
    for (int k : trainable()) {
      act_series[k] = {std::string(className(k)) + " ACT", {}, {}, classColor(k), false};
      static_series[k] = {std::string(className(k)) + " static", {}, {}, classColor(k), true};
    }
    for (size_t i = 0; i < frames.size(); ++i) {
      const int cycle = static_cast<int>(i) - before + 1;  // 1: the first darkened frame
      if (static_cast<int>(i) == before) {
        frozen = trainer.lut();  // the static table: trained once, then frozen
      }
      trainer.cycle(view(frames[i].rgb), poses[i]);
      const ClassificationMetrics m = evaluate(segmenter, trainer.lut(), frames[i]);
      cv::Mat labels;
      segmenter.classify(static_cast<int>(i) < before ? trainer.lut() : frozen, view(frames[i].rgb), labels);
      ClassificationMetrics ms;
      ms.add(labels, frames[i].labels);
      csv << mode.name << ",act," << cycle;
      for (int k : trainable()) csv << "," << fmt(m.recall(k), 4);
      csv << "\n" << mode.name << ",static," << cycle;
      for (int k : trainable()) csv << "," << fmt(ms.recall(k), 4);
      csv << "\n";
      for (int k : trainable()) {
        act_series[k].x.push_back(cycle);
        act_series[k].y.push_back(m.recall(k));
        static_series[k].x.push_back(cycle);
        static_series[k].y.push_back(ms.recall(k));
      }
    }
    // Settle cycles and final recall from per-frame recall (stricter than RunEvaluation: both ways).
    auto settle = [&](const tools::Series& se, double* final_recall) {
      const size_t first = before;  // index of cycle 1
      const size_t n = se.y.size() - first;
      double sum = 0;
      size_t cnt = 0;
      for (size_t j = first + n - n / 4; j < se.y.size(); ++j) {
        sum += se.y[j];
        ++cnt;
      }
      *final_recall = sum / cnt;
      int last_bad = 0;
      for (size_t j = first; j < se.y.size(); ++j) {
        if (std::abs(se.y[j] - *final_recall) > 0.02) last_bad = static_cast<int>(j - first + 1);
      }
      return last_bad + 1;
    };
    for (const std::string table : {"act", "static"}) {
      auto& ser = table == "act" ? act_series : static_series;
      std::ostringstream row_settle, finals;
      int gw = 0, all = 0;
      for (int k : trainable()) {
        double fr = 0;
        const int c = settle(ser[k], &fr);
        row_settle << " " << c << " |";
        if (k == core::kGreen || k == core::kWhite) gw = std::max(gw, c);
        all = std::max(all, c);
        finals << (finals.tellp() > 0 ? "/" : "") << fmt(fr, 2);
      }
      summary << "| " << mode.name << " | " << (table == "act" ? "ACT" : "static (frozen before the drop)") << " |"
              << row_settle.str() << " " << gw << " | " << all << " | " << finals.str() << " |\n";
    }
    for (int k : trainable()) series.push_back(act_series[k]);
    for (int k : {core::kGreen, core::kWhite}) series.push_back(static_series[k]);
    writePng(dir + "/fig23_darkening_" + mode.name + ".png",
             tools::plotLines("Figs. 2-3 (" + mode.name + "): recall per cycle, 50% darkening at cycle 1",
                              "cycle (1 = first darkened frame)", "recall", series, 0.0, 1.0, 1000, 560,
                              {{0.5, "darkening"}}));
  }
  summary << "\nPaper: near-optimal after 2 cycles for green and white, stable after 12. Issue 5 asks for green/white "
             "within 2 and every trainable class within 6. Settle values are cycles (1 = already there on the first "
             "darkened frame). The static table is the same ACT table frozen before the drop, i.e. a perfectly "
             "hand-calibrated table for the normal light.\n\n";
  writeFile(dir + "/fig23_darkening.csv", csv.str());
}

// Paper 3.3, fig. 4: frames cycle over poses A, B and a true pose 2.5 m from B rotated by 165
// degrees while ACT is told B; the same frames with the right poses; and a static table.
void fig4(const core::Calibration& cal, const sim::Renderer& renderer, const std::string& dir,
          std::ostringstream& summary) {
  const sim::Scenario s = sim::makeScenario("wrong_pose", sim::ScenarioLength::kFull, cal, 1);
  const size_t n = 90;  // 30 rounds of the three poses
  std::vector<sim::LabeledFrame> frames;
  for (size_t i = 0; i < n; ++i) frames.push_back(renderer.render(s.frames[i].scene));
  const core::Segmenter segmenter(cal.camera);
  const size_t skip = 12;  // frames left out of the pooled figures, as act_replay's adapt frames
  std::ostringstream csv;
  csv << "mode,run,frame,phase";
  for (int k : trainable()) csv << ",recall_" << className(k);
  csv << ",mean_recall\n";
  summary << "## Fig. 4: wrong pose (2.5 m away, rotated by 165 degrees) every third frame\n\n"
          << "Frames cycle over poses A, B and C, where C is 2.5 m from B and rotated by 165 degrees but ACT is told "
             "B. Right pose: the same frames with C told correctly. Static: the table bootstrapped on frame 0 ("
          << core::kDefaultBootstrapCycles << " cycles), then frozen. Recall pooled over frames " << skip << ".."
          << n - 1 << " (all), and over the wrong-pose frames only (C).\n\n";
  summary << "| mode | run | green | white | yellow | blue | black | C frames: green | white | yellow | blue | black "
             "|\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Mode& mode : modes()) {
    std::map<std::string, std::array<double, core::kNumClasses>> pooled_all;
    std::vector<tools::Series> series;
    for (const std::string run : {"right_pose", "wrong_pose", "static"}) {
      ActTrainer trainer(cal, mode.params);
      trainer.bootstrap(view(frames[0].rgb), s.frames[0].told_pose, core::kDefaultBootstrapCycles);
      ClassificationMetrics all, wrong_frames;
      tools::Series se{run == "right_pose"   ? "right pose"
                       : run == "wrong_pose" ? "wrong pose"
                                             : "static table",
                       {},
                       {},
                       run == "right_pose"   ? cv::Scalar(0, 150, 0)
                       : run == "wrong_pose" ? cv::Scalar(0, 0, 220)
                                             : cv::Scalar(90, 90, 90),
                       run == "static"};
      for (size_t i = 0; i < n; ++i) {
        const core::Pose2D told = run == "right_pose" ? s.frames[i].scene.robot_pose : s.frames[i].told_pose;
        if (run != "static") trainer.cycle(view(frames[i].rgb), told);
        const ClassificationMetrics m = evaluate(segmenter, trainer.lut(), frames[i]);
        if (i >= skip) {
          all.merge(m);
          if (i % 3 == 2) wrong_frames.merge(m);
        }
        double mean = 0;
        int cnt = 0;
        csv << mode.name << "," << run << "," << i << ","
            << "ABC"[i % 3];
        for (int k : trainable()) {
          csv << "," << fmt(m.recall(k), 4);
          if (std::isfinite(m.recall(k))) {
            mean += m.recall(k);
            ++cnt;
          }
        }
        mean /= std::max(1, cnt);
        csv << "," << fmt(mean, 4) << "\n";
        se.x.push_back(static_cast<double>(i));
        se.y.push_back(mean);
      }
      series.push_back(se);
      summary << "| " << mode.name << " | " << run << " |";
      for (int k : trainable()) {
        summary << " " << fmt(all.recall(k)) << " |";
        pooled_all[run][k] = all.recall(k);
      }
      for (int k : trainable()) summary << " " << fmt(wrong_frames.recall(k)) << " |";
      summary << "\n";
    }
    summary << "| " << mode.name << " | wrong - right |";
    double worst = 0;
    for (int k : trainable()) {
      const double d = pooled_all["wrong_pose"][k] - pooled_all["right_pose"][k];
      worst = std::min(worst, d);
      summary << " " << fmt(d) << " |";
    }
    summary << " largest drop " << fmt(-worst) << " (issue 5: <= 0.03) | | | | |\n";
    writePng(dir + "/fig4_wrong_pose_" + mode.name + ".png",
             tools::plotLines("Fig. 4 (" + mode.name + "): mean recall of the trainable classes per frame",
                              "frame (every third: the wrong pose)", "mean recall", series, 0.5, 1.0, 1000, 560));
  }
  summary << "\n";
  writeFile(dir + "/fig4_wrong_pose.csv", csv.str());
}

}  // namespace

int main(int argc, char** argv) {
  std::string calibration_path = std::string(ACT_SOURCE_DIR) + "/config/calibration/msl_2007_580.yaml";
  std::string dir, only;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--calibration" && a + 1 < argc) {
      calibration_path = argv[++a];
    } else if (arg == "--output-dir" && a + 1 < argc) {
      dir = argv[++a];
    } else if (arg == "--only" && a + 1 < argc) {
      only = argv[++a];
    } else {
      std::cerr << "usage: act_reproduce [--calibration CAL.yaml] --output-dir DIR [--only fig1|fig23|fig4]\n";
      return 2;
    }
  }
  if (dir.empty()) {
    std::cerr << "usage: act_reproduce [--calibration CAL.yaml] --output-dir DIR [--only fig1|fig23|fig4]\n";
    return 2;
  }
  try {
    const core::Calibration cal = core::loadCalibration(calibration_path);
    const sim::Renderer renderer(cal);
    std::ostringstream summary;
    summary << "# act_reproduce: the paper's section 3 on the simulator\n\n"
            << "Calibration " << calibration_path.substr(calibration_path.rfind('/') + 1)
            << "; 'ours' = ActParams defaults (all extensions on), 'paper' = act_replay --paper (every "
               "extension off: the published algorithm).\n\n";
    if (only.empty() || only == "fig1") fig1(cal, renderer, dir, summary);
    if (only.empty() || only == "fig23") fig23(cal, renderer, dir, summary);
    if (only.empty() || only == "fig4") fig4(cal, renderer, dir, summary);
    std::cout << summary.str();
    writeFile(dir + "/summary" + (only.empty() ? "" : "_" + only) + ".md", summary.str());
  } catch (const std::exception& e) {
    std::cerr << "act_reproduce: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
