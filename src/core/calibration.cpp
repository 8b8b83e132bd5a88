#include "act_color/core/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>
#include <vector>

#include "act_color/core/file_io.hpp"
#include "act_color/core/yaml_subset.hpp"

namespace act_color {
namespace core {
namespace {

[[noreturn]] void fail(const std::string& source, const std::string& key, const std::string& what) {
  throw CalibrationError(source + ": " + key + ": " + what);
}

// Reads one YAML map, remembering which keys were read so that the rest can be rejected. Values
// are typed here, in their real type: an integer is read as int64 and range-checked before it
// becomes an int (no wrap), a number is decimal (no octal, no hex, no inf).
class MapReader {
 public:
  MapReader(const YamlNode* node, std::string path, const std::string& source)
      : node_(node), path_(std::move(path)), source_(source) {
    if (node_ == nullptr) fail(source_, path_, "missing");
    if (!node_->isMap()) fail(source_, path_, "must be a map" + at(*node_));
    std::set<std::string> seen;
    for (const auto& e : node_->entries) {
      if (!seen.insert(e.first).second) fail(source_, key(e.first), "appears twice" + at(e.second));
    }
  }

  std::string key(const std::string& name) const { return path_.empty() ? name : path_ + "." + name; }
  static std::string at(const YamlNode& n) {
    return " (line " + std::to_string(n.line) + ", column " + std::to_string(n.column) + ")";
  }

  const YamlNode& child(const std::string& name) {
    used_.insert(name);
    const YamlNode* n = node_->find(name);
    if (n == nullptr) fail(source_, key(name), "missing" + misspelling(name));
    return *n;
  }
  bool has(const std::string& name) const { return node_->find(name) != nullptr; }

  double number(const YamlNode& n, const std::string& k) const {
    double value = 0;
    if (!n.isScalar() || n.quoted || !parseYamlNumber(n.scalar, &value)) {
      fail(source_, k, "must be a finite decimal number, is " + describe(n) + at(n));
    }
    return value;
  }

  // A number in [lo, hi] (open at lo when lo_open).
  double real(const std::string& name, double lo, double hi, bool lo_open = false) {
    const std::string k = key(name);
    const YamlNode& n = child(name);
    const double value = number(n, k);
    if ((lo_open ? value <= lo : value < lo) || value > hi) {
      std::ostringstream s;
      s << "must be in " << (lo_open ? "(" : "[") << lo << ", " << hi << "], is " << n.scalar << at(n);
      fail(source_, k, s.str());
    }
    return value;
  }

  int integer(const std::string& name, int lo, int hi) {
    const std::string k = key(name);
    const YamlNode& n = child(name);
    long long value = 0;
    if (!n.isScalar() || n.quoted || !parseYamlInteger(n.scalar, &value)) {
      fail(source_, k, "must be an integer (decimal, no leading zero), is " + describe(n) + at(n));
    }
    if (value < lo || value > hi) {
      fail(source_, k, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], is " + n.scalar + at(n));
    }
    return static_cast<int>(value);
  }

  int sign(const std::string& name) {
    const std::string k = key(name);
    const YamlNode& n = child(name);
    long long value = 0;
    if (!n.isScalar() || n.quoted || !parseYamlInteger(n.scalar, &value) || (value != 1 && value != -1)) {
      fail(source_, k, "must be 1 or -1, is " + describe(n) + at(n));
    }
    return static_cast<int>(value);
  }

  MapReader map(const std::string& name) { return MapReader(&child(name), key(name), source_); }

  void rejectUnknownKeys() const {
    for (const auto& e : node_->entries) {
      if (!used_.count(e.first)) fail(source_, key(e.first), "unknown key" + at(e.second));
    }
  }

  const std::string& source() const { return source_; }

  // For a missing key: a key of this map not read as another within two edits of it (a typo, an
  // accent), named with its place, so that the message points at the line to fix; empty when there
  // is none.
  std::string misspelling(const std::string& name) const {
    for (const auto& e : node_->entries) {
      if (used_.count(e.first) || e.first.size() > name.size() + 2 || name.size() > e.first.size() + 2) continue;
      std::vector<size_t> row(e.first.size() + 1);
      for (size_t j = 0; j < row.size(); ++j) row[j] = j;
      for (size_t i = 1; i <= name.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t j = 1; j <= e.first.size(); ++j) {
          const size_t above = row[j];
          row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (name[i - 1] == e.first[j - 1] ? 0 : 1)});
          diagonal = above;
        }
      }
      if (row.back() <= 2) return "; is '" + e.first + "'" + at(e.second) + " meant?";
    }
    return "";
  }

  // What a node is, for messages: its text, shortened, or "a list" / "a map".
  static std::string describe(const YamlNode& n) {
    if (n.isList()) return "a list";
    if (n.isMap()) return "a map";
    std::string text = n.scalar.size() > 40 ? n.scalar.substr(0, 40) + "..." : n.scalar;
    return n.quoted ? "the string \"" + text + "\"" : "'" + text + "'";
  }

 private:
  const YamlNode* node_;
  std::string path_;
  std::string source_;
  std::set<std::string> used_;
};

std::vector<double> numberSequence(MapReader& reader, const YamlNode& n, const std::string& k, size_t size) {
  if (!n.isList() || n.items.size() != size) {
    fail(reader.source(), k, "must be a list of " + std::to_string(size) + " numbers" + MapReader::at(n));
  }
  std::vector<double> values;
  for (size_t i = 0; i < size; ++i) values.push_back(reader.number(n.items[i], k));
  return values;
}

CameraCalibration parseCamera(MapReader camera) {
  CameraCalibration c;
  c.width = camera.integer("width", 16, kMaxImageSidePx);
  c.height = camera.integer("height", 16, kMaxImageSidePx);
  const auto center = numberSequence(camera, camera.child("center"), camera.key("center"), 2);
  c.center_u = center[0];
  c.center_v = center[1];
  c.bearing_sign = camera.sign("bearing_sign");
  c.bearing_offset_rad = camera.real("bearing_offset", -2 * M_PI, 2 * M_PI);
  c.height_m = camera.real("height_m", 0.0, 10.0, true);
  c.chassis_radius_px = camera.real("chassis_radius_px", 0.0, 1e5);
  c.mirror_radius_px = camera.real("mirror_radius_px", 0.0, 1e5, true);
  const YamlNode& map = camera.child("elevation_map");
  const std::string map_key = camera.key("elevation_map");
  if (!map.isList() || map.items.size() < 2) {
    fail(camera.source(), map_key, "must be a list of at least two [r_px, elevation_rad] pairs" + MapReader::at(map));
  }
  c.elevation_map.reserve(map.items.size());
  for (size_t i = 0; i < map.items.size(); ++i) {
    const std::string entry_key = map_key + "[" + std::to_string(i) + "]";
    const auto pair = numberSequence(camera, map.items[i], entry_key, 2);
    c.elevation_map.emplace_back(pair[0], pair[1]);
  }
  if (camera.has("tilt")) {
    const auto tilt = numberSequence(camera, camera.child("tilt"), camera.key("tilt"), 2);
    c.tilt_x_rad = tilt[0];
    c.tilt_y_rad = tilt[1];
  }
  if (camera.has("self_mask")) {
    const YamlNode& n = camera.child("self_mask");
    if (!n.isScalar() || n.scalar.empty() || n.scalar.find_first_of("\"\\\n") != std::string::npos)
      fail(camera.source(), camera.key("self_mask"), "must be the file name of a PNG (no quotes or backslashes)");
    c.self_mask_file = n.scalar;
  }
  camera.rejectUnknownKeys();
  return c;
}

// The self mask's pixels from its PNG, `file` relative to the calibration's directory.
void readSelfMask(CameraCalibration& c, const std::string& source) {
  std::string path = c.self_mask_file;
  const size_t slash = source.rfind('/');
  if (!path.empty() && path[0] != '/' && slash != std::string::npos) path = source.substr(0, slash + 1) + path;
  // A regular file, not decoded when its header declares another size than the camera's (a FIFO
  // blocked the loader, a 32000 x 32000 px PNG of 1 MB took 1 GB to decode before it was refused).
  cv::Mat mask;
  std::string error;
  if (!readImageFile(path, cv::IMREAD_GRAYSCALE, kMaxImageFileBytes, std::max(c.width, c.height),
                     static_cast<int64_t>(c.width) * c.height, &mask, &error)) {
    fail(source, "camera.self_mask", error);
  }
  if (mask.cols != c.width || mask.rows != c.height) {
    fail(source, "camera.self_mask",
         "'" + path + "' is " + std::to_string(mask.cols) + "x" + std::to_string(mask.rows) + " px, the camera is " +
             std::to_string(c.width) + "x" + std::to_string(c.height));
  }
  c.self_mask.clear();
  addSelfMask(c, mask.data, mask.cols, mask.rows, mask.step);
}

FieldCalibration parseField(MapReader field) {
  FieldCalibration f;
  f.length_m = field.real("length_m", 0.0, 1000.0, true);
  f.width_m = field.real("width_m", 0.0, 1000.0, true);
  f.line_width_m = field.real("line_width_m", 0.0, 10.0, true);
  f.margin_m = field.real("margin_m", 0.0, 100.0);
  f.center_circle_radius_m = field.real("center_circle_radius_m", 0.0, 1000.0, true);
  f.corner_arc_radius_m = field.real("corner_arc_radius_m", 0.0, 1000.0);  // 0: no corner arcs
  {
    MapReader goal_area = field.map("goal_area");
    f.goal_area_depth_m = goal_area.real("depth_m", 0.0, 1000.0, true);
    f.goal_area_width_m = goal_area.real("width_m", 0.0, 1000.0, true);
    goal_area.rejectUnknownKeys();
  }
  {
    MapReader penalty_area = field.map("penalty_area");
    f.penalty_area_depth_m = penalty_area.real("depth_m", 0.0, 1000.0, true);
    f.penalty_area_width_m = penalty_area.real("width_m", 0.0, 1000.0, true);
    penalty_area.rejectUnknownKeys();
  }
  if (field.has("penalty_mark_distance_m"))
    f.penalty_mark_distance_m = field.real("penalty_mark_distance_m", 0.0, 1000.0, true);
  if (field.has("penalty_arc")) {
    MapReader arc = field.map("penalty_arc");
    f.penalty_arc_radius_m = arc.real("radius_m", 0.0, 1000.0, true);
    f.penalty_arc_center_m = arc.real("center_distance_m", 0.0, 1000.0);
    arc.rejectUnknownKeys();
  }
  {
    MapReader goal = field.map("goal");
    f.goal_width_m = goal.real("width_m", 0.0, 1000.0, true);
    f.goal_height_m = goal.real("height_m", 0.0, 100.0, true);
    f.goal_depth_m = goal.real("depth_m", 0.0, 100.0, true);
    if (goal.has("setback_m")) f.goal_setback_m = goal.real("setback_m", 0.0, 100.0);
    goal.rejectUnknownKeys();
  }
  f.yellow_goal_x_sign = field.sign("yellow_goal_x_sign");
  field.rejectUnknownKeys();
  return f;
}

}  // namespace

Calibration parseCalibration(const std::string& yaml_text, const std::string& source_name) {
  YamlNode root_node;
  try {
    root_node = parseYaml(yaml_text);
  } catch (const YamlError& e) {
    throw CalibrationError(source_name + ": not valid YAML: " + e.what());
  }
  if (root_node.isScalar() && root_node.scalar.empty()) throw CalibrationError(source_name + ": not valid YAML: empty");
  MapReader root(&root_node, "", source_name);
  Calibration calibration;
  calibration.camera = parseCamera(root.map("camera"));
  calibration.field = parseField(root.map("field"));
  root.rejectUnknownKeys();
  validateCalibration(calibration, source_name);
  if (!calibration.camera.self_mask_file.empty()) readSelfMask(calibration.camera, source_name);
  return calibration;
}

Calibration loadCalibration(const std::string& path) {
  // A regular file of bounded size only: a FIFO or a device would block or never end.
  std::string text, error;
  if (!readRegularFile(path, YamlLimits().max_bytes, &text, &error)) throw CalibrationError(path + ": " + error);
  return parseCalibration(text, path);
}

void validateCalibration(const Calibration& calibration, const std::string& source) {
  const CameraCalibration& c = calibration.camera;
  if (c.width < 16 || c.height < 16) fail(source, "camera.width", "image must be at least 16x16 px");
  if (c.width > kMaxImageSidePx || c.height > kMaxImageSidePx ||
      static_cast<int64_t>(c.width) * c.height > kMaxImagePixels) {
    fail(source, "camera.width",
         std::to_string(c.width) + "x" + std::to_string(c.height) + " px is larger than " +
             std::to_string(kMaxImagePixels) + " pixels or " + std::to_string(kMaxImageSidePx) + " px a side (limit)");
  }
  if (!(c.center_u >= 0 && c.center_u <= c.width && c.center_v >= 0 && c.center_v <= c.height)) {
    fail(source, "camera.center", "must lie inside the image");
  }
  if (c.bearing_sign != 1 && c.bearing_sign != -1) fail(source, "camera.bearing_sign", "must be 1 or -1");
  if (!(c.height_m > 0)) fail(source, "camera.height_m", "must be positive");
  if (!(c.chassis_radius_px < c.mirror_radius_px)) {
    fail(source, "camera.chassis_radius_px", "must be smaller than camera.mirror_radius_px");
  }
  if (!(c.tiltRad() <= kMaxTiltRad)) {
    fail(source, "camera.tilt", "must be finite and at most " + std::to_string(kMaxTiltRad) + " rad from the vertical");
  }
  if (c.elevation_map.size() < 2) fail(source, "camera.elevation_map", "needs at least two entries");
  for (size_t i = 0; i < c.elevation_map.size(); ++i) {
    const auto& [r, e] = c.elevation_map[i];
    const std::string key = "camera.elevation_map[" + std::to_string(i) + "]";
    if (!(r >= 0)) fail(source, key, "r_px must not be negative");
    if (!(e > -M_PI / 2 && e < M_PI / 2)) fail(source, key, "elevation_rad must be in (-pi/2, pi/2)");
    if (i > 0 && !(r > c.elevation_map[i - 1].first)) fail(source, key, "r_px must increase strictly");
    if (i > 0 && !(e > c.elevation_map[i - 1].second)) fail(source, key, "elevation_rad must increase strictly");
  }
  if (!(c.elevation_map.front().second < 0)) fail(source, "camera.elevation_map[0]", "must look below the horizon");
  {
    // Some pixel of the image must see the floor: a radius between the chassis and the mirror's
    // rim, inside the image, covered by the map and below the horizon.
    const double far_u = std::max(c.center_u, c.width - c.center_u),
                 far_v = std::max(c.center_v, c.height - c.center_v);
    const double lo = std::max(c.elevation_map.front().first, c.chassis_radius_px);
    const double hi = std::min({c.elevation_map.back().first, c.mirror_radius_px, std::hypot(far_u, far_v)});
    if (!(lo < hi)) {
      std::ostringstream s;
      s << "images no pixel: it covers r " << c.elevation_map.front().first << " to " << c.elevation_map.back().first
        << " px, the image has r up to " << std::hypot(far_u, far_v) << " px between the chassis ("
        << c.chassis_radius_px << ") and the mirror's rim (" << c.mirror_radius_px << ")";
      fail(source, "camera.elevation_map", s.str());
    }
    // Elevation grows with r: the innermost imaged radius looks lowest.
    const auto& map = c.elevation_map;
    size_t k = 1;
    while (k + 1 < map.size() && map[k].first < lo) ++k;
    const double t = (lo - map[k - 1].first) / (map[k].first - map[k - 1].first);
    const double lowest = map[k - 1].second + std::clamp(t, 0.0, 1.0) * (map[k].second - map[k - 1].second);
    if (!(lowest < 0)) {
      fail(source, "camera.elevation_map", "no imaged pixel looks below the horizon: the camera would see no floor");
    }
    // And enough pixels do (a ring of 1e-7 px passed the test above and trained nothing): those
    // whose centre lies between lo and the radius of the horizon (or hi).
    double horizon = hi;
    for (size_t j = 1; j < map.size(); ++j) {
      if (map[j].second >= 0 && map[j - 1].second < 0) {
        horizon = map[j - 1].first +
                  (0 - map[j - 1].second) / (map[j].second - map[j - 1].second) * (map[j].first - map[j - 1].first);
        break;
      }
    }
    const double top = std::min(hi, horizon);
    int64_t floor_pixels = 0;
    for (int v = 0; v < c.height; ++v) {
      const double dv = v - c.center_v;
      for (int u = 0; u < c.width; ++u) {
        const double du = u - c.center_u, r2 = du * du + dv * dv;
        floor_pixels += r2 >= lo * lo && r2 < top * top;
      }
    }
    const int64_t needed = std::max<int64_t>(16, static_cast<int64_t>(c.width) * c.height / 100);
    if (floor_pixels < needed) {
      fail(source, "camera.elevation_map",
           "images the floor in " + std::to_string(floor_pixels) + " pixels, fewer than " + std::to_string(needed) +
               " (1% of the image): the camera would see no field");
    }
  }

  const FieldCalibration& f = calibration.field;
  if (!(2 * f.line_width_m < std::min(f.length_m, f.width_m)))
    fail(source, "field.line_width_m", "too wide for the field");
  if (!(f.center_circle_radius_m < f.width_m / 2 && f.center_circle_radius_m < f.length_m / 2)) {
    fail(source, "field.center_circle_radius_m", "must fit into the field");
  }
  if (!(f.corner_arc_radius_m < f.width_m / 2)) fail(source, "field.corner_arc_radius_m", "must fit into the field");
  if (!(f.goal_area_width_m < f.width_m)) fail(source, "field.goal_area.width_m", "must be less than field.width_m");
  if (!(f.goal_area_depth_m < f.length_m / 2))
    fail(source, "field.goal_area.depth_m", "must be less than half the length");
  if (!(f.penalty_area_width_m < f.width_m))
    fail(source, "field.penalty_area.width_m", "must be less than field.width_m");
  if (!(f.penalty_area_depth_m < f.length_m / 2)) {
    fail(source, "field.penalty_area.depth_m", "must be less than half the length");
  }
  if (f.penalty_mark_distance_m && !(*f.penalty_mark_distance_m < f.length_m / 2)) {
    fail(source, "field.penalty_mark_distance_m", "must be less than half the length");
  }
  if (f.penalty_arc_radius_m) {
    if (!(f.penalty_arc_center_m < f.length_m / 2))
      fail(source, "field.penalty_arc.center_distance_m", "must be less than half the length");
    if (!(f.penalty_arc_center_m - *f.penalty_arc_radius_m < f.penalty_area_depth_m))
      fail(source, "field.penalty_arc.radius_m", "the arc must reach out of the penalty area");
    if (!(*f.penalty_arc_radius_m < f.width_m / 2))
      fail(source, "field.penalty_arc.radius_m", "must fit into the field");
  }
  if (!(f.goal_width_m < f.width_m)) fail(source, "field.goal.width_m", "must be less than field.width_m");
  if (!(f.goal_setback_m <= f.margin_m)) fail(source, "field.goal.setback_m", "must lie within field.margin_m");
  if (f.yellow_goal_x_sign != 1 && f.yellow_goal_x_sign != -1)
    fail(source, "field.yellow_goal_x_sign", "must be 1 or -1");
}

std::string toYaml(const Calibration& calibration) {
  const CameraCalibration& c = calibration.camera;
  const FieldCalibration& f = calibration.field;
  std::ostringstream s;
  s << std::setprecision(17);
  s << "camera:\n"
    << "  width: " << c.width << "\n"
    << "  height: " << c.height << "\n"
    << "  center: [" << c.center_u << ", " << c.center_v << "]\n"
    << "  bearing_sign: " << c.bearing_sign << "\n"
    << "  bearing_offset: " << c.bearing_offset_rad << "\n"
    << "  height_m: " << c.height_m << "\n"
    << "  chassis_radius_px: " << c.chassis_radius_px << "\n"
    << "  mirror_radius_px: " << c.mirror_radius_px << "\n"
    << "  elevation_map:\n";
  for (const auto& [r, e] : c.elevation_map) s << "    - [" << r << ", " << e << "]\n";
  if (c.tilt_x_rad != 0 || c.tilt_y_rad != 0) s << "  tilt: [" << c.tilt_x_rad << ", " << c.tilt_y_rad << "]\n";
  if (!c.self_mask_file.empty()) s << "  self_mask: \"" << c.self_mask_file << "\"\n";
  s << "field:\n"
    << "  length_m: " << f.length_m << "\n"
    << "  width_m: " << f.width_m << "\n"
    << "  line_width_m: " << f.line_width_m << "\n"
    << "  margin_m: " << f.margin_m << "\n"
    << "  center_circle_radius_m: " << f.center_circle_radius_m << "\n"
    << "  corner_arc_radius_m: " << f.corner_arc_radius_m << "\n"
    << "  goal_area: {depth_m: " << f.goal_area_depth_m << ", width_m: " << f.goal_area_width_m << "}\n"
    << "  penalty_area: {depth_m: " << f.penalty_area_depth_m << ", width_m: " << f.penalty_area_width_m << "}\n";
  if (f.penalty_mark_distance_m) s << "  penalty_mark_distance_m: " << *f.penalty_mark_distance_m << "\n";
  if (f.penalty_arc_radius_m) {
    s << "  penalty_arc: {radius_m: " << *f.penalty_arc_radius_m << ", center_distance_m: " << f.penalty_arc_center_m
      << "}\n";
  }
  s << "  goal: {width_m: " << f.goal_width_m << ", height_m: " << f.goal_height_m << ", depth_m: " << f.goal_depth_m;
  if (f.goal_setback_m > 0) s << ", setback_m: " << f.goal_setback_m;
  s << "}\n"
    << "  yellow_goal_x_sign: " << f.yellow_goal_x_sign << "\n";
  return s.str();
}

std::vector<uint8_t> selfMaskImage(const CameraCalibration& camera) {
  if (camera.self_mask.size() != static_cast<size_t>(camera.width) * camera.height)
    throw CalibrationError("the self mask does not match the camera's size");
  std::vector<uint8_t> image(camera.self_mask.size());
  for (size_t i = 0; i < image.size(); ++i) image[i] = camera.self_mask[i] ? 255 : 0;
  return image;
}

void addSelfMask(CameraCalibration& camera, const uint8_t* image, int width, int height, size_t step) {
  if (width != camera.width || height != camera.height) {
    throw CalibrationError("a self mask of " + std::to_string(width) + "x" + std::to_string(height) +
                           " px for a camera of " + std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
  camera.self_mask.resize(static_cast<size_t>(width) * height, 0);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      uint8_t& own = camera.self_mask[static_cast<size_t>(v) * width + u];
      own = own || image[static_cast<size_t>(v) * step + u] != 0;
    }
  }
}

std::vector<uint8_t> encodeSelfMask(const CameraCalibration& camera) {
  std::vector<uint8_t> pixels = selfMaskImage(camera);
  const cv::Mat image(camera.height, camera.width, CV_8UC1, pixels.data());
  std::vector<uint8_t> png;
  bool encoded = false;
  try {
    encoded = cv::imencode(".png", image, png);
  } catch (const cv::Exception&) {
    encoded = false;
  }
  if (!encoded) throw CalibrationError("cannot encode the self mask as a PNG");
  return png;
}

void saveSelfMask(const CameraCalibration& camera, const std::string& path) {
  std::vector<uint8_t> png;
  try {
    png = encodeSelfMask(camera);
  } catch (const CalibrationError& e) {
    throw CalibrationError(path + ": " + e.what());
  }
  std::string error;
  if (!writeFileAtomically(path, png.data(), png.size(), &error)) throw CalibrationError(error);
}

bool PoseBounds::contains(double x_m, double y_m, std::string* why) const {
  if (std::abs(x_m) <= half_x_m && std::abs(y_m) <= half_y_m) return true;
  std::ostringstream s;
  s << "pose (" << x_m << ", " << y_m << ") m is off the field (|x| <= " << half_x_m << ", |y| <= " << half_y_m
    << " m with the margin)";
  *why = s.str();
  return false;
}

}  // namespace core
}  // namespace act_color
