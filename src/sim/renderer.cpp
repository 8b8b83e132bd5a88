#include "act_color/sim/renderer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

namespace act_color {
namespace sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Linear reflectance of an 8-bit sRGB-like color (the color a surface shows at light 1, gamma 1/2.2).
Eigen::Vector3f linearFromSrgb(double r, double g, double b) {
  auto lin = [](double c) { return static_cast<float>(std::pow(c / 255.0, 2.2)); };
  return Eigen::Vector3f(lin(r), lin(g), lin(b));
}

// A surface kind: linear albedo and how strongly the value-noise texture modulates it.
struct Material {
  Eigen::Vector3f albedo = Eigen::Vector3f::Zero();
  float texture_amplitude = 0.f;  // relative albedo variation
  float texture_scale = 1.f;      // texels per metre / kTexelsPerMetre
  float texture_offset = 0.f;     // decorrelates materials sampling the same texture
};

// Tileable multi-octave value noise in [-1, 1], seeded: the texture of every material.
class NoiseTexture {
 public:
  static constexpr int kSize = 512;  // power of two: wrap by masking

  explicit NoiseTexture(uint32_t seed) : data_(kSize * kSize, 0.f) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> uniform(-1.f, 1.f);
    float total = 0.f;
    float amplitude = 1.f;
    for (int period = 64; period >= 2; period /= 2, amplitude *= 0.55f) {
      const int cells = kSize / period;
      std::vector<float> lattice(static_cast<size_t>(cells) * cells);
      for (float& l : lattice) l = uniform(rng);
      for (int y = 0; y < kSize; ++y) {
        const int cy = y / period;
        float fy = static_cast<float>(y % period) / period;
        fy = fy * fy * (3.f - 2.f * fy);  // smoothstep
        for (int x = 0; x < kSize; ++x) {
          const int cx = x / period;
          float fx = static_cast<float>(x % period) / period;
          fx = fx * fx * (3.f - 2.f * fx);
          auto at = [&](int i, int j) { return lattice[static_cast<size_t>(j % cells) * cells + (i % cells)]; };
          const float top = at(cx, cy) + fx * (at(cx + 1, cy) - at(cx, cy));
          const float bottom = at(cx, cy + 1) + fx * (at(cx + 1, cy + 1) - at(cx, cy + 1));
          data_[static_cast<size_t>(y) * kSize + x] += amplitude * (top + fy * (bottom - top));
        }
      }
      total += amplitude;
    }
    for (float& d : data_) d /= total;
  }

  // Bilinear sample at texel coordinates, wrapping.
  float sample(float x, float y) const {
    const float fx0 = std::floor(x);
    const float fy0 = std::floor(y);
    const int x0 = static_cast<int>(fx0) & (kSize - 1);
    const int y0 = static_cast<int>(fy0) & (kSize - 1);
    const int x1 = (x0 + 1) & (kSize - 1);
    const int y1 = (y0 + 1) & (kSize - 1);
    const float fx = x - fx0;
    const float fy = y - fy0;
    const float* r0 = &data_[static_cast<size_t>(y0) * kSize];
    const float* r1 = &data_[static_cast<size_t>(y1) * kSize];
    const float top = r0[x0] + fx * (r0[x1] - r0[x0]);
    const float bottom = r1[x0] + fx * (r1[x1] - r1[x0]);
    return top + fy * (bottom - top);
  }

 private:
  std::vector<float> data_;
};

constexpr float kTexelsPerMetre = 60.f;  // 1.7 cm texels: finer than a floor pixel near the robot

// An axis-aligned colored box in the hall (furniture, crates, benches).
struct ClutterBox {
  Eigen::Vector3d min_corner, max_corner;
  Material material;
};

// A colored rectangle on a hall wall (poster, window, door) or on the hall floor (mat).
struct Patch {
  double s_min, s_max, t_min, t_max;  // wall: s along the wall, t = height; floor: x, y
  Material material;
  float emission = 0.f;  // windows and lamps shine by themselves (times the light level)
};

// Ray-box slab test; entry parameter in [0, t_max) or +inf. `axis` receives the entry face's axis.
double slabHit(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
               double t_max, int* axis) {
  double t0 = 0.0;
  double t1 = t_max;
  int entry_axis = 2;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-12) {
      if (o[a] < lo[a] || o[a] > hi[a]) return kInf;
      continue;
    }
    double ta = (lo[a] - o[a]) / d[a];
    double tb = (hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    if (ta > t0) {
      t0 = ta;
      entry_axis = a;
    }
    t1 = std::min(t1, tb);
    if (t0 > t1) return kInf;
  }
  if (t0 >= t_max) return kInf;
  *axis = entry_axis;
  return t0;
}

// What a ray met first.
enum class Surface : uint8_t { kNone, kFloor, kGoal, kWall, kCeiling, kClutter, kRobot, kBall, kPerson };

}  // namespace

struct Renderer::Impl {
  Impl(const core::Calibration& calibration, const RendererOptions& options);

  core::Calibration calibration;
  core::ExpectedClassModel model;
  NoiseTexture texture;

  // Per imaged pixel (not outside the mirror): index, vignetting factor.
  std::vector<uint32_t> imaged;
  std::vector<float> vignette_radius2;  // (r / mirror radius)^2 per imaged pixel
  std::vector<uint8_t> imaged_mask;     // per pixel: 1 inside the mirror
  // Per imaged pixel: index into `struts` + 1 of the strut covering it, 0 for none; and the
  // pixel's relative offset from the strut's axis in [-1, 1] (for the rod's highlight). Empty
  // without struts.
  std::vector<uint8_t> strut_of_pixel;
  std::vector<float> strut_offset;
  std::vector<Material> struts;

  // Hall: walls at +-hall_x, +-hall_y, ceiling at hall_height.
  double hall_x = 0.0, hall_y = 0.0, hall_height = 4.0;
  std::vector<ClutterBox> boxes;
  std::array<std::vector<Patch>, 4> wall_patches;  // +x, -x, +y, -y walls
  std::vector<Patch> floor_patches;
  std::vector<Patch> ceiling_lamps;

  Material carpet, line, yellow_goal, blue_goal, robot, ball, chassis, hall_floor, wall, ceiling;
  std::optional<Material> ball_patches, robot_marker;

  float textured(const Material& m, double a, double b) const {
    const float s = kTexelsPerMetre * m.texture_scale;
    return 1.f + m.texture_amplitude * texture.sample(static_cast<float>(a) * s + m.texture_offset,
                                                      static_cast<float>(b) * s + 0.37f * m.texture_offset);
  }
};

Renderer::Impl::Impl(const core::Calibration& cal, const RendererOptions& options)
    : calibration(cal), model(cal), texture(options.hall_seed * 2654435761u + 12345u) {
  const uint32_t hall_seed = options.hall_seed;
  const core::OmniCameraModel& camera = model.camera();
  const size_t pixels = camera.rays().size();
  imaged_mask.assign(pixels, 0);
  const double mirror = cal.camera.mirror_radius_px;
  for (size_t i = 0; i < pixels; ++i) {
    if (camera.ray(i).region == core::PixelRegion::kNotImaged) continue;
    imaged.push_back(static_cast<uint32_t>(i));
    imaged_mask[i] = 1;
    const double du = static_cast<double>(i % camera.width()) - cal.camera.center_u;
    const double dv = static_cast<double>(i / camera.width()) - cal.camera.center_v;
    vignette_radius2.push_back(static_cast<float>((du * du + dv * dv) / (mirror * mirror)));
  }

  // Materials: 8-bit colors they show under light 1 with the default photometry.
  auto material = [](double r, double g, double b, float amplitude, float scale, float offset) {
    Material m;
    m.albedo = linearFromSrgb(r, g, b);
    m.texture_amplitude = amplitude;
    m.texture_scale = scale;
    m.texture_offset = offset;
    return m;
  };
  auto look = [&material](const SurfaceLook& l, float scale, float offset) {
    return material(l.rgb[0], l.rgb[1], l.rgb[2], l.texture_amplitude, scale, offset);
  };
  carpet = look(options.carpet, 1.f, 0.f);
  line = look(options.line, 1.f, 101.f);
  yellow_goal = look(options.yellow_goal, 0.5f, 203.f);
  blue_goal = look(options.blue_goal, 0.5f, 307.f);
  robot = look(options.robot, 0.7f, 409.f);
  ball = look(options.ball, 1.f, 13.f);
  if (options.ball_patches) ball_patches = look(*options.ball_patches, 1.f, 17.f);
  if (options.robot_marker) robot_marker = look(*options.robot_marker, 0.7f, 419.f);
  chassis = look(options.chassis, 3.f, 57.f);
  hall_floor = look(options.hall_floor, 0.25f, 71.f);
  wall = look(options.wall, 0.2f, 83.f);
  ceiling = look(options.ceiling, 0.2f, 97.f);

  // Struts: which imaged pixels they cover, looked up once instead of per frame.
  if (options.struts.size() > 254) throw std::invalid_argument("Renderer: at most 254 struts");
  for (const Strut& strut : options.struts) {
    struts.push_back(material(strut.rgb[0], strut.rgb[1], strut.rgb[2], 0.12f, 2.f, 29.f));
  }
  if (!options.struts.empty()) {
    strut_of_pixel.assign(imaged.size(), 0);
    strut_offset.assign(imaged.size(), 0.f);
    for (size_t n = 0; n < imaged.size(); ++n) {
      const double du = static_cast<double>(imaged[n] % camera.width()) - cal.camera.center_u;
      const double dv = static_cast<double>(imaged[n] / camera.width()) - cal.camera.center_v;
      const double r = std::hypot(du, dv);
      const double angle = std::atan2(dv, du);
      for (size_t k = 0; k < options.struts.size(); ++k) {
        const Strut& strut = options.struts[k];
        if (r < strut.inner_radius_px || r > strut.outer_radius_px || !(strut.half_width_rad > 0)) continue;
        const double off = std::remainder(angle - strut.bearing_rad, 2.0 * M_PI);
        if (std::abs(off) > strut.half_width_rad) continue;
        strut_of_pixel[n] = static_cast<uint8_t>(k + 1);
        strut_offset[n] = static_cast<float>(off / strut.half_width_rad);
        break;
      }
    }
  }

  const core::FieldModel& field = model.field();
  const double carpet_x = field.halfLength() + cal.field.margin_m;
  const double carpet_y = field.halfWidth() + cal.field.margin_m;
  const double hall_distance = options.hall_wall_distance_m;
  // Narrower bands leave no room for the boxes' 0.6 m from the carpet and 0.2 m from the wall.
  if (!(hall_distance >= 1.2)) throw std::invalid_argument("Renderer: hall_wall_distance_m must be at least 1.2 m");
  if (options.clutter_palette.empty()) throw std::invalid_argument("Renderer: empty clutter palette");
  hall_x = carpet_x + hall_distance;
  hall_y = carpet_y + hall_distance;
  hall_height = options.hall_height_m;

  const std::vector<Eigen::Vector3d>& palette = options.clutter_palette;
  const int num_clutter = static_cast<int>(palette.size());
  std::mt19937 rng(hall_seed);
  auto uniform = [&rng](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  auto clutterMaterial = [&](float amplitude) {
    const int c = std::uniform_int_distribution<int>(0, num_clutter - 1)(rng);
    return material(palette[c][0], palette[c][1], palette[c][2], amplitude, 0.5f, static_cast<float>(uniform(0, 500)));
  };

  // Boxes standing in the band between the carpet and the walls: at least 0.6 m from the carpet
  // and 0.2 m from the wall, so a narrow band takes smaller boxes (1.4 m in the default 4 m band).
  const double max_box_m = std::max(0.3, std::min(1.4, hall_distance - 0.8));
  for (int n = 0; n < options.num_boxes; ++n) {
    const double sx = uniform(0.3, max_box_m), sy = uniform(0.3, max_box_m), sz = uniform(0.3, 2.0);
    double cx, cy;
    const int side = std::uniform_int_distribution<int>(0, 3)(rng);
    if (side < 2) {
      cx = (side == 0 ? 1 : -1) * uniform(carpet_x + 0.6 + sx / 2, hall_x - 0.2 - sx / 2);
      cy = uniform(-hall_y + 0.5, hall_y - 0.5);
    } else {
      cx = uniform(-hall_x + 0.5, hall_x - 0.5);
      cy = (side == 2 ? 1 : -1) * uniform(carpet_y + 0.6 + sy / 2, hall_y - 0.2 - sy / 2);
    }
    ClutterBox box;
    box.min_corner = Eigen::Vector3d(cx - sx / 2, cy - sy / 2, 0.0);
    box.max_corner = Eigen::Vector3d(cx + sx / 2, cy + sy / 2, sz);
    box.material = clutterMaterial(0.2f);
    boxes.push_back(box);
  }
  // Posters, doors and windows on the walls.
  for (int w = 0; w < 4; ++w) {
    const double half = w < 2 ? hall_y : hall_x;
    for (int n = 0; n < options.num_wall_patches; ++n) {
      Patch p;
      const double width = uniform(0.8, 3.5);
      const double s = uniform(-half, half - width);
      const double bottom = uniform(0.0, 2.2);
      p.s_min = s;
      p.s_max = s + width;
      p.t_min = bottom;
      p.t_max = std::min(hall_height, bottom + uniform(0.6, 1.8));
      p.material = clutterMaterial(0.12f);
      if (n == 0) {  // a bright window
        p.material = material(220, 226, 232, 0.05f, 0.5f, 11.f);
        p.emission = 0.5f;
      }
      wall_patches[w].push_back(p);
    }
  }
  // Mats and markings on the hall floor.
  for (int n = 0; n < options.num_floor_mats; ++n) {
    Patch p;
    const double sx = uniform(0.5, 2.5), sy = uniform(0.5, 2.5);
    double cx = uniform(-hall_x, hall_x), cy = uniform(-hall_y, hall_y);
    if (std::abs(cx) < carpet_x + sx / 2 && std::abs(cy) < carpet_y + sy / 2) {
      cx = (cx < 0 ? -1 : 1) * uniform(carpet_x + sx / 2, hall_x);  // keep it off the carpet
    }
    p.s_min = cx - sx / 2;
    p.s_max = cx + sx / 2;
    p.t_min = cy - sy / 2;
    p.t_max = cy + sy / 2;
    p.material = clutterMaterial(0.15f);
    floor_patches.push_back(p);
  }
  // Lamp rows on the ceiling.
  for (double x = -hall_x + 2.0; x < hall_x - 1.0; x += 4.0) {
    for (double y = -hall_y + 2.0; y < hall_y - 1.0; y += 4.0) {
      Patch p;
      p.s_min = x - 0.6;
      p.s_max = x + 0.6;
      p.t_min = y - 0.3;
      p.t_max = y + 0.3;
      p.material = material(240, 240, 236, 0.02f, 0.5f, 5.f);
      p.emission = 1.2f;
      ceiling_lamps.push_back(p);
    }
  }
}

namespace {
RendererOptions withHallSeed(uint32_t hall_seed) {
  RendererOptions options;
  options.hall_seed = hall_seed;
  return options;
}
}  // namespace

const std::vector<Eigen::Vector3d>& defaultClutterPalette() {
  static const std::vector<Eigen::Vector3d> kPalette = {
      {70, 140, 76},    // greenish
      {112, 132, 60},   // olive
      {214, 190, 72},   // yellowish
      {200, 178, 138},  // beige
      {62, 92, 172},    // bluish
      {40, 50, 92},     // navy
      {226, 226, 214},  // whitish
      {178, 178, 172},  // light grey
      {40, 38, 42},     // dark
      {112, 76, 50},    // brown
      {172, 52, 46},    // red
      {112, 62, 132},   // purple
      {204, 116, 64},   // orange-brown
      {90, 160, 150},   // teal
  };
  return kPalette;
}

Renderer::Renderer(const core::Calibration& calibration, uint32_t hall_seed)
    : Renderer(calibration, withHallSeed(hall_seed)) {}

Renderer::Renderer(const core::Calibration& calibration, const RendererOptions& options)
    : impl_(std::make_shared<const Impl>(calibration, options)) {}

const core::ExpectedClassModel& Renderer::model() const { return impl_->model; }

std::vector<uint8_t> Renderer::strutMask() const {
  const Impl& im = *impl_;
  if (im.strut_of_pixel.empty()) return {};
  const core::CameraCalibration& camera = im.calibration.camera;
  std::vector<uint8_t> mask(static_cast<size_t>(camera.width) * camera.height, 0);
  for (size_t n = 0; n < im.imaged.size(); ++n) mask[im.imaged[n]] = im.strut_of_pixel[n] != 0;
  return mask;
}

namespace {

const Patch* findPatch(const std::vector<Patch>& patches, double s, double t) {
  for (const Patch& p : patches) {
    if (s >= p.s_min && s <= p.s_max && t >= p.t_min && t <= p.t_max) return &p;
  }
  return nullptr;
}

// Relative RGB gains of light of a color temperature, 1 at 5500 K (a camera with fixed white balance).
Eigen::Vector3f temperatureGains(double kelvin) {
  const double t = std::log2(std::max(1000.0, kelvin) / 5500.0);
  return Eigen::Vector3f(static_cast<float>(std::exp2(-0.45 * t)), static_cast<float>(std::exp2(-0.05 * t)),
                         static_cast<float>(std::exp2(0.65 * t)));
}

}  // namespace

LabeledFrame Renderer::render(const Scene& scene) const {
  const Impl& im = *impl_;
  const core::OmniCameraModel& camera = im.model.camera();
  const core::FieldModel& field = im.model.field();
  const Lighting& light = scene.lighting;
  const int width = camera.width();
  const int height = camera.height();
  const double cam_h = camera.viewpointHeight();

  LabeledFrame frame;
  frame.rgb = cv::Mat::zeros(height, width, CV_8UC3);
  frame.labels = cv::Mat(height, width, CV_8UC1, cv::Scalar(core::kNotImaged));
  uint8_t* rgb = frame.rgb.ptr<uint8_t>(0);
  uint8_t* labels = frame.labels.ptr<uint8_t>(0);

  const core::PoseTransform pose(scene.robot_pose);
  const Eigen::Vector3d origin(pose.x_m, pose.y_m, cam_h);
  // Light color times the camera's white balance: both are per-channel gains on the linear signal.
  const Eigen::Vector3f gains =
      temperatureGains(light.color_temperature_k).cwiseProduct(light.white_balance.cast<float>());
  const float exposure = static_cast<float>(light.exposure);

  // Exposure-scaled linear light -> 8 bit through gamma: a table instead of pow per channel.
  constexpr int kGammaBins = 16384;
  constexpr float kGammaMax = 1.0f;  // linear values above saturate
  std::vector<uint8_t> gamma_table(kGammaBins + 1);
  for (int i = 0; i <= kGammaBins; ++i) {
    const double value = 255.0 * std::pow(static_cast<double>(i) / kGammaBins, light.gamma);
    gamma_table[i] = static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
  }

  // Light arriving at a point of the field (x, y); shadows only on the floor.
  auto lightAt = [&](double x, double y, bool on_floor) {
    double l = light.level * std::max(0.0, 1.0 + light.gradient_x_per_m * x + light.gradient_y_per_m * y);
    for (const Spotlight& s : light.spotlights) {
      const double dx = x - s.x_m, dy = y - s.y_m;
      l += s.gain * std::exp(-(dx * dx + dy * dy) / (2.0 * s.radius_m * s.radius_m));
    }
    for (const Shadow& s : light.shadows) {
      if ((on_floor || !s.floor_only) && x >= s.x_min_m && x <= s.x_max_m && y >= s.y_min_m && y <= s.y_max_m) {
        l *= s.factor;
      }
    }
    return static_cast<float>(l);
  };

  const double safe_range = im.model.safeCarpetRange(scene.robot_pose);
  const double carpet_x = field.halfLength() + im.calibration.field.margin_m;
  const double carpet_y = field.halfWidth() + im.calibration.field.margin_m;
  const bool robot_on_carpet = std::abs(pose.x_m) < carpet_x && std::abs(pose.y_m) < carpet_y;
  const float chassis_light = lightAt(pose.x_m, pose.y_m, false);
  const bool has_struts = !im.strut_of_pixel.empty();
  const bool saturate = light.saturation != 1.0;
  const float saturation = static_cast<float>(light.saturation);

  for (size_t n = 0; n < im.imaged.size(); ++n) {
    const size_t i = im.imaged[n];
    const core::PixelRay& ray = camera.ray(i);
    Eigen::Vector3f color;  // linear, before photometry
    uint8_t label = core::kUnknown;
    float illumination = 1.f;

    if (has_struts && im.strut_of_pixel[n] != 0) {
      // A strut in front of the mirror: a metal rod, brightest along its axis.
      const Material& m = im.struts[im.strut_of_pixel[n] - 1];
      const float off = im.strut_offset[n];
      const double rr = std::sqrt(static_cast<double>(im.vignette_radius2[n])) * im.calibration.camera.mirror_radius_px;
      color = m.albedo * ((0.55f + 0.6f * (1.f - off * off)) * im.textured(m, rr * 0.01, off * 0.05));
      label = core::kBlack;
      illumination = chassis_light * 0.8f;
    } else if (ray.region == core::PixelRegion::kChassis) {
      const double a = ray.bearing_rad;
      const double rr = std::hypot(static_cast<double>(i % width) - im.calibration.camera.center_u,
                                   static_cast<double>(i / width) - im.calibration.camera.center_v);
      color = im.chassis.albedo * im.textured(im.chassis, std::cos(a) * rr * 0.01, std::sin(a) * rr * 0.01);
      label = core::kBlack;
      illumination = chassis_light * 0.8f;
    } else {
      // Same arithmetic as ExpectedClassModel::geometricClass, so truth equals the model's class.
      const Eigen::Vector3d dir(pose.cos_theta * ray.dir_x - pose.sin_theta * ray.dir_y,
                                pose.sin_theta * ray.dir_x + pose.cos_theta * ray.dir_y, ray.dir_z);
      Surface surface = Surface::kNone;
      double t_hit = kInf;
      double fx = 0.0, fy = 0.0;  // floor point, when the floor is hit
      int goal_class = core::kUnknown;
      double t_goal = kInf;
      bool floor_candidate = false;
      if (ray.region == core::PixelRegion::kFloor) {
        pose.apply(ray.ground_x_m, ray.ground_y_m, &fx, &fy);
        const double t_floor = cam_h / -dir.z();
        if (std::abs(fx) >= field.halfLength() || std::abs(pose.x_m) >= field.halfLength()) {
          goal_class = field.goalHit(origin, dir, t_floor, &t_goal);
        }
        if (goal_class == core::kUnknown) {
          floor_candidate = true;
          t_hit = t_floor;
        }
      } else {
        goal_class = field.goalHit(origin, dir, kInf, &t_goal);
      }
      if (goal_class != core::kUnknown) {
        surface = Surface::kGoal;
        t_hit = t_goal;
      } else if (floor_candidate && std::abs(fx) <= im.hall_x && std::abs(fy) <= im.hall_y) {
        surface = Surface::kFloor;
      } else {
        // Leaves the hall through a wall or the ceiling.
        const double tx = dir.x() > 0   ? (im.hall_x - origin.x()) / dir.x()
                          : dir.x() < 0 ? (-im.hall_x - origin.x()) / dir.x()
                                        : kInf;
        const double ty = dir.y() > 0   ? (im.hall_y - origin.y()) / dir.y()
                          : dir.y() < 0 ? (-im.hall_y - origin.y()) / dir.y()
                                        : kInf;
        const double tz = dir.z() > 0 ? (im.hall_height - origin.z()) / dir.z() : kInf;
        t_hit = std::min({tx, ty, tz});
        surface = t_hit == tz ? Surface::kCeiling : Surface::kWall;
      }

      // Clutter boxes and people can only be met by rays that leave the carpet.
      int box_index = -1, box_axis = 2;
      const bool may_leave_carpet = !robot_on_carpet || !im.model.surelyOnCarpet(i, safe_range);
      if (may_leave_carpet) {
        for (size_t b = 0; b < im.boxes.size(); ++b) {
          int axis = 2;
          const double t = slabHit(origin, dir, im.boxes[b].min_corner, im.boxes[b].max_corner, t_hit, &axis);
          if (t < t_hit) {
            t_hit = t;
            box_index = static_cast<int>(b);
            box_axis = axis;
            surface = Surface::kClutter;
          }
        }
      }

      // Other robots: vertical cylinders with a flat top.
      int robot_index = -1;
      bool robot_top = false;
      const double a2 = dir.x() * dir.x() + dir.y() * dir.y();
      for (size_t r = 0; r < scene.robots.size(); ++r) {
        const RobotObstacle& ob = scene.robots[r];
        const double ox = origin.x() - ob.x_m, oy = origin.y() - ob.y_m;
        const double b = ox * dir.x() + oy * dir.y();
        const double c = ox * ox + oy * oy - ob.radius_m * ob.radius_m;
        if (b >= 0 && c > 0) continue;  // moving away from it
        const double disc = b * b - a2 * c;
        if (disc < 0 || a2 <= 0) continue;
        const double t_side = (-b - std::sqrt(disc)) / a2;
        if (t_side > 0 && t_side < t_hit) {
          const double z = origin.z() + t_side * dir.z();
          if (z >= 0 && z <= ob.height_m) {
            t_hit = t_side;
            robot_index = static_cast<int>(r);
            robot_top = false;
            surface = Surface::kRobot;
            continue;
          }
        }
        if (dir.z() < 0 && origin.z() > ob.height_m) {
          const double t_top = (ob.height_m - origin.z()) / dir.z();
          if (t_top < t_hit) {
            const double px = ox + t_top * dir.x(), py = oy + t_top * dir.y();
            if (px * px + py * py <= ob.radius_m * ob.radius_m) {
              t_hit = t_top;
              robot_index = static_cast<int>(r);
              robot_top = true;
              surface = Surface::kRobot;
            }
          }
        }
      }
      // People: vertical cylinders (their tops are above the camera in practice; a ray from above
      // meets the head's top disc).
      int person_index = -1;
      bool person_top = false;
      if (may_leave_carpet) {
        for (size_t k = 0; k < scene.people.size(); ++k) {
          const Person& pe = scene.people[k];
          const double ox = origin.x() - pe.x_m, oy = origin.y() - pe.y_m;
          const double b = ox * dir.x() + oy * dir.y();
          const double c = ox * ox + oy * oy - pe.radius_m * pe.radius_m;
          if (b >= 0 && c > 0) continue;
          const double disc = b * b - a2 * c;
          if (disc < 0 || a2 <= 0) continue;
          const double t_side = (-b - std::sqrt(disc)) / a2;
          if (t_side > 0 && t_side < t_hit) {
            const double z = origin.z() + t_side * dir.z();
            if (z >= 0 && z <= pe.height_m) {
              t_hit = t_side;
              person_index = static_cast<int>(k);
              person_top = false;
              surface = Surface::kPerson;
              continue;
            }
          }
          if (dir.z() < 0 && origin.z() > pe.height_m) {
            const double t_top = (pe.height_m - origin.z()) / dir.z();
            if (t_top < t_hit) {
              const double px = ox + t_top * dir.x(), py = oy + t_top * dir.y();
              if (px * px + py * py <= pe.radius_m * pe.radius_m) {
                t_hit = t_top;
                person_index = static_cast<int>(k);
                person_top = true;
                surface = Surface::kPerson;
              }
            }
          }
        }
      }
      // The ball.
      Eigen::Vector3d ball_center = Eigen::Vector3d::Zero();
      if (scene.ball) {
        ball_center = Eigen::Vector3d(scene.ball->x_m, scene.ball->y_m, scene.ball->radius_m);
        const Eigen::Vector3d oc = origin - ball_center;
        const double b = oc.dot(dir);
        const double c = oc.squaredNorm() - scene.ball->radius_m * scene.ball->radius_m;
        const double disc = b * b - dir.squaredNorm() * c;
        if (disc >= 0 && b < 0) {
          const double t = (-b - std::sqrt(disc)) / dir.squaredNorm();
          if (t > 0 && t < t_hit) {
            t_hit = t;
            surface = Surface::kBall;
          }
        }
      }

      const Eigen::Vector3d p = origin + t_hit * dir;
      switch (surface) {
        case Surface::kFloor: {
          const uint8_t k = field.floorClass(fx, fy);
          label = k;
          const Material* m = &im.hall_floor;
          float emission = 0.f;
          if (k == core::kWhite) {
            m = &im.line;
          } else if (k == core::kGreen) {
            m = &im.carpet;
          } else if (const Patch* patch = findPatch(im.floor_patches, fx, fy)) {
            m = &patch->material;
            emission = patch->emission;
          }
          // Carpet: fine texture plus slow, large-scale variation of the pile.
          float tex = im.textured(*m, fx, fy);
          if (k == core::kGreen)
            tex *= 1.f + 0.08f * im.texture.sample(static_cast<float>(fx) * 3.f, static_cast<float>(fy) * 3.f + 200.f);
          color = m->albedo * tex * (1.f + emission);
          illumination = lightAt(fx, fy, true);
          break;
        }
        case Surface::kGoal: {
          label = static_cast<uint8_t>(goal_class);
          const Material& m = goal_class == core::kYellow ? im.yellow_goal : im.blue_goal;
          Eigen::Vector3d lo, hi;
          field.goalBox(static_cast<core::ColorClass>(goal_class), &lo, &hi);
          // Top lit best, the face towards the field a little less, the sides least.
          float shade = 0.72f;
          if (std::abs(p.z() - hi.z()) < 1e-6) {
            shade = 1.0f;
          } else if (std::abs(p.x() - lo.x()) < 1e-6 || std::abs(p.x() - hi.x()) < 1e-6) {
            shade = 0.86f;
          }
          color = m.albedo * (shade * im.textured(m, p.x() + p.y(), p.z() + 0.5 * p.y()));
          illumination = lightAt(p.x(), p.y(), false);
          break;
        }
        case Surface::kWall:
        case Surface::kCeiling: {
          label = core::kUnknown;
          const Material* m = &im.wall;
          float emission = 0.f;
          double s = 0.0, t = 0.0;
          const Patch* patch = nullptr;
          if (surface == Surface::kCeiling) {
            m = &im.ceiling;
            s = p.x();
            t = p.y();
            patch = findPatch(im.ceiling_lamps, s, t);
          } else {
            const bool x_wall = std::abs(std::abs(p.x()) - im.hall_x) < std::abs(std::abs(p.y()) - im.hall_y);
            const int w = x_wall ? (p.x() > 0 ? 0 : 1) : (p.y() > 0 ? 2 : 3);
            s = x_wall ? p.y() : p.x();
            t = p.z();
            patch = findPatch(im.wall_patches[w], s, t);
          }
          if (patch) {
            m = &patch->material;
            emission = patch->emission;
          }
          const float shade = surface == Surface::kCeiling ? 0.45f : 0.7f;
          color = m->albedo * (shade * im.textured(*m, s, t) + emission);
          if (surface == Surface::kWall && t < 0.15 && !patch)
            color = Eigen::Vector3f(0.015f, 0.015f, 0.016f);  // skirting
          illumination = lightAt(p.x(), p.y(), false);
          break;
        }
        case Surface::kClutter: {
          label = core::kUnknown;
          const Material& m = im.boxes[box_index].material;
          const float shade = box_axis == 2 ? 1.0f : (box_axis == 0 ? 0.8f : 0.65f);
          color = m.albedo * (shade * im.textured(m, p.x() + p.z(), p.y() - p.z()));
          illumination = lightAt(p.x(), p.y(), false);
          break;
        }
        case Surface::kRobot: {
          label = core::kBlack;
          const RobotObstacle& ob = scene.robots[robot_index];
          float shade = 1.0f;
          if (!robot_top) {
            // Light from above and slightly from +x of the hall: brighter on that side.
            const double nx = (p.x() - ob.x_m) / ob.radius_m, ny = (p.y() - ob.y_m) / ob.radius_m;
            shade = static_cast<float>(0.6 + 0.2 * nx + 0.05 * ny);
          }
          const double angle = std::atan2(p.y() - ob.y_m, p.x() - ob.x_m);
          // A team marker: a band from 55% to 75% of the robot's height.
          const bool marker = im.robot_marker && !robot_top && p.z() > 0.55 * ob.height_m && p.z() < 0.75 * ob.height_m;
          const Material& m = marker ? *im.robot_marker : im.robot;
          color = m.albedo *
                  (shade * im.textured(m, angle * ob.radius_m + 3.0 * robot_index, robot_top ? p.x() + p.y() : p.z()));
          illumination = lightAt(p.x(), p.y(), false);
          break;
        }
        case Surface::kPerson: {
          label = core::kUnknown;
          const Person& pe = scene.people[person_index];
          const double rel = p.z() / pe.height_m;
          const Eigen::Vector3d& rgb = person_top || rel > 0.87 ? pe.skin_rgb
                                       : rel > 0.48             ? pe.shirt_rgb
                                                                : pe.trousers_rgb;
          const Eigen::Vector3f albedo = linearFromSrgb(rgb[0], rgb[1], rgb[2]);
          float shade = 1.0f;
          if (!person_top) {
            const double nx = (p.x() - pe.x_m) / pe.radius_m, ny = (p.y() - pe.y_m) / pe.radius_m;
            shade = static_cast<float>(0.65 + 0.2 * nx + 0.05 * ny);
          }
          const double angle = std::atan2(p.y() - pe.y_m, p.x() - pe.x_m);
          color = albedo * (shade * im.textured(im.wall, angle * pe.radius_m + 5.0 * person_index, p.z()));
          illumination = lightAt(p.x(), p.y(), false);
          break;
        }
        case Surface::kBall: {
          label = core::kOrange;
          const Eigen::Vector3d normal = (p - ball_center) / scene.ball->radius_m;
          const float shade = static_cast<float>(0.35 + 0.65 * std::max(0.0, 0.3 * normal.x() + 0.95 * normal.z()));
          // Patches of the second color: where a smooth pattern on the sphere is high (a third of it).
          const bool patch =
              im.ball_patches &&
              std::sin(5.0 * normal.x()) * std::sin(5.0 * normal.y() + 1.0) * std::sin(5.0 * normal.z() + 2.0) > 0.12;
          const Material& m = patch ? *im.ball_patches : im.ball;
          color = m.albedo * (shade * im.textured(m, normal.x() * 2.0, normal.y() * 2.0 + normal.z()));
          illumination = lightAt(ball_center.x(), ball_center.y(), false);
          break;
        }
        case Surface::kNone:
          color.setZero();
          break;
      }
    }

    // Photometry: light, color temperature, vignetting, exposure, gamma (linear -> 8 bit).
    const float vignette = 1.f - static_cast<float>(light.vignetting) * im.vignette_radius2[n];
    const float scale = illumination * vignette * exposure * (kGammaBins / kGammaMax);
    uint8_t* out = rgb + 3 * i;
    for (int c = 0; c < 3; ++c) {
      const float v = std::max(0.f, color[c] * gains[c] * scale);
      out[c] = gamma_table[v >= kGammaBins ? kGammaBins : static_cast<int>(v)];
    }
    if (saturate) {
      // The camera's color matrix: more or less color about the same grey (Rec. 601 luma).
      const float grey = 0.299f * out[0] + 0.587f * out[1] + 0.114f * out[2];
      for (int c = 0; c < 3; ++c) {
        out[c] = static_cast<uint8_t>(std::clamp(grey + saturation * (out[c] - grey) + 0.5f, 0.f, 255.f));
      }
    }
    labels[i] = label;
  }

  if (light.blur_sigma_px > 0) cv::GaussianBlur(frame.rgb, frame.rgb, cv::Size(0, 0), light.blur_sigma_px);

  // Sensor noise, then the paper's darkening of brightness and contrast (out = f * in).
  cv::Mat noise;
  if (light.noise_sigma > 0) {
    noise.create(height, width, CV_32FC3);
    cv::RNG rng(0x9E3779B97F4A7C15ull ^ scene.noise_seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, light.noise_sigma);
  }
  const float f = static_cast<float>(light.brightness_contrast);
  const float black = static_cast<float>(light.black_level);
  const float* noise_data = noise.empty() ? nullptr : noise.ptr<float>(0);
  const bool transfer = !light.transfer.isIdentity();
  const auto& tables = light.transfer.tables();
  const size_t pixels = static_cast<size_t>(width) * height;
  for (size_t i = 0; i < pixels; ++i) {
    uint8_t* out = rgb + 3 * i;
    if (!im.imaged_mask[i]) {
      out[0] = out[1] = out[2] = 0;
      continue;
    }
    for (int c = 0; c < 3; ++c) {
      const float v = f * (out[c] + (noise_data ? noise_data[3 * i + c] : 0.f) + black) + 0.5f;
      out[c] = static_cast<uint8_t>(std::clamp(v, 0.f, 255.f));
    }
    if (transfer) {
      for (int c = 0; c < 3; ++c) out[c] = tables[c][out[c]];
    }
  }
  return frame;
}

}  // namespace sim
}  // namespace act_color
