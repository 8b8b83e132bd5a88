#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/types.hpp"

namespace act_color {
namespace core {

// The camera calibration from one image of the field with the robot at a roughly known pose (the
// paper's automatic pixel-to-world training "using the field markings and a predefined pose of the
// robot", its section 2): line pixels found in the image are mapped to the floor and the mirror
// centre, the elevation profile, the bearing and the pose are fitted so that they fall on the
// field model's lines.
//
// One image cannot tell the heading from the bearing offset (only their sum is seen), so one of
// them is taken as given: by default the heading (the pose's theta) and the bearing offset is
// fitted; with `bearing_offset_rad` set, the offset is kept and the heading refined. On a pose on
// the field's long axis the field's mirror symmetry hides the bearing sign: then the sign prior
// is used (and the fit says so); the field's point symmetry about the centre spot is resolved by
// the goal colors.
struct MirrorCalibratorOptions {
  Pose2D pose;  // rough pose of base_link in the field frame
  double position_tolerance_m = 0.5;
  double heading_tolerance_rad = 20.0 * 3.14159265358979323846 / 180.0;
  double height_m = 0.7;                     // viewpoint height; the elevation map is fitted for it
  std::optional<Eigen::Vector2d> center_px;  // hints: mirror centre (u, v) as a start ...
  std::optional<double> mirror_radius_px;    // ... and the radii, used as given
  std::optional<double> chassis_radius_px;
  std::optional<int> bearing_sign;           // fixed instead of fitted
  int bearing_sign_prior = 1;                // when the image cannot tell (see above)
  std::optional<double> bearing_offset_rad;  // fixed: the heading is refined instead
  // Rejection: an image whose fit is worse than this is refused. Residual and inliers count the
  // line pixels that land on the carpet (field and margin). Line pixels have carpet on both sides:
  // a right fit takes 0.8-1.0 of them for inliers (NuBot's images, simulated cameras), most
  // wrong fits seen 0.43-0.62.
  double max_median_residual_m = 0.05;
  double min_inlier_fraction = 0.7;
  int min_line_pixels = 150;
  double inlier_distance_m = 0.08;  // a line pixel this close to a model line is an inlier
  std::string profile = "auto";     // "tan", "monotone" or "auto": the one with the smaller residual
  // Fraction of carpet pixels the fit may put on painted lines: right fits put 0-0.5% there on
  // simulated cameras and 0-0.1% on NuBot's images (nubot_2 1.7% fitted upright, 0.1% with its
  // tilt, camera.tilt); two half-turn fits of random cameras 2.2% and 2.4% (bearing 173 and 180 degrees off),
  // written under the former 3%.
  double max_carpet_on_lines = 0.02;
};

// Mirror centre and radii as seen in the image (before the line fit).
struct ImageGeometry {
  Eigen::Vector2d center_px{0.0, 0.0};
  double mirror_radius_px = 0.0;
  double chassis_radius_px = 0.0;
  bool chassis_found = false;  // centre and chassis radius from the chassis seen (else guessed)
};

// Distance of line pixels to the field model's lines under a calibration and pose.
struct LineResidual {
  size_t pixels = 0;     // line pixels that look at the floor under the calibration
  size_t on_carpet = 0;  // of them, landing on the carpet (field and margin)
  size_t total = 0;      // all line pixels given
  // Median distance to the nearest model line of the pixels on the carpet (hall clutter beyond
  // it is no field line; +inf when none).
  double median_m = 0.0;
  double inlier_fraction = 0.0;         // fraction of all line pixels within the inlier distance
  double carpet_inlier_fraction = 0.0;  // the same of the pixels on the carpet
};

struct MirrorFit {
  Calibration calibration;                   // camera fitted, field as given
  Pose2D pose;                               // refined pose
  std::string profile;                       // "tan" (d = a tan(b r)) or "monotone" (piecewise linear elevation)
  double tan_a_m = 0.0, tan_b_per_px = 0.0;  // the best a tan(b r) fit (also when not chosen)
  double tan_median_m = 0.0, monotone_median_m = 0.0;  // median residual of either profile
  // RMS distance to the lines' middles over the line pixels both profiles take for inliers: the
  // profile with the smaller one is chosen (the monotone one only when 5% smaller).
  double tan_rms_m = 0.0, monotone_rms_m = 0.0;
  LineResidual residual;         // of the chosen profile
  double carpet_on_lines = 0.0;  // fraction of carpet pixels that land on a painted model line
  // How much of the model's lines line pixels cover, upright and with the tilt free (camera.tilt:
  // taken when clearly more; both 0 when the upright fit would be refused and no tilt was tried).
  double upright_coverage = 0.0, tilted_coverage = 0.0;
  std::vector<cv::Point2f> line_pixels;  // candidates found in the image
  ImageGeometry image_geometry;
  std::vector<std::string> notes;  // what was assumed (sign prior, goal colors, ...)
};

// Thrown when an image cannot be fitted; the message says why.
class CalibrationFitError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class MirrorCalibrator {
 public:
  MirrorCalibrator(const FieldCalibration& field, const MirrorCalibratorOptions& options);

  // Fits the camera to a BGR image (8-bit, 3 channels). Throws CalibrationFitError when the image
  // shows too few line pixels or no fit within the options' residual and inlier limits.
  MirrorFit fit(const cv::Mat& bgr) const;
  // The same without the residual checks (it still throws for too few line pixels): for a look
  // at the overlay of a fit that would be refused. rejection() says why it would be ("" if not).
  MirrorFit fitUnchecked(const cv::Mat& bgr) const;
  std::string rejection(const MirrorFit& fit) const;

  // The steps of fit, for tests and tools.
  ImageGeometry estimateImageGeometry(const cv::Mat& bgr) const;
  // Thin bright unsaturated pixels next to green carpet between the chassis and the mirror rim.
  std::vector<cv::Point2f> findLinePixels(const cv::Mat& bgr, const ImageGeometry& geometry) const;
  LineResidual residual(const CameraCalibration& camera, const Pose2D& pose,
                        const std::vector<cv::Point2f>& pixels) const;

 private:
  FieldCalibration field_;
  MirrorCalibratorOptions options_;
};

// The image with the field model's lines (magenta) drawn where the calibration and pose see them,
// line pixels (inliers cyan, outliers red; may be empty), the mirror rim, chassis circle and centre.
cv::Mat drawCalibrationOverlay(const cv::Mat& bgr, const Calibration& calibration, const Pose2D& pose,
                               const std::vector<cv::Point2f>& line_pixels, double inlier_distance_m);

// Field presets: "msl2007" (18 x 12 m) and "lab6x4" (a 6 x 4 m lab field). Throws
// std::invalid_argument for another name.
FieldCalibration fieldPreset(const std::string& name);
const std::vector<std::string>& fieldPresetNames();

// A NuBot omni_vision mirror fit (mirror_calib.xml: center_coloum, center_row, ground distance
// m = para_a * tan(para_b * r)) in the contract's camera format: the elevation map sampled densely
// from the model for the given height, up to the mirror radius (ROI.xml's big_radius when given,
// else the radius where the model reaches the horizon or max_radius). Throws CalibrationError for a
// missing, malformed or implausible value (e.g. a fit of another model).
// NuBot's hand-picked white line pixels (whites.txt: `x y`, column and row, per line). Throws
// std::runtime_error when the file cannot be read or holds no pixel.
std::vector<cv::Point2f> readNubotWhites(const std::string& path);

// The image geometry a calibration states (centre and radii), e.g. to find line pixels with it.
ImageGeometry imageGeometryOf(const CameraCalibration& camera);

CameraCalibration importNubotMirror(const std::string& mirror_xml_path, const std::string& roi_xml_path, int width,
                                    int height, double height_m);

}  // namespace core
}  // namespace act_color
