#pragma once

#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace act_color {
namespace core {

// The camera-to-world mapping of the contract's calibration file.
// Largest camera image a calibration may describe (the per-pixel tables of the camera model are
// built for every pixel): 8192 px a side, 16 Mpx in all.
constexpr int kMaxImageSidePx = 8192;
constexpr int64_t kMaxImagePixels = int64_t{4096} * 4096;
// Largest tilt of the mirror axis a calibration may state (camera.tilt): 0.35 rad, 20 degrees; a
// mount askew by more is not a tilt to correct.
constexpr double kMaxTiltRad = 0.35;

struct CameraCalibration {
  int width = 0;
  int height = 0;
  double center_u = 0.0;
  double center_v = 0.0;
  int bearing_sign = 1;
  double bearing_offset_rad = 0.0;
  double height_m = 0.0;
  double chassis_radius_px = 0.0;
  double mirror_radius_px = 0.0;
  // (r_px, elevation_rad), both strictly increasing.
  std::vector<std::pair<double, double>> elevation_map;
  // Optional (camera.tilt): the mirror axis' tilt from the vertical, a rotation vector (about
  // base_link's x and y axes, rad) applied to every view ray the elevation map gives; a camera or
  // mirror mounted a degree or two askew sees one side of the field nearer than the other.
  double tilt_x_rad = 0.0;
  double tilt_y_rad = 0.0;
  double tiltRad() const { return std::hypot(tilt_x_rad, tilt_y_rad); }  // from the vertical
  // Optional: pixels that show the own robot wherever it stands (mirror struts, a cable), row-major,
  // 1 = own robot; empty = none. Read from the PNG `self_mask_file` names (key camera.self_mask,
  // relative to the calibration file); nonzero pixels of the PNG are the mask.
  std::string self_mask_file;
  std::vector<uint8_t> self_mask;
};

// 2007-rules MSL field geometry. Lengths to the outer edges of lines.
struct FieldCalibration {
  double length_m = 0.0;
  double width_m = 0.0;
  double line_width_m = 0.0;
  double margin_m = 0.0;
  double center_circle_radius_m = 0.0;
  double corner_arc_radius_m = 0.0;
  double goal_area_depth_m = 0.0;
  double goal_area_width_m = 0.0;
  double penalty_area_depth_m = 0.0;
  double penalty_area_width_m = 0.0;
  std::optional<double> penalty_mark_distance_m;
  // Optional penalty arc, as lab fields draw it: a circle of this radius (outer edge) centred on
  // the long axis at penalty_arc_center_m from the goal line's outer edge, drawn only outside the
  // penalty area (with the centre on the area's front line: a semicircle).
  std::optional<double> penalty_arc_radius_m;
  double penalty_arc_center_m = 0.0;
  double goal_width_m = 0.0;
  double goal_height_m = 0.0;
  double goal_depth_m = 0.0;    // a colored panel is a goal of small depth
  double goal_setback_m = 0.0;  // optional: gap between the goal line's outer edge and the goal
  int yellow_goal_x_sign = 1;
};

// Where a robot's pose may lie: the carpet (outer lines plus margin_m) and kPoseMarginM beyond it,
// as half extents about the centre spot; a pose outside is no robot's on this field.
constexpr double kPoseMarginM = 1.0;
struct PoseBounds {
  double half_x_m = 1e9, half_y_m = 1e9;
  explicit PoseBounds(const FieldCalibration& f)
      : half_x_m(0.5 * f.length_m + f.margin_m + kPoseMarginM), half_y_m(0.5 * f.width_m + f.margin_m + kPoseMarginM) {}
  PoseBounds() = default;
  // False with a reason for a pose outside.
  bool contains(double x_m, double y_m, std::string* why) const;
};

struct Calibration {
  CameraCalibration camera;
  FieldCalibration field;
};

// Thrown for a calibration that cannot be read or breaks a rule; the message names the file and
// the offending key (e.g. "cal.yaml: camera.elevation_map: r must increase strictly ...").
class CalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads and validates a calibration file. Unknown keys, missing keys, wrong types and values out
// of range are errors.
Calibration loadCalibration(const std::string& path);
// The same from YAML text; `source_name` is used in error messages.
Calibration parseCalibration(const std::string& yaml_text, const std::string& source_name);
// Checks ranges and consistency of an already filled calibration; throws CalibrationError.
void validateCalibration(const Calibration& calibration, const std::string& source_name);
// YAML text in the contract's format; parseCalibration(toYaml(c)) == c (the self mask's file name
// is written, its pixels are saved with saveSelfMask).
std::string toYaml(const Calibration& calibration);
// camera.self_mask as a grey image's pixels, row by row (255 = own robot); throws CalibrationError
// when the mask does not match the camera's size.
std::vector<uint8_t> selfMaskImage(const CameraCalibration& camera);
// Adds the pixels of a grey image of the camera's size (rows `step` bytes apart, nonzero = own
// robot) to camera.self_mask (made when empty); throws CalibrationError for another size.
void addSelfMask(CameraCalibration& camera, const uint8_t* image, int width, int height, size_t step);
// camera.self_mask as the bytes of a PNG (selfMaskImage); throws CalibrationError when the mask
// does not match the camera's size.
std::vector<uint8_t> encodeSelfMask(const CameraCalibration& camera);
// Writes encodeSelfMask(camera) to `path` atomically (a temporary file beside it, renamed over it);
// throws CalibrationError when it cannot. The file `self_mask_file` names is resolved against the
// calibration file's directory.
void saveSelfMask(const CameraCalibration& camera, const std::string& path);

}  // namespace core
}  // namespace act_color
