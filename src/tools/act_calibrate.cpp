// act_calibrate: the camera calibration from one image of the field with the robot at a roughly
// known pose (core::MirrorCalibrator), or a NuBot mirror fit imported; see README.md.
//   act_calibrate --image IMG (--field CAL.yaml | --preset NAME) [--pose x,y,theta] [--height-m H]
//                 [--center u,v] [--mirror-radius PX] [--chassis-radius PX] [--bearing-sign S]
//                 [--bearing-offset RAD] [--output CAL.yaml] [--overlay OUT.png] [--whites FILE]
//   act_calibrate --nubot mirror_calib.xml [--roi ROI.xml] (--image IMG | --size WxH) ...
//   act_calibrate --check CAL.yaml --image IMG [--pose x,y,theta] [--whites FILE] [--overlay OUT.png]
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/file_io.hpp"
#include "act_color/core/mirror_calibrator.hpp"
#include "act_color/sim/calibrator_check.hpp"
#include "cli_numbers.hpp"
#include "seed_range.hpp"

namespace {

namespace core = act_color::core;

const char* const kUsage =
    "usage: act_calibrate --image IMG (--field CAL.yaml | --preset NAME) [options]   fit the camera\n"
    "       act_calibrate --nubot mirror_calib.xml [--roi ROI.xml] (--image IMG | --size WxH)\n"
    "                     (--field CAL.yaml | --preset NAME) [options]             import a NuBot fit\n"
    "       act_calibrate --check CAL.yaml --image IMG [options]                   measure a calibration\n"
    "       act_calibrate --family A-B      fit the simulator's random cameras of seeds A-B (truth known)\n"
    "  --field CAL.yaml      copy the field section of this calibration\n"
    "  --preset NAME         msl2007 (18 x 12 m) or lab6x4 (6 x 4 m lab field)\n"
    "  --pose x,y,theta      rough pose (m, m, rad) of the robot; default 0,0,0: on the centre\n"
    "                        spot facing the yellow goal; may be 0.5 m and 20 degrees off\n"
    "  --height-m H          viewpoint height above the floor (default 0.7); the elevation map is\n"
    "                        fitted for it (ground distances depend on height and elevation jointly)\n"
    "  --center u,v          start the mirror centre here instead of at the chassis found\n"
    "  --mirror-radius PX    the mirror's rim, instead of the one found\n"
    "  --chassis-radius PX   the own chassis, instead of the one found\n"
    "  --bearing-sign S      1 or -1 instead of fitting it (used when the image cannot tell; default 1)\n"
    "  --bearing-offset RAD  keep this offset and refine the heading instead\n"
    "  --profile P           tan (d = a tan(b r)), monotone (piecewise linear elevation) or auto\n"
    "                        (default: the monotone one when its residual is 5% smaller)\n"
    "  --max-residual M      reject above this median line-pixel residual (default 0.05 m)\n"
    "  --min-inliers F       reject below this fraction of line pixels on the carpet within 0.08 m\n"
    "                        (default 0.7)\n"
    "  --max-carpet-on-lines F  reject when more of the carpet lands on the model's lines (default 0.02)\n"
    "  --output CAL.yaml     write the calibration (validated first)\n"
    "  --overlay OUT.png     the image with the model's lines (magenta) and the line pixels found\n"
    "  --whites FILE         also measure hand-picked line pixels ('x y' per line, NuBot's whites.txt)\n"
    "  --height-m applies to --nubot too (their fit gives ground distances for any height).\n";

int usage(const std::string& message) {
  std::cerr << "act_calibrate: " << message << "\n" << kUsage;
  return 2;
}

using act_color_tools::parseNumber;
using act_color_tools::parseNumbers;

void printResidual(const std::string& what, const core::LineResidual& r) {
  std::printf(
      "%s: median %.3f m to the model's lines and inliers (<= 0.08 m) %.3f of the %zu on the carpet; inliers %.3f of "
      "all %zu, %zu on the floor\n",
      what.c_str(), r.median_m, r.carpet_inlier_fraction, r.on_carpet, r.inlier_fraction, r.total, r.pixels);
}

}  // namespace

// --family A-B: the calibrator on the randomized family's cameras, against their true calibration.
int checkFamily(const std::string& range) {
  uint32_t first = 0, last = 0;
  if (!act_color_tools::parseSeedRange(range, &first, &last, 1001)) {
    return usage("--family wants A-B (seeds), not '" + range + "' (A <= B, at most 1001 seeds)");
  }
  std::vector<act_color::sim::CalibratorCheck> checks;
  for (uint32_t seed = first; seed <= last; ++seed) {
    checks.push_back(act_color::sim::checkCalibrator(seed));
    std::cerr << "act_calibrate: seed " << seed << (checks.back().passed() ? " within the targets\n" : " off\n");
  }
  std::cout << act_color::sim::formatCalibratorChecks(checks);
  return 0;
}

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "--family") {
    if (argc != 3) return usage("--family takes one range A-B and no other option");
    return checkFamily(argv[2]);
  }
  std::string image_path, field_path, preset, output, overlay, whites, nubot, roi, check;
  int size_w = 0, size_h = 0;
  core::MirrorCalibratorOptions options;
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
      } else if (arg == "--image") {
        image_path = value();
      } else if (arg == "--field") {
        field_path = value();
      } else if (arg == "--preset") {
        preset = value();
      } else if (arg == "--pose") {
        const auto p = parseNumbers(value(), 3, arg);
        options.pose = {p[0], p[1], p[2]};
      } else if (arg == "--height-m") {
        options.height_m = parseNumber(value(), arg);
        if (!(options.height_m > 0)) throw std::invalid_argument("--height-m must be positive");
      } else if (arg == "--center") {
        const auto p = parseNumbers(value(), 2, arg);
        options.center_px = Eigen::Vector2d(p[0], p[1]);
      } else if (arg == "--mirror-radius") {
        options.mirror_radius_px = parseNumber(value(), arg);
      } else if (arg == "--chassis-radius") {
        options.chassis_radius_px = parseNumber(value(), arg);
      } else if (arg == "--bearing-sign") {
        const double s = parseNumber(value(), arg);
        if (s != 1 && s != -1) throw std::invalid_argument("--bearing-sign must be 1 or -1");
        options.bearing_sign = static_cast<int>(s);
        options.bearing_sign_prior = static_cast<int>(s);
      } else if (arg == "--bearing-offset") {
        options.bearing_offset_rad = parseNumber(value(), arg);
      } else if (arg == "--max-residual") {
        options.max_median_residual_m = parseNumber(value(), arg);
      } else if (arg == "--min-inliers") {
        options.min_inlier_fraction = parseNumber(value(), arg);
      } else if (arg == "--profile") {
        options.profile = value();
        if (options.profile != "auto" && options.profile != "tan" && options.profile != "monotone") {
          throw std::invalid_argument("--profile must be auto, tan or monotone");
        }
      } else if (arg == "--max-carpet-on-lines") {
        options.max_carpet_on_lines = parseNumber(value(), arg);
      } else if (arg == "--output") {
        output = value();
      } else if (arg == "--overlay") {
        overlay = value();
      } else if (arg == "--whites") {
        whites = value();
      } else if (arg == "--nubot") {
        nubot = value();
      } else if (arg == "--roi") {
        roi = value();
      } else if (arg == "--check") {
        check = value();
      } else if (arg == "--size") {
        const std::string s = value();
        if (std::sscanf(s.c_str(), "%dx%d", &size_w, &size_h) != 2 || size_w < 16 || size_h < 16) {
          throw std::invalid_argument("--size needs WxH, e.g. 640x480");
        }
      } else {
        return usage("unknown option " + arg);
      }
    }
  } catch (const std::exception& e) {
    return usage(e.what());
  }

  try {
    core::Calibration calibration;
    if (!check.empty()) {
      calibration = core::loadCalibration(check);
    } else {
      if (field_path.empty() == preset.empty()) return usage("give either --field or --preset");
      calibration.field = preset.empty() ? core::loadCalibration(field_path).field : core::fieldPreset(preset);
    }
    cv::Mat image;
    if (!image_path.empty()) {
      // BGR, as OpenCV writes PNGs; a regular file, its size checked before it is decoded.
      std::string error;
      if (!core::readImageFile(image_path, cv::IMREAD_COLOR, core::kMaxImageFileBytes, core::kMaxImageSidePx,
                               core::kMaxImagePixels, &image, &error)) {
        throw std::runtime_error(error);
      }
    }
    core::MirrorCalibrator calibrator(calibration.field, options);
    core::Pose2D pose = options.pose;
    std::vector<cv::Point2f> line_pixels;
    std::string rejected;  // why the fit is refused; its overlay is still written

    if (!check.empty()) {
      if (image.empty()) return usage("--check needs --image");
      if (image.cols != calibration.camera.width || image.rows != calibration.camera.height) {
        throw std::runtime_error(image_path + ": " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                                 " but " + check + " is for " + std::to_string(calibration.camera.width) + "x" +
                                 std::to_string(calibration.camera.height));
      }
      line_pixels = calibrator.findLinePixels(image, core::imageGeometryOf(calibration.camera));
      printResidual("line pixels found", calibrator.residual(calibration.camera, pose, line_pixels));
    } else if (!nubot.empty()) {
      int w = size_w, h = size_h;
      if (!image.empty()) w = image.cols, h = image.rows;
      if (w <= 0) return usage("--nubot needs --image or --size for the image size");
      calibration.camera = core::importNubotMirror(nubot, roi, w, h, options.height_m);
      std::printf("imported %s: centre (%.1f, %.1f), %zu elevation entries up to r = %.0f px\n", nubot.c_str(),
                  calibration.camera.center_u, calibration.camera.center_v, calibration.camera.elevation_map.size(),
                  calibration.camera.mirror_radius_px);
      if (!image.empty()) {
        line_pixels = calibrator.findLinePixels(image, core::imageGeometryOf(calibration.camera));
        printResidual("line pixels found", calibrator.residual(calibration.camera, pose, line_pixels));
      }
    } else {
      if (image.empty()) return usage("give --image (or --nubot, --check)");
      const core::MirrorFit fit = calibrator.fitUnchecked(image);
      calibration = fit.calibration;
      pose = fit.pose;
      line_pixels = fit.line_pixels;
      const auto& c = calibration.camera;
      const core::ImageGeometry& g = fit.image_geometry;
      std::printf("image: mirror centre (%.1f, %.1f) %s, rim %.0f px, chassis %.0f px; %zu line pixels\n",
                  g.center_px.x(), g.center_px.y(), g.chassis_found ? "from the chassis" : "guessed (no chassis found)",
                  g.mirror_radius_px, g.chassis_radius_px, fit.line_pixels.size());
      std::printf(
          "profile: %s (RMS to the lines' middles over common inliers: a tan(b r) %.4f m with a = %.3f m, b = %.6f "
          "/px; "
          "monotone %.4f m)\n",
          fit.profile.c_str(), fit.tan_rms_m, fit.tan_a_m, fit.tan_b_per_px, fit.monotone_rms_m);
      std::printf(
          "camera: centre (%.1f, %.1f), bearing sign %d, offset %.4f rad, chassis %.0f px, mirror %.0f px, tilt [%.4f, "
          "%.4f] rad (coverage of the model's lines upright %.3f, tilted %.3f)\n",
          c.center_u, c.center_v, c.bearing_sign, c.bearing_offset_rad, c.chassis_radius_px, c.mirror_radius_px,
          c.tilt_x_rad, c.tilt_y_rad, fit.upright_coverage, fit.tilted_coverage);
      std::printf("pose: %.3f, %.3f, %.4f\n", pose.x_m, pose.y_m, pose.theta_rad);
      for (const std::string& note : fit.notes) std::printf("note: %s\n", note.c_str());
      printResidual("residual", fit.residual);
      std::printf("carpet pixels on the model's lines: %.1f%%\n", 100 * fit.carpet_on_lines);
      rejected = calibrator.rejection(fit);
    }
    if (!whites.empty()) {
      printResidual("whites " + whites, calibrator.residual(calibration.camera, pose, core::readNubotWhites(whites)));
    }
    if (!overlay.empty()) {
      if (image.empty()) return usage("--overlay needs --image");
      if (!cv::imwrite(overlay, core::drawCalibrationOverlay(image, calibration, pose, line_pixels, 0.08))) {
        throw std::runtime_error(overlay + ": cannot be written");
      }
    }
    if (!rejected.empty()) throw core::CalibrationFitError(rejected + (overlay.empty() ? "" : "; see " + overlay));
    if (!output.empty()) {
      core::validateCalibration(calibration, output);
      std::ofstream file(output);
      file << "# written by act_calibrate";
      if (!image_path.empty()) file << " from " << image_path;
      file << "; pose " << pose.x_m << ", " << pose.y_m << ", " << pose.theta_rad << "\n" << core::toYaml(calibration);
      if (!file) throw std::runtime_error(output + ": cannot be written");
      std::printf("wrote %s\n", output.c_str());
    }
  } catch (const core::CalibrationFitError& e) {
    std::cerr << "act_calibrate: " << image_path << ": " << e.what() << "; nothing written\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "act_calibrate: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
