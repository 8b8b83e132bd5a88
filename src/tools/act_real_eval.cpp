// act_real_eval: ACT on real camera images (issue 12, item 4). For every folder given (or every
// folder of --dir) with an image (pic_save0.png) and, optionally, hand-picked line pixels
// (whites.txt): the camera calibration fitted to the image (as act_calibrate does: the field of a
// preset or of a calibration file, the robot at a rough pose), then ACT from
// that image at the fitted pose, and the image under five changes of light as 60-frame sequences
// with fresh noise, for the defaults and the paper side by side. A folder may hold its own setup
// (act_real_eval.args: the image's name, the field, the rough pose, the height), over the command
// line's.
#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
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
         "  FOLDER         a folder with the image and, optionally, whites.txt (hand-picked line pixels),\n"
         "                 CTableBGR.dat (NuBot's hand-made table, compared with ACT's) and\n"
         "                 act_real_eval.args: options for this folder over the command line's (--image,\n"
         "                 --preset, --field, --calibration, --pose, --height-m; files relative to the\n"
         "                 folder; # starts a comment)\n"
         "  --image NAME   the image's file name in each folder (pic_save0.png)\n"
         "  --preset NAME  the field (lab6x4)\n"
         "  --field CAL.yaml  the field section of this calibration instead (your field)\n"
         "  --calibration CAL.yaml  this calibration (camera, field, self mask) instead of a fit; the\n"
         "                 robot stands at --pose exactly\n"
         "  --pose x,y,theta  the robot's rough pose (m, m, rad) in every image, for the fit (default\n"
         "                 0,0,0: on the centre spot facing +x, the yellow goal)\n"
         "  --height-m H   the camera's viewpoint height for the fit (default 0.7)\n"
         "  --png DIR      each image beside its classes (defaults) as PNGs: the frame before the change\n"
         "                 (NAME_classified.png) and the last frame of each variant (NAME_VARIANT.png);\n"
         "                 DIR is made if missing\n"
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

// What the evaluation of one folder needs besides the folder: from the command line, and from the
// folder's act_real_eval.args over it.
struct FolderSetup {
  std::string image_name = "pic_save0.png";
  // The field: at most one of a preset, a calibration's field section and a whole calibration.
  std::string preset, field_path, calibration_path;
  act_color::core::MirrorCalibratorOptions calibrator;
  bool height_given = false;
};

// Applies `arg` (taking its value from `value`) to the setup; false when it is no folder option.
// `fields` counts the field options given in one place (two are an error); a relative file name
// is taken relative to `base` (empty: as given).
bool applyFolderOption(const std::string& arg, const std::function<std::string()>& value, const std::string& base,
                       FolderSetup* s, int* fields) {
  auto path = [&](const std::string& name) {
    return base.empty() || name.rfind('/', 0) == 0 ? name : base + "/" + name;
  };
  if (arg == "--image") {
    s->image_name = value();
  } else if (arg == "--preset" || arg == "--field" || arg == "--calibration") {
    ++*fields;
    s->preset.clear();
    s->field_path.clear();
    s->calibration_path.clear();
    if (arg == "--preset") {
      s->preset = value();
    } else if (arg == "--field") {
      s->field_path = path(value());
    } else {
      s->calibration_path = path(value());
    }
  } else if (arg == "--pose") {
    const auto p = act_color_tools::parseNumbers(value(), 3, arg);
    s->calibrator.pose = {p[0], p[1], p[2]};
  } else if (arg == "--height-m") {
    s->calibrator.height_m = act_color_tools::parseNumber(value(), arg);
    s->height_given = true;
    if (!(s->calibrator.height_m > 0 && s->calibrator.height_m < 10)) {
      throw std::invalid_argument("--height-m must be in (0, 10) m");
    }
  } else {
    return false;
  }
  if (*fields > 1) throw std::invalid_argument("give one of --preset, --field and --calibration");
  return true;
}

// The folder's act_real_eval.args over the command line's setup; throws naming the file.
constexpr size_t kMaxFolderSetupBytes = 4096;
FolderSetup folderSetup(const std::string& folder, const FolderSetup& command_line) {
  FolderSetup s = command_line;
  const std::string file = folder + "/act_real_eval.args";
  if (!isFile(file)) return s;
  try {
    std::string bytes, error;
    if (!act_color::core::readRegularFile(file, kMaxFolderSetupBytes, &bytes, &error, "a folder's setup")) {
      throw std::invalid_argument(error);
    }
    std::istringstream in(bytes);
    std::vector<std::string> words;
    for (std::string line; std::getline(in, line);) {
      std::istringstream tokens(line.substr(0, line.find('#')));
      for (std::string w; tokens >> w;) words.push_back(w);
    }
    int fields = 0;
    for (size_t i = 0; i < words.size(); ++i) {
      auto value = [&]() -> std::string {
        if (i + 1 >= words.size()) throw std::invalid_argument(words[i] + " needs a value");
        return words[++i];
      };
      if (!applyFolderOption(words[i], value, folder, &s, &fields)) {
        throw std::invalid_argument("'" + words[i] + "' is no option for a folder");
      }
    }
  } catch (const std::exception& e) {
    throw std::invalid_argument(file + ": " + e.what());
  }
  return s;
}

// The field of a setup (a preset, a calibration's field) and the calibration to use as it is, if
// one is given.
void resolveField(const FolderSetup& s, act_color::core::FieldCalibration* field,
                  std::optional<act_color::core::Calibration>* calibration) {
  calibration->reset();
  if (!s.calibration_path.empty()) {
    if (s.height_given) throw std::invalid_argument("--height-m is the calibration's with --calibration");
    *calibration = act_color::core::loadCalibration(s.calibration_path);
    *field = (*calibration)->field;
  } else {
    *field = s.field_path.empty() ? act_color::core::fieldPreset(s.preset.empty() ? "lab6x4" : s.preset)
                                  : act_color::core::loadCalibration(s.field_path).field;
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> folders;
  std::string dir, png_dir;
  FolderSetup command_line;
  bool frames = false;
  act_color::core::ActParams defaults;
  try {
    int command_line_fields = 0;
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
      } else if (applyFolderOption(arg, value, "", &command_line, &command_line_fields)) {  // applied
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
    // The command line's field is checked before any folder is looked at.
    {
      act_color::core::FieldCalibration field;
      std::optional<act_color::core::Calibration> calibration;
      resolveField(command_line, &field, &calibration);
    }
    if (!dir.empty()) {
      DIR* d = opendir(dir.c_str());
      if (!d) throw std::invalid_argument(dir + ": cannot be read");
      std::vector<std::string> names;
      while (dirent* e = readdir(d)) {
        const std::string name = e->d_name;
        if (name != "." && name != "..") names.push_back(name);
      }
      closedir(d);
      std::sort(names.begin(), names.end());
      for (const auto& n : names) {
        const std::string folder = dir + "/" + n;
        if (!isFile(folder + "/act_real_eval.args") && !isFile(folder + "/" + command_line.image_name)) continue;
        folders.push_back(folder);
      }
    }
    if (folders.empty()) throw std::invalid_argument("no folder with " + command_line.image_name);
    if (std::string error; !png_dir.empty() && !act_color::core::makeFolder(png_dir, &error)) {
      throw std::invalid_argument("--png: " + error);
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
    FolderSetup setup;
    try {
      setup = folderSetup(folder, command_line);
      resolveField(setup, &image.field, &image.calibration);
    } catch (const std::exception& e) {
      std::cerr << "act_real_eval: " << e.what() << "\n";
      return 1;
    }
    if (!dir.empty() && !isFile(folder + "/" + setup.image_name)) continue;  // a folder of no image
    const size_t slash = folder.find_last_of('/');
    image.name = (slash == std::string::npos ? folder : folder.substr(slash + 1)) + "/" + setup.image_name;
    std::string error;
    if (!act_color::core::readImageFile(folder + "/" + setup.image_name, cv::IMREAD_COLOR,
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
    image.calibrator = setup.calibrator;
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
