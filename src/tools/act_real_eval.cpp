// act_real_eval: ACT on real camera images (issue 12, item 4). For every folder given (or every
// folder of --dir) with an image (pic_save0.png) and, optionally, hand-picked line pixels
// (whites.txt): the camera calibration fitted to the image (as act_calibrate does: the field of a
// preset or of a calibration file, the robot at a rough pose), then ACT from
// that image at the fitted pose, and the image under five changes of light as 60-frame sequences
// with fresh noise, for the defaults and the paper side by side.
#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <string>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/file_io.hpp"
#include "act_color/core/mirror_calibrator.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/sim/real_image_suite.hpp"
#include "cli_numbers.hpp"

namespace {

void printUsage(std::ostream& out) {
  out << "usage: act_real_eval (--dir DIR | FOLDER...) [--image NAME]\n"
         "                    [--preset lab6x4|msl2007 | --field CAL.yaml | --calibration CAL.yaml]\n"
         "                    [--pose x,y,theta] [--height-m H] [--set NAME=VALUE] [--png DIR] [--frames]\n"
         "  --dir DIR      every folder of DIR that holds the image\n"
         "  FOLDER         a folder with the image and, optionally, whites.txt (hand-picked line pixels)\n"
         "                 and CTableBGR.dat (NuBot's hand-made table, compared with ACT's)\n"
         "  --image NAME   the image's file name in each folder (pic_save0.png)\n"
         "  --preset NAME  the field (lab6x4)\n"
         "  --field CAL.yaml  the field section of this calibration instead (your field)\n"
         "  --calibration CAL.yaml  this calibration (camera, field, self mask) instead of a fit; the\n"
         "                 robot stands at --pose exactly\n"
         "  --pose x,y,theta  the robot's rough pose (m, m, rad) in every image, for the fit (default\n"
         "                 0,0,0: on the centre spot facing +x, the yellow goal)\n"
         "  --height-m H   the camera's viewpoint height for the fit (default 0.7)\n"
         "  --png DIR      each image beside its classes (defaults) as PNGs: the frame before the change\n"
         "                 (NAME_classified.png) and the last frame of each variant (NAME_VARIANT.png)\n"
         "  --set NAME=VALUE  an ActParams parameter of the defaults (repeatable; e.g. seed=2)\n"
         "  --frames       also every frame's white recall, green recall, hall in a field class, hall\n"
         "                 as black and hall as a goal (after the change from frame 21), per variant and\n"
         "                 mode\n";
}

// An rgb8 frame beside its labels in the palette, as one PNG; false (and a message) when it
// cannot be written.
bool writeClassified(const std::string& path, const cv::Mat& frame_rgb, const cv::Mat& labels) {
  cv::Mat bgr, colored, out;
  cv::cvtColor(frame_rgb, bgr, cv::COLOR_RGB2BGR);
  act_color::core::colorizeLabels(labels, colored);
  cv::cvtColor(colored, colored, cv::COLOR_RGB2BGR);
  cv::hconcat(bgr, colored, out);
  if (cv::imwrite(path, out)) return true;
  std::cerr << "act_real_eval: " << path << ": cannot be written\n";
  return false;
}

bool isFile(const std::string& path) {
  struct stat st {};
  return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> folders;
  std::string dir, png_dir, image_name = "pic_save0.png", preset, field_path, calibration_path;
  std::optional<act_color::core::Calibration> calibration;
  bool height_given = false;
  act_color::core::MirrorCalibratorOptions calibrator;
  act_color::core::FieldCalibration field;
  bool frames = false;
  act_color::core::ActParams defaults;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
        return argv[++i];
      };
      if (arg == "--help" || arg == "-h") {
        printUsage(std::cout);
        return 0;
      } else if (arg == "--dir") {
        dir = value();
      } else if (arg == "--image") {
        image_name = value();
      } else if (arg == "--preset") {
        preset = value();
      } else if (arg == "--field") {
        field_path = value();
      } else if (arg == "--calibration") {
        calibration_path = value();
      } else if (arg == "--pose") {
        const auto p = act_color_tools::parseNumbers(value(), 3, arg);
        calibrator.pose = {p[0], p[1], p[2]};
      } else if (arg == "--height-m") {
        calibrator.height_m = act_color_tools::parseNumber(value(), arg);
        height_given = true;
        if (!(calibrator.height_m > 0 && calibrator.height_m < 10)) {
          throw std::invalid_argument("--height-m must be in (0, 10) m");
        }
      } else if (arg == "--png") {
        png_dir = value();
      } else if (arg == "--frames") {
        frames = true;
      } else if (arg == "--set") {
        defaults.assign(value());
        defaults.validate();
      } else if (!arg.empty() && arg[0] == '-') {
        throw std::invalid_argument("unknown option " + arg);
      } else {
        folders.push_back(arg);
      }
    }
    if (!dir.empty()) {
      DIR* d = opendir(dir.c_str());
      if (!d) throw std::invalid_argument(dir + ": cannot be read");
      std::vector<std::string> names;
      while (dirent* e = readdir(d)) {
        const std::string name = e->d_name;
        if (name != "." && name != ".." && isFile(dir + "/" + name + "/" + image_name)) names.push_back(name);
      }
      closedir(d);
      std::sort(names.begin(), names.end());
      for (const auto& n : names) folders.push_back(dir + "/" + n);
    }
    if (folders.empty()) throw std::invalid_argument("no folder with " + image_name);
    if (!preset.empty() + !field_path.empty() + !calibration_path.empty() > 1) {
      throw std::invalid_argument("give one of --preset, --field and --calibration");
    }
    if (!calibration_path.empty()) {
      if (height_given) throw std::invalid_argument("--height-m is the calibration's with --calibration");
      calibration = act_color::core::loadCalibration(calibration_path);
      field = calibration->field;
    } else {
      field = field_path.empty() ? act_color::core::fieldPreset(preset.empty() ? "lab6x4" : preset)
                                 : act_color::core::loadCalibration(field_path).field;
    }
  } catch (const std::exception& e) {
    std::cerr << "act_real_eval: " << e.what() << "\n";
    printUsage(std::cerr);
    return 2;
  }

  using act_color::core::ActParams;
  const std::vector<std::pair<std::string, ActParams>> modes = {{"defaults", defaults}, {"paper", ActParams::paper()}};
  std::vector<act_color::sim::RealImageResult> results;
  for (const std::string& folder : folders) {
    act_color::sim::RealImage image;
    const size_t slash = folder.find_last_of('/');
    image.name = (slash == std::string::npos ? folder : folder.substr(slash + 1)) + "/" + image_name;
    std::string error;
    if (!act_color::core::readImageFile(folder + "/" + image_name, cv::IMREAD_COLOR,
                                        act_color::core::kMaxImageFileBytes, act_color::core::kMaxImageSidePx,
                                        act_color::core::kMaxImagePixels, &image.bgr, &error)) {
      std::cerr << "act_real_eval: " << error << "\n";
      return 1;
    }
    try {
      if (isFile(folder + "/whites.txt")) image.whites = act_color::core::readNubotWhites(folder + "/whites.txt");
    } catch (const std::exception& e) {
      std::cerr << "act_real_eval: " << e.what() << "\n";
      return 1;
    }
    image.nubot_table = act_color::sim::readNubotTable(folder + "/CTableBGR.dat");
    act_color::sim::BallMark ball;
    if (act_color::sim::readBallMark(folder + "/ball.txt", &ball)) image.ball = ball;
    image.field = field;
    image.calibrator = calibrator;
    image.calibration = calibration;
    results.push_back(act_color::sim::evaluateRealImage(image, modes));
    const auto& r = results.back();
    if (!png_dir.empty() && !r.labels_before.empty()) {
      std::string stem = image.name;
      std::replace(stem.begin(), stem.end(), '/', '_');
      stem = png_dir + "/" + stem.substr(0, stem.rfind('.'));
      bool written = writeClassified(stem + "_classified.png", r.frame_before, r.labels_before);
      for (const auto& row : r.rows) {
        if (!row.labels_last.empty()) {
          written = written && writeClassified(stem + "_" + row.variant + ".png", row.frame_last, row.labels_last);
        }
      }
      if (!written) return 1;
    }
    std::cerr << "act_real_eval: " << image.name << " done\n";
  }
  std::cout << act_color::sim::formatRealImageReport(results) << act_color::sim::formatRealImageTargets(results);
  if (frames) std::cout << act_color::sim::formatRealImageFrames(results);
  return 0;
}
