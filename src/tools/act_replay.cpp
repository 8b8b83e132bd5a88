// act_replay: runs ACT and the segmentation over a recorded bag, without a ROS master.
// Usage: see printUsage() and README.md.
#include <ros/time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <string>

#include "act_color/core/calibration.hpp"
#include "act_color/core/self_mask_learner.hpp"
#include "act_color/ros/bag_replay.hpp"

namespace {

void printUsage(std::ostream& out) {
  out << "usage: act_replay --bag IN.bag --calibration CAL.yaml --output OUT.bag [options]\n"
         "  --image-topic T      images (default /omni/image_raw)\n"
         "  --pose-topic T       PoseWithCovarianceStamped of base_link in field (default /localization/pose)\n"
         "  --truth-topic T      mono8 truth labels, optional (default /omni/labels_truth)\n"
         "  --events-topic T     std_msgs/String events splitting the run (default /scenario/events)\n"
         "  --seed N             random start pixels (default 1)\n"
         "  --zeta X --xi X --eta X --sigma-min X\n"
         "  --cluster-stride N --add-stride N --remove-stride N --lut-bits N\n"
         "  --paper              the paper's algorithm exactly (every extension off)\n"
         "  --neighbourhood-cells N  an added color also adds cells within n cells (default 1)\n"
         "  --removal-protect-cycles N  cells confirmed in the field within n cycles are not removed (default 10)\n"
         "  --evidence-removal-ratio X  cells seen off the field X times as often as in it are removed (default 3, 0 "
         "off)\n"
         "  --no-nearest-mean    add colors to their class even when another class's mean is nearer\n"
         "  --set NAME=VALUE     any ACT parameter by its name (as in ActParams and the nodelet's parameters)\n"
         "  --bootstrap-cycles N cycles on the first image with a pose (default 100)\n"
         "  --lut-every N        write /act/color_lut with every n-th frame (default 1)\n"
         "  --adapt-frames N     frames after each event left out of the *_ad figures (default 12)\n"
         "  --csv FILE           per-frame recall and precision per class\n"
         "  --learn-self-mask F  learn the own robot's pixels (struts, cables), use them from the 8th distinct pose\n"
         "                       on (as the trainer's ~learn_self_mask) and write them to the PNG F\n"
         "  --png DIR            input | classified | truth as PNG for every n-th frame (--png-every N, 10;\n"
         "                       DIR is made if missing)\n"
         "  --no-progress        no progress lines on stderr\n"
         "  --brief              a short accuracy summary instead of the full report\n";
}

}  // namespace

int main(int argc, char** argv) {
  ros::Time::init();
  act_color::ros_layer::ReplayOptions options;
  bool brief = false;
  auto& p = options.params;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
        return argv[++i];
      };
      // Read whole and checked: "abc", "1e400" or "-1" where a count goes are refused by name.
      auto number = [&]() {
        const std::string text = value();
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        if (text.empty() || *end != '\0' || !std::isfinite(v)) {
          throw std::invalid_argument(arg + ": '" + text + "' is not a finite number");
        }
        return v;
      };
      auto integer = [&](long long lo = std::numeric_limits<int>::min(),
                         long long hi = std::numeric_limits<int>::max()) {
        const std::string text = value();
        char* end = nullptr;
        errno = 0;
        const long long v = std::strtoll(text.c_str(), &end, 10);
        if (text.empty() || *end != '\0' || errno == ERANGE || v < lo || v > hi) {
          throw std::invalid_argument(arg + ": '" + text + "' is not an integer in [" + std::to_string(lo) + ", " +
                                      std::to_string(hi) + "]");
        }
        return v;
      };
      constexpr long long kManyFrames = 1000000000;
      if (arg == "--help" || arg == "-h") {
        printUsage(std::cout);
        return 0;
      } else if (arg == "--bag") {
        options.input_bag = value();
      } else if (arg == "--calibration") {
        options.calibration = value();
      } else if (arg == "--output") {
        options.output_bag = value();
      } else if (arg == "--image-topic") {
        options.image_topic = value();
      } else if (arg == "--pose-topic") {
        options.pose_topic = value();
      } else if (arg == "--truth-topic") {
        options.truth_topic = value();
      } else if (arg == "--events-topic") {
        options.events_topic = value();
      } else if (arg == "--seed") {
        p.seed = static_cast<uint32_t>(integer(0, std::numeric_limits<uint32_t>::max()));
      } else if (arg == "--zeta") {
        p.zeta = number();
      } else if (arg == "--xi") {
        p.xi = number();
      } else if (arg == "--eta") {
        p.eta = number();
      } else if (arg == "--sigma-min") {
        p.sigma_min = number();
      } else if (arg == "--cluster-stride") {
        p.cluster_stride = static_cast<int>(integer());
      } else if (arg == "--add-stride") {
        p.add_stride = static_cast<int>(integer());
      } else if (arg == "--remove-stride") {
        p.remove_stride = static_cast<int>(integer());
      } else if (arg == "--lut-bits") {
        p.lut_bits = static_cast<int>(integer());
      } else if (arg == "--paper") {
        p.switchOffExtensions();
      } else if (arg == "--neighbourhood-cells") {
        p.add_neighbourhood_cells = static_cast<int>(integer());
      } else if (arg == "--removal-protect-cycles") {
        p.removal_protect_cycles = static_cast<int>(integer());
      } else if (arg == "--evidence-removal-ratio") {
        p.evidence_removal_ratio = number();
      } else if (arg == "--set") {
        p.assign(value());
      } else if (arg == "--no-nearest-mean") {
        p.nearest_mean = false;
      } else if (arg == "--bootstrap-cycles") {
        options.bootstrap_cycles = static_cast<int>(integer(0, 100000));
      } else if (arg == "--lut-every") {
        options.lut_every = static_cast<size_t>(integer(1, kManyFrames));
      } else if (arg == "--adapt-frames") {
        options.adapt_frames = static_cast<size_t>(integer(0, kManyFrames));
      } else if (arg == "--csv") {
        options.csv_path = value();
      } else if (arg == "--png") {
        options.png_dir = value();
      } else if (arg == "--png-every") {
        options.png_every = static_cast<size_t>(integer(1, kManyFrames));
      } else if (arg == "--learn-self-mask") {
        options.self_mask_png = value();
      } else if (arg == "--brief") {
        brief = true;
      } else if (arg == "--no-progress") {
        options.progress = false;
      } else {
        throw std::invalid_argument("unknown option " + arg);
      }
    }
    if (options.input_bag.empty() || options.calibration.empty() || options.output_bag.empty()) {
      throw std::invalid_argument("--bag, --calibration and --output are required");
    }
    p.validate();
  } catch (const std::exception& e) {
    std::cerr << "act_replay: " << e.what() << "\n";
    printUsage(std::cerr);
    return 2;
  }

  try {
    const auto result = act_color::ros_layer::runReplay(options, std::cerr);
    std::cout << "act_replay: " << result.images << " frames from " << options.input_bag << " (" << result.trained
              << " trained, " << result.without_pose << " without a usable pose, " << result.unusable_images
              << " unusable images, " << result.with_truth << " with truth); wrote " << options.output_bag << "\n";
    if (result.pose_contradicted > 0) {
      std::cout << "act_replay: " << result.pose_contradicted << " of the " << result.trained
                << " trained frames trained nothing: the table contradicted their pose (pose_check)\n";
    }
    if (result.truth_left_out > 0) {
      const size_t bad_image = result.truth_left_out - result.unusable_truth;
      std::cout << "act_replay: warning: " << result.truth_left_out << " of "
                << result.truth_left_out + result.with_truth << " frames with truth left out of the metrics (";
      if (result.unusable_truth) std::cout << result.unusable_truth << " with a truth image that does not fit";
      if (result.unusable_truth && bad_image) std::cout << ", ";
      if (bad_image) std::cout << bad_image << " with an unusable image";
      std::cout << "; see the warnings on stderr)\n";
    }
    if (!options.self_mask_png.empty()) {
      std::printf(
          "act_replay: self mask learned from %d poses: %.2f%% of the imaged pixels; wrote %s (set camera.self_mask "
          "to it)\n",
          result.self_mask_poses, 100.0 * result.self_mask_fraction, options.self_mask_png.c_str());
      if (result.self_masks_used > 0) {
        std::printf(
            "act_replay: the learned mask was used from frame %zu on (as the trainer's ~learn_self_mask does), "
            "taken over %zu times, last %zu px\n",
            result.self_mask_first_frame, result.self_masks_used, result.self_mask_used_pixels);
      }
      if (result.self_mask_poses < act_color::core::SelfMaskLearner::kMinPosesForConstancy) {
        std::printf(
            "act_replay: fewer than %d distinct poses (%.2f m or %.0f deg apart): only the parts over the field were "
            "learned; a longer drive also finds where they cross the hall\n",
            act_color::core::SelfMaskLearner::kMinPosesForConstancy, act_color::core::SelfMaskLearner::kMinMoveM,
            act_color::core::SelfMaskLearner::kMinTurnRad * 180.0 / M_PI);
      }
    }
    if (result.with_truth > 0) {
      std::cout << (brief ? result.evaluation.brief() : result.evaluation.report());
    } else {
      std::cout << "act_replay: no frame with truth on " << options.truth_topic << ": no metrics\n";
    }
    std::cout << std::flush;
    if (result.images == result.unusable_images) {
      std::cerr << "act_replay: none of the " << result.images << " images of " << options.input_bag
                << " is usable (see the warnings above)\n";
      return 1;
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "act_replay: " << e.what() << "\n";
    return 1;
  }
}
