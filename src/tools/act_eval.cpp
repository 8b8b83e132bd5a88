// act_eval: ACT on the randomized scene family (sim/scene_family.hpp), in-process: per class the
// median, 10th percentile and worst recall and precision after adaptation for the defaults and the
// paper's algorithm side by side, the fixed-table ceiling of every scene segment, the gaps to it,
// the cycles to settle after each event, and where the defaults fall below the paper.
//   act_eval [--split report|tuning] [--seeds A-B] [--count N] [--length small|full] [--ablate]
//            [--local-light] [--per-scene] [--png DIR] [--false-pixels] [--self-mask]
//            [--learn-self-mask]
// Tune on the tuning split (seeds 0-99); the report split (1000-1099) is for reporting only.
#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "act_color/core/act_trainer.hpp"
#include "act_color/core/file_io.hpp"
#include "act_color/sim/family_evaluation.hpp"
#include "act_color/sim/scene_family.hpp"

namespace {

namespace core = act_color::core;
namespace sim = act_color::sim;

const char* const kUsage =
    "usage: act_eval [--split report|tuning] [--seeds A-B] [--count N] [--length small|full]\n"
    "                [--ablate] [--local-light] [--set NAME=VALUE] [--mode NAME:N=V,...] [--per-scene]\n"
    "                [--png DIR] [--false-pixels] [--self-mask | --learn-self-mask]\n"
    "  --split S     report: seeds 1000-1099 (default); tuning: seeds 0-99\n"
    "  --seeds A-B   any range of seeds instead (inclusive)\n"
    "  --count N     only the first N seeds of the range (a quick subset)\n"
    "  --length L    small (default, 40-60 frames per scene) or full\n"
    "  --ablate      also the defaults with each extension off in turn\n"
    "  --local-light the same scenes with each sudden change of light made local: the light on one\n"
    "                side of a line across the field x0.25-0.6 or x1.4-1.8 (events 'local:...')\n"
    "  --set N=V     an ACT parameter for every mode but the paper's (repeatable), e.g. zeta=3\n"
    "  --mode M:N=V,N=V  one more mode: the defaults with these parameters (repeatable)\n"
    "  --per-scene   one line per scene and segment: F1 per class and mode, [ceiling]\n"
    "  --png DIR     input | labels of each mode | truth, for the last frame of every segment\n"
    "                (scene_SSSSS_frame_FFF.png; DIR is made if missing)\n"
    "  --false-pixels  also where each class's false pixels lie: in cells the ceiling gives the class\n"
    "                too, in the hall's cells, in other classes' cells; clipped (slower)\n"
    "  --self-mask   each scene's calibration carries its mirror struts as the self mask (as after\n"
    "                act_replay --learn-self-mask, at best): they train nothing and are labelled black\n"
    "  --learn-self-mask  the self mask learned first, as a team does it: a drive over the field\n"
    "                (24 random poses, the scene's first light) with core::SelfMaskLearner\n";

int usage(const std::string& message) {
  std::cerr << "act_eval: " << message << "\n" << kUsage;
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  uint32_t first = sim::kReportSeedsBegin, end = sim::kReportSeedsEnd;
  long count = -1;
  sim::ScenarioLength length = sim::ScenarioLength::kSmall;
  bool ablate = false, per_scene = false;
  sim::LightEvents light_events = sim::LightEvents::kGlobal;
  sim::EvalOptions options;
  std::vector<std::string> overrides;  // --set name=value
  std::vector<std::string> extra_modes;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
        return argv[++i];
      };
      if (arg == "--help" || arg == "-h") {
        std::cout << kUsage;
        return 0;
      } else if (arg == "--split") {
        const std::string s = value();
        if (s == "report") {
          first = sim::kReportSeedsBegin;
          end = sim::kReportSeedsEnd;
        } else if (s == "tuning") {
          first = sim::kTuningSeedsBegin;
          end = sim::kTuningSeedsEnd;
        } else {
          return usage("--split is report or tuning, not '" + s + "'");
        }
      } else if (arg == "--seeds") {
        const std::string s = value();
        const size_t dash = s.find('-');
        if (dash == std::string::npos) return usage("--seeds wants A-B");
        first = static_cast<uint32_t>(std::stoul(s.substr(0, dash)));
        end = static_cast<uint32_t>(std::stoul(s.substr(dash + 1))) + 1;
        if (end <= first) return usage("--seeds: B must not be below A");
      } else if (arg == "--count") {
        count = std::stol(value());
        if (count < 1) return usage("--count must be at least 1");
      } else if (arg == "--length") {
        if (!sim::parseScenarioLength(value(), &length)) return usage("--length is small or full");
      } else if (arg == "--ablate") {
        ablate = true;
      } else if (arg == "--local-light") {
        light_events = sim::LightEvents::kLocal;
      } else if (arg == "--per-scene") {
        per_scene = true;
      } else if (arg == "--set") {
        overrides.push_back(value());
      } else if (arg == "--mode") {
        extra_modes.push_back(value());
      } else if (arg == "--png") {
        options.png_dir = value();
      } else if (arg == "--false-pixels") {
        options.false_pixels = true;
      } else if (arg == "--self-mask") {
        options.self_mask = sim::SelfMaskSource::kStruts;
      } else if (arg == "--learn-self-mask") {
        options.self_mask = sim::SelfMaskSource::kLearnedOnDrive;
      } else {
        return usage("unknown option " + arg);
      }
    }
  } catch (const std::exception& e) {
    return usage(e.what());
  }
  if (count > 0 && first + static_cast<uint32_t>(count) < end) end = first + static_cast<uint32_t>(count);

  const auto start = std::chrono::steady_clock::now();
  std::vector<sim::EvalMode> modes = sim::evalModes(ablate);
  try {
    for (auto& m : modes) {
      if (m.name == "paper") continue;
      for (const std::string& assignment : overrides) m.params.assign(assignment);
      m.params.validate();
    }
    // --mode NAME:a=1,b=2 : the defaults (with --set) and these parameters.
    const core::ActParams base = modes.front().params;
    for (const std::string& text : extra_modes) {
      const size_t colon = text.find(':');
      sim::EvalMode m{text.substr(0, colon), base};
      std::string rest = colon == std::string::npos ? "" : text.substr(colon + 1);
      while (!rest.empty()) {
        const size_t comma = rest.find(',');
        m.params.assign(rest.substr(0, comma));
        rest = comma == std::string::npos ? "" : rest.substr(comma + 1);
      }
      m.params.validate();
      modes.push_back(m);
    }
  } catch (const std::invalid_argument& e) {
    return usage(e.what());
  }
  if (std::string error; !options.png_dir.empty() && !core::makeFolder(options.png_dir, &error)) {
    return usage("--png: " + error);
  }
  std::vector<sim::SceneResult> results;
  double render = 0, act = 0;
  size_t frames = 0;
  for (uint32_t seed = first; seed < end; ++seed) {
    const sim::FamilyScene scene = sim::makeFamilyScene(seed, length, true, light_events);
    try {
      results.push_back(sim::evaluateScene(scene, modes, options));
    } catch (const std::runtime_error& e) {
      std::cerr << "act_eval: " << e.what() << "\n";
      return 1;
    }
    render += results.back().render_seconds;
    act += results.back().act_seconds;
    frames += results.back().frames;
    if (per_scene) {
      std::cout << sim::formatScene(results.back());
      std::cout.flush();
    } else {
      std::cerr << "act_eval: seed " << seed << " done\r";
    }
  }
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::cout << "act_eval: seeds " << first << "-" << end - 1 << " (" << results.size() << " scenes, " << frames
            << " frames), modes:";
  for (const auto& m : modes) std::cout << " " << m.name;
  std::cout << "\n" << sim::formatReport(sim::summarize(results));
  char line[160];
  std::snprintf(line, sizeof(line), "act_eval: %.0f s (rendering %.0f s, ACT and classification %.0f s)\n", elapsed,
                render, act);
  std::cout << line;
  return 0;
}
