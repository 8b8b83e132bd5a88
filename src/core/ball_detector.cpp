#include "act_color/core/ball_detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "act_color/core/light_model.hpp"

namespace act_color {
namespace core {
namespace {

// The grid is spaced so that the smallest ball image on the carpet spans this many grid points
// across its narrower extent (one hit is enough: the blob is grown at full resolution). The grid
// is most of the stage's cost.
constexpr double kGridPointsAcrossBall = 1.0;
constexpr int kMinGridStride = 4;
constexpr int kMaxGridStride = 8;
// Ground distances over which the grid spacing and the largest ball image are computed.
constexpr double kNearestDistanceM = 0.3;
constexpr double kDistanceStepM = 0.05;
// Components of more grid points than this many times the largest ball image are not a ball.
constexpr double kMaxAreaFactor = 2.5;
// A blob grows through colors within this many of its grid points' spreads of their mean, and at
// least kGrowMinRadius units (a sphere's shading spans a range of intensities).
constexpr double kGrowSpreads = 3.0;
constexpr double kGrowMinRadius = 30.0;
// A sphere's shading scales its color. From grid points of one color (their spread within
// kGrowMinRadius / kGrowSpreads) a blob also grows through the colors within kGrowMinRadius of that
// color scaled by kShadeLow to kShadeHigh (about LightModel::pivot: black, or YUV's grey for its
// chroma). Within the radius alone, a far pink ball of 36 px grew from its one grid point to its
// lit middle row, 6-9 px, and was never seeded (tuning scene 47: its shading runs from 0.85 to 1.4
// times that point's color). Grid points of mixed colors (a ball beside a grey robot) define no
// such line: grown along it, their blob took in the grey (tuning scene 33).
constexpr double kShadeLow = 0.5;
constexpr double kShadeHigh = 2.0;
// Blobs looked at per cycle at most (those with a point of the ball's class first, then the
// largest). 8 left a far ball of one or two grid points behind specks of noise in most cycles
// (tuning split: 26 -> 27 of 44 scenes with ball recall and precision both >= 0.80 at 16; 32 gave
// the same as 16).
constexpr size_t kMaxBlobs = 16;
// A blob whose area or extents exceed a ball's this many times is not a ball alone.
constexpr double kMaxBallExtent = 2.0;
// labelBallImage: pixels of the ball's class farther from the ball seen than this many times its
// image's extent (in that direction) are not the ball. Beyond the image itself: a sighting's
// position may be a few pixels off (tuning split: 1.5 and 3 gave the same figures).
constexpr double kOneBallReach = 1.5;

constexpr uint8_t kNoSector = 255;     // BallDetector::sectors_ of a pixel that does not see the floor
constexpr uint8_t kGridOff = 0;        // not on the carpet, or not a grid point
constexpr uint8_t kGridBall = 1;       // unknown
constexpr uint8_t kGridCarpet = 2;     // green or white
constexpr uint8_t kGridOther = 3;      // another class
constexpr uint8_t kGridVisited = 4;    // a ball grid point already in a component
constexpr uint8_t kGridBallClass = 5;  // the ball's class
bool ballPoint(uint8_t g) { return g == kGridBall || g == kGridBallClass; }

bool ballCandidate(uint8_t k) { return k == kUnknown || k == kOrange; }

}  // namespace

BallGeometry::BallGeometry(const OmniCameraModel& camera, double radius_m) : camera_(camera), radius_m_(radius_m) {}

bool BallGeometry::expected(double d, Image* out) const {
  const double h = camera_.viewpointHeight() - radius_m_;  // viewpoint above the ball's centre
  const double rho = std::hypot(d, h);
  if (!(rho > radius_m_)) return false;
  const double e_c = -std::atan2(h, d);
  const double a = std::asin(radius_m_ / rho);
  const double r_c = camera_.radiusAtElevation(e_c);
  if (!std::isfinite(r_c)) return false;
  // Edges beyond the table's ends are cut at them (the chassis, the mirror's rim).
  const auto& map = camera_.calibration().elevation_map;
  const double r_lo = camera_.radiusAtElevation(std::max(e_c - a, map.front().second));
  const double r_hi = camera_.radiusAtElevation(std::min(e_c + a, map.back().second));
  // Half the bearing range of the cone at the centre's elevation: cos a = cos^2 e cos b + sin^2 e.
  const double s2 = std::sin(e_c) * std::sin(e_c), c2 = 1.0 - s2;
  const double b = std::acos(std::clamp((std::cos(a) - s2) / c2, -1.0, 1.0));
  out->radial_px = r_hi - r_lo;
  out->tangential_px = 2.0 * b * r_c;
  out->area_px = M_PI / 4.0 * out->radial_px * out->tangential_px;
  out->centre_offset_px = 0.5 * (r_lo + r_hi) - r_c;
  return true;
}

bool BallGeometry::imageEllipse(double x_m, double y_m, Ellipse* out) const {
  const double d = std::hypot(x_m, y_m);
  Image im;
  if (!std::isfinite(d) || !expected(d, &im)) return false;
  const double e_c = -std::atan2(camera_.viewpointHeight() - radius_m_, d);
  double u = 0, v = 0;
  if (!camera_.projectDirection(std::atan2(y_m, x_m), e_c, &u, &v)) return false;
  const CameraCalibration& cal = camera_.calibration();
  const double r = std::hypot(u - cal.center_u, v - cal.center_v);
  if (!(r > 0)) return false;
  out->axis_u = (u - cal.center_u) / r;
  out->axis_v = (v - cal.center_v) / r;
  out->u = u + im.centre_offset_px * out->axis_u;
  out->v = v + im.centre_offset_px * out->axis_v;
  out->half_radial_px = 0.5 * im.radial_px;
  out->half_tangential_px = 0.5 * im.tangential_px;
  return true;
}

uint32_t labelBallImage(const OmniCameraModel& camera, double radius_m, double x_m, double y_m, cv::Mat& labels) {
  BallGeometry::Ellipse e;
  if (labels.type() != CV_8UC1 || labels.cols != camera.width() || labels.rows != camera.height() ||
      !BallGeometry(camera, radius_m).imageEllipse(x_m, y_m, &e) || !(e.half_radial_px > 0) ||
      !(e.half_tangential_px > 0)) {
    return 0;
  }
  const double inv_r2 = 1.0 / (e.half_radial_px * e.half_radial_px);
  const double inv_t2 = 1.0 / (e.half_tangential_px * e.half_tangential_px);
  // (distance from the centre / the ellipse's at that angle)^2
  auto scaled = [&](int u, int v) {
    const double du = u - e.u, dv = v - e.v;
    const double along = du * e.axis_u + dv * e.axis_v, across = dv * e.axis_u - du * e.axis_v;
    return along * along * inv_r2 + across * across * inv_t2;
  };
  const double reach = std::max(e.half_radial_px, e.half_tangential_px);
  const int u0 = std::max(0, static_cast<int>(std::floor(e.u - reach)));
  const int u1 = std::min(labels.cols - 1, static_cast<int>(std::ceil(e.u + reach)));
  const int v0 = std::max(0, static_cast<int>(std::floor(e.v - reach)));
  const int v1 = std::min(labels.rows - 1, static_cast<int>(std::ceil(e.v + reach)));
  uint32_t labelled = 0;
  for (int v = v0; v <= v1; ++v) {
    uint8_t* row = labels.ptr<uint8_t>(v);
    for (int u = u0; u <= u1; ++u) {
      if ((row[u] != kUnknown && row[u] != kWhite) || scaled(u, v) > 1.0) continue;
      const PixelRegion region = camera.ray(u, v).region;
      if (region != PixelRegion::kFloor && region != PixelRegion::kAboveHorizon) continue;
      row[u] = kOrange;
      ++labelled;
    }
  }
  // The ball is one: the ball's class away from it is something of its colors. (memchr: the
  // image has few such pixels, and a byte-wise loop over all of it cost 0.2 ms at 580x580.)
  const size_t cols = static_cast<size_t>(labels.cols);
  for (int v = 0; v < labels.rows; ++v) {
    uint8_t* row = labels.ptr<uint8_t>(v);
    for (auto* p = static_cast<uint8_t*>(std::memchr(row, kOrange, cols)); p;
         p = static_cast<uint8_t*>(std::memchr(p + 1, kOrange, cols - static_cast<size_t>(p + 1 - row)))) {
      if (scaled(static_cast<int>(p - row), v) > kOneBallReach * kOneBallReach) *p = kUnknown;
    }
  }
  return labelled;
}

double BallGeometry::distanceFromRadii(double r_near_px, double r_far_px) const {
  const auto& map = camera_.calibration().elevation_map;
  const double e_near = camera_.elevationAtRadius(std::clamp(r_near_px, map.front().first, map.back().first));
  const double e_far = camera_.elevationAtRadius(std::clamp(r_far_px, map.front().first, map.back().first));
  const double e_c = 0.5 * (e_near + e_far);
  const double h = camera_.viewpointHeight() - radius_m_;
  if (!(e_c < 0) || !(h > 0)) return std::numeric_limits<double>::quiet_NaN();
  return h / std::tan(-e_c);
}

namespace {

// A ball on the carpet: its pixels' view rays pass over the carpet at the ball's top, 2 radii up.
// Their floor points lie up to height / (height - 2 radii) times as far (a ball near a line at
// the field's edge reaches far beyond it in the image).
bool onCarpet(const ExpectedClassModel& model, const std::vector<uint8_t>& sectors, size_t pixel,
              const std::array<double, ExpectedClassModel::kRemovalSectors>& safe, double reach) {
  const uint8_t sector = sectors[pixel];
  if (sector == kNoSector) return false;
  return model.removalRange(pixel) < reach * safe[sector];
}

}  // namespace

BallDetector::BallDetector(const ExpectedClassModel& model, double radius_m) : radius_m_(radius_m) {
  const OmniCameraModel& camera = model.camera();
  const BallGeometry geometry(camera, radius_m);
  const FieldModel& field = model.field();
  const double farthest =
      std::hypot(2.0 * field.halfLength(), 2.0 * (field.halfWidth() + field.calibration().margin_m));
  double smallest = std::numeric_limits<double>::infinity();
  for (double d = kNearestDistanceM; d <= farthest; d += kDistanceStepM) {
    BallGeometry::Image im;
    if (!geometry.expected(d, &im)) continue;
    max_area_px_ = std::max(max_area_px_, im.area_px);
    smallest = std::min(smallest, std::min(im.radial_px, im.tangential_px));
  }
  if (std::isfinite(smallest)) {
    stride_ = std::clamp(static_cast<int>(smallest / kGridPointsAcrossBall), kMinGridStride, kMaxGridStride);
  }
  const double h = camera.viewpointHeight();
  reach_ = h > 2.0 * radius_m ? h / (h - 2.0 * radius_m) : std::numeric_limits<double>::infinity();
  grid_w_ = (camera.width() + stride_ - 1) / stride_;
  grid_h_ = (camera.height() + stride_ - 1) / stride_;
  for (int gy = 0; gy < grid_h_; ++gy) {
    for (int gx = 0; gx < grid_w_; ++gx) {
      const int u = std::min(gx * stride_ + stride_ / 2, camera.width() - 1);
      const int v = std::min(gy * stride_ + stride_ / 2, camera.height() - 1);
      const size_t pixel = static_cast<size_t>(v) * camera.width() + u;
      GridPoint point{static_cast<uint32_t>(gy * grid_w_ + gx),
                      static_cast<uint32_t>(pixel),
                      0.f,
                      static_cast<uint16_t>(u),
                      static_cast<uint16_t>(v),
                      kNoSector};
      if (camera.ray(pixel).region == PixelRegion::kAboveHorizon) beyond_.push_back(point);
      if (camera.ray(pixel).region != PixelRegion::kFloor) continue;
      point.range_m = model.removalRange(pixel);
      point.sector = static_cast<uint8_t>(model.removalSector(pixel));
      points_.push_back(point);
    }
  }
  grid_.assign(static_cast<size_t>(grid_w_) * grid_h_, kGridOff);
  sectors_.assign(model.pixels(), kNoSector);
  for (size_t i = 0; i < model.pixels(); ++i) {
    if (camera.ray(i).region == PixelRegion::kFloor) sectors_[i] = static_cast<uint8_t>(model.removalSector(i));
  }
  window_.assign(model.pixels(), -1);
}

inline uint8_t BallDetector::classOf(const ColorLut& lut, const std::vector<KnownColor>& known_colors,
                                     const uint8_t c[3]) {
  const uint8_t k = lut.classOf(c[0], c[1], c[2]);
  return k != kUnknown ? k : knownClassOf(known_colors, c);
}

uint8_t BallDetector::knownClassOf(const std::vector<KnownColor>& known_colors, const uint8_t c[3]) {
  const Eigen::Vector3f color(c[0], c[1], c[2]);
  const KnownColor* nearest = nullptr;
  float nearest_ratio = 1.f;  // squared distance over squared radius
  for (const KnownColor& known : known_colors) {
    const Eigen::Vector3f d = color - known.mean;
    float sq = d.squaredNorm();
    if (known.yuv) {
      sq -= (1.f - known.intensity_weight) * d[0] * d[0];
    } else {
      const float sum = d.sum();
      sq -= (1.f - known.intensity_weight) * sum * sum / 3.f;
    }
    if (sq < nearest_ratio * known.radius_sq) {
      nearest = &known;
      nearest_ratio = sq / known.radius_sq;
    }
  }
  return nearest && !nearest->ball ? kGreen : kUnknown;  // kGreen: known, not the ball's
}

void BallDetector::detect(const ExpectedClassModel& model, const ImageView& image, const ColorLut& lut,
                          const SafeRanges& safe, const std::vector<KnownColor>& known, std::vector<BallBlob>* blobs,
                          std::vector<uint32_t>* off_field_ball, uint32_t phase, bool look_off_field) {
  blobs->clear();
  off_field_ball->clear();
  const int width = image.width, height = image.height;
  // The look off the field moves within the grid's cells from cycle to cycle.
  const int du = static_cast<int>(phase % stride_) - stride_ / 2,
            dv = static_cast<int>((phase / stride_) % stride_) - stride_ / 2;
  auto tableClass = [&](uint32_t pixel) {
    uint8_t c[3];
    image.color(static_cast<int>(pixel % width), static_cast<int>(pixel / width), c);
    return lut.classOf(c[0], c[1], c[2]);
  };
  // The grid's classes (every floor point is written: last cycle's marks need no clearing).
  ball_points_.clear();
  withPixels(image, [&](const auto& pixels) {
    // A grid point's pixel of this cycle's look off the field, if it is one of the ball's class.
    auto lookOffField = [&](const GridPoint& p) {
      const int u = p.u + du, v = p.v + dv;
      if (u < 0 || v < 0 || u >= width || v >= height) return;
      const uint32_t q = static_cast<uint32_t>(v * width + u);
      uint8_t c[3];
      pixels.color(q, u, v, c);
      if (lut.classOf(c[0], c[1], c[2]) == kOrange) off_field_ball->push_back(q);
    };
    for (const GridPoint& p : points_) {
      uint8_t g = kGridOff;
      if (!ExpectedClassModel::mayBeOffField(p.range_m, safe[p.sector])) {
        uint8_t c[3];
        pixels.color(p.pixel, p.u, p.v, c);
        const uint8_t k = classOf(lut, known, c);
        g = k == kOrange                   ? kGridBallClass
            : k == kUnknown                ? kGridBall
            : (k == kGreen || k == kWhite) ? kGridCarpet
                                           : kGridOther;
        if (ballPoint(g)) ball_points_.push_back(p.cell);
      } else if (look_off_field) {
        lookOffField(p);
      }
      grid_[p.cell] = g;
    }
    if (look_off_field) {
      for (const GridPoint& p : beyond_) lookOffField(p);
    }
  });
  // Connected components of ball grid points (8-neighbourhood), the largest first.
  components_.clear();
  component_.clear();
  const size_t max_points = static_cast<size_t>(kMaxAreaFactor * max_area_px_ / (stride_ * stride_)) + 4;
  for (const uint32_t start : ball_points_) {
    if (!ballPoint(grid_[start])) continue;
    const size_t begin = component_.size();
    bool of_class = grid_[start] == kGridBallClass;
    stack_.assign(1, start);
    grid_[start] = kGridVisited;
    while (!stack_.empty()) {
      const uint32_t cell = stack_.back();
      stack_.pop_back();
      component_.push_back(cell);
      const int gx = static_cast<int>(cell % grid_w_), gy = static_cast<int>(cell / grid_w_);
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = gx + dx, y = gy + dy;
          if (x < 0 || y < 0 || x >= grid_w_ || y >= grid_h_) continue;
          const uint32_t n = static_cast<uint32_t>(y * grid_w_ + x);
          if (!ballPoint(grid_[n])) continue;
          of_class = of_class || grid_[n] == kGridBallClass;
          grid_[n] = kGridVisited;
          stack_.push_back(n);
        }
      }
    }
    if (component_.size() - begin > max_points) {
      component_.resize(begin);  // far larger than a ball: an untrained region
      continue;
    }
    components_.push_back({begin, component_.size(), of_class});
  }
  // Those with a point of the ball's class first: a small far ball of one or two grid points is
  // otherwise one of many specks of noise on a dark carpet, looked at in some cycles only.
  std::sort(components_.begin(), components_.end(), [](const Component& a, const Component& b) {
    return std::make_pair(a.of_ball_class, a.end - a.begin) > std::make_pair(b.of_ball_class, b.end - b.begin);
  });
  if (components_.size() > kMaxBlobs) components_.resize(kMaxBlobs);
  for (const Component& c : components_) {
    seeds_.clear();
    for (size_t j = c.begin; j < c.end; ++j) {
      const uint32_t cell = component_[j];
      const int u = std::min(static_cast<int>(cell % grid_w_) * stride_ + stride_ / 2, width - 1);
      const int v = std::min(static_cast<int>(cell / grid_w_) * stride_ + stride_ / 2, image.height - 1);
      seeds_.push_back(static_cast<uint32_t>(v * width + u));
    }
    BallBlob blob;
    measure(model, image, lut, safe, known, &blob);
    if (blob.pixels == 0) continue;
    // A ball beside a grey region unknown to the table (the floor beyond the carpet's edge, a
    // shadow) makes one component with it, and its blob, grown through colors near both, is
    // several balls large. Grown again from the points of the ball's class alone, it is the ball.
    if (blob.ball_pixels > 0 &&
        std::max({blob.area_ratio, blob.radial_ratio, blob.tangential_ratio}) > kMaxBallExtent) {
      const size_t all = seeds_.size();
      seeds_.erase(std::remove_if(seeds_.begin(), seeds_.end(), [&](uint32_t p) { return tableClass(p) != kOrange; }),
                   seeds_.end());
      if (!seeds_.empty() && seeds_.size() < all) {
        BallBlob ball;
        measure(model, image, lut, safe, known, &ball);
        if (ball.pixels > 0) blob = std::move(ball);
      }
    }
    blobs->push_back(std::move(blob));
  }
}

void BallDetector::measure(const ExpectedClassModel& model, const ImageView& image, const ColorLut& lut,
                           const SafeRanges& safe, const std::vector<KnownColor>& known, BallBlob* blob) {
  const std::vector<uint32_t>& seeds = seeds_;
  const int width = image.width, height = image.height;
  const CameraCalibration& cal = model.camera().calibration();
  const BallGeometry geometry(model.camera(), radius_m_);
  // The blob grows at full resolution from the grid points, within their box plus one spacing.
  int u0 = width, u1 = -1, v0 = height, v1 = -1;
  for (const uint32_t s : seeds) {
    const int u = static_cast<int>(s % width), v = static_cast<int>(s / width);
    u0 = std::min(u0, u);
    u1 = std::max(u1, u);
    v0 = std::min(v0, v);
    v1 = std::max(v1, v);
  }
  // The grid points lie surely on the carpet; the ball's far part may be seen beyond its edge
  // (onCarpet's reach): the blob may grow by the ball's expected extent around them, through
  // colors near the grid points' own (not into the hall's floor behind the ball).
  int margin = stride_;
  {
    const uint32_t s = seeds[seeds.size() / 2];
    BallGeometry::Image im;
    if (geometry.expected(model.removalRange(s), &im)) {
      margin += static_cast<int>(std::ceil(0.5 * std::max(im.radial_px, im.tangential_px)));
    }
  }
  u0 = std::max(0, u0 - margin);
  v0 = std::max(0, v0 - margin);
  u1 = std::min(width - 1, u1 + margin);
  v1 = std::min(height - 1, v1 + margin);
  Eigen::Vector3d seed_mean(0, 0, 0);
  for (const uint32_t s : seeds) {
    uint8_t c[3];
    image.color(static_cast<int>(s % width), static_cast<int>(s / width), c);
    seed_mean += Eigen::Vector3d(c[0], c[1], c[2]);
  }
  seed_mean /= static_cast<double>(seeds.size());
  double seed_sq = 0;
  for (const uint32_t s : seeds) {
    uint8_t c[3];
    image.color(static_cast<int>(s % width), static_cast<int>(s / width), c);
    seed_sq += (Eigen::Vector3d(c[0], c[1], c[2]) - seed_mean).squaredNorm();
  }
  const double seed_spread = std::sqrt(seed_sq / std::max<size_t>(1, seeds.size() - 1));
  const double grow_radius = std::max(kGrowMinRadius, kGrowSpreads * seed_spread);
  const double grow_radius_sq = grow_radius * grow_radius;
  const bool one_color = kGrowSpreads * seed_spread <= kGrowMinRadius;
  ShadeLine shade = LightModel::shadeLine(seed_mean, lut.colorSpace());
  const double seed_position = shade.position(seed_mean);
  shade.from = kShadeLow * seed_position;
  shade.to = kShadeHigh * seed_position;
  shade.tolerance = grow_radius;
  auto nearSeedColor = [&](const Eigen::Vector3d& color) {
    return (color - seed_mean).squaredNorm() <= grow_radius_sq || (one_color && shade.contains(color));
  };
  // window_: -1 not looked at, 0 looked at and not in the blob, 1 in the blob.
  auto look = [&](uint32_t pixel, int u, int v) {
    int8_t& mark = window_[pixel];
    if (mark >= 0) return false;
    mark = 0;
    if (!onCarpet(model, sectors_, pixel, safe, reach_)) return false;
    uint8_t c[3];
    image.color(u, v, c);
    const uint8_t k = classOf(lut, known, c);
    if (!ballCandidate(k)) return false;
    if (!nearSeedColor(Eigen::Vector3d(c[0], c[1], c[2]))) return false;
    mark = 1;
    if (k == kOrange) ++blob->ball_pixels;
    return true;
  };
  looked_.clear();
  pixel_stack_.clear();
  for (const uint32_t s : seeds) {
    if (look(s, static_cast<int>(s % width), static_cast<int>(s / width))) pixel_stack_.push_back(s);
    looked_.push_back(s);
  }
  while (!pixel_stack_.empty()) {
    const uint32_t p = pixel_stack_.back();
    pixel_stack_.pop_back();
    blob->members.push_back(p);
    const int u = static_cast<int>(p % width), v = static_cast<int>(p / width);
    const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
    for (int n = 0; n < 4; ++n) {
      const int x = u + du[n], y = v + dv[n];
      if (x < u0 || x > u1 || y < v0 || y > v1) continue;
      const uint32_t q = static_cast<uint32_t>(y * width + x);
      if (window_[q] >= 0) continue;
      looked_.push_back(q);
      if (look(q, x, y)) pixel_stack_.push_back(q);
    }
  }
  blob->pixels = static_cast<uint32_t>(blob->members.size());
  if (blob->pixels == 0) {
    for (const uint32_t q : looked_) window_[q] = -1;
    return;
  }
  // Shape in polar coordinates about the mirror's axis.
  double su = 0, sv = 0;
  for (const uint32_t p : blob->members) {
    su += p % width;
    sv += p / width;
  }
  blob->centroid_u = su / blob->pixels;
  blob->centroid_v = sv / blob->pixels;
  const double phi_c = std::atan2(blob->centroid_v - cal.center_v, blob->centroid_u - cal.center_u);
  // Across the radius: the offset along the tangent at the centroid (a ball is small against its
  // distance from the mirror's axis).
  const double tu = -std::sin(phi_c), tv = std::cos(phi_c);
  double r_min = std::numeric_limits<double>::infinity(), r_max = 0, t_min = 0, t_max = 0;
  for (const uint32_t p : blob->members) {
    const double du = static_cast<double>(p % width) - cal.center_u, dv = static_cast<double>(p / width) - cal.center_v;
    const double r = std::sqrt(du * du + dv * dv);
    const double t = (du - (blob->centroid_u - cal.center_u)) * tu + (dv - (blob->centroid_v - cal.center_v)) * tv;
    r_min = std::min(r_min, r);
    r_max = std::max(r_max, r);
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
  }
  blob->r_near_px = r_min - 0.5;
  blob->r_far_px = r_max + 0.5;
  const double radial = blob->r_far_px - blob->r_near_px;
  const double tangential = t_max - t_min + 1.0;
  blob->fill = blob->pixels / (M_PI / 4.0 * radial * tangential);
  blob->distance_m = geometry.distanceFromRadii(blob->r_near_px, blob->r_far_px);
  const double bearing = cal.bearing_sign * phi_c + cal.bearing_offset_rad;
  BallGeometry::Image expected;
  if (std::isfinite(blob->distance_m) && geometry.expected(blob->distance_m, &expected)) {
    blob->base_x_m = blob->distance_m * std::cos(bearing);
    blob->base_y_m = blob->distance_m * std::sin(bearing);
    blob->radial_ratio = radial / expected.radial_px;
    blob->tangential_ratio = tangential / expected.tangential_px;
    blob->area_ratio = blob->pixels / expected.area_px;
  }
  // Interior pixels, and the colors.
  blob->interior.assign(blob->members.size(), 0);
  std::array<std::vector<uint8_t>, 3>& channels = channels_;
  for (auto& values : channels) values.clear();
  Eigen::Vector3d sum(0, 0, 0);
  std::vector<Eigen::Vector3d>& colors = colors_;
  colors.clear();
  for (size_t j = 0; j < blob->members.size(); ++j) {
    const uint32_t p = blob->members[j];
    const int u = static_cast<int>(p % width), v = static_cast<int>(p / width);
    const bool inner = u > 0 && v > 0 && u + 1 < width && v + 1 < height && window_[p + 1] == 1 &&
                       window_[p - 1] == 1 && window_[p + width] == 1 && window_[p - width] == 1;
    blob->interior[j] = inner ? 1 : 0;
  }
  const size_t inner_count = static_cast<size_t>(std::count(blob->interior.begin(), blob->interior.end(), 1));
  const bool use_inner = inner_count >= 5;
  for (size_t j = 0; j < blob->members.size(); ++j) {
    if (use_inner && !blob->interior[j]) continue;
    const uint32_t p = blob->members[j];
    uint8_t c[3];
    image.color(static_cast<int>(p % width), static_cast<int>(p / width), c);
    for (int ch = 0; ch < 3; ++ch) channels[ch].push_back(c[ch]);
    colors.emplace_back(c[0], c[1], c[2]);
    sum += colors.back();
  }
  for (int ch = 0; ch < 3; ++ch) {
    auto& values = channels[ch];
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    blob->median[ch] = values[values.size() / 2];
  }
  const Eigen::Vector3d mean = sum / static_cast<double>(colors.size());
  double sq = 0;
  for (const auto& c : colors) sq += (c - mean).squaredNorm();
  blob->spread = colors.size() > 1 ? std::sqrt(sq / (colors.size() - 1.0)) : 0.0;
  // What lies around the blob: a ball rests on the carpet.
  const int grow = std::max(2, static_cast<int>(std::lround(0.25 * std::max(radial, tangential))));
  int bu0 = width, bu1 = -1, bv0 = height, bv1 = -1;
  for (const uint32_t p : blob->members) {
    const int u = static_cast<int>(p % width), v = static_cast<int>(p / width);
    bu0 = std::min(bu0, u);
    bu1 = std::max(bu1, u);
    bv0 = std::min(bv0, v);
    bv1 = std::max(bv1, v);
  }
  uint32_t around = 0, carpet = 0;
  for (int v = std::max(0, bv0 - grow); v <= std::min(height - 1, bv1 + grow); v += 2) {  // every other
    for (int u = std::max(0, bu0 - grow); u <= std::min(width - 1, bu1 + grow); u += 2) {
      const size_t p = static_cast<size_t>(v) * width + u;
      if (window_[p] == 1) continue;
      if (!onCarpet(model, sectors_, p, safe, 1.0)) continue;  // behind a ball near the edge: the hall
      ++around;
      uint8_t c[3];
      image.color(u, v, c);
      const uint8_t k = classOf(lut, known, c);
      carpet += k == kGreen || k == kWhite;
    }
  }
  blob->surround = around ? static_cast<double>(carpet) / around : 0.0;
  for (const uint32_t q : looked_) window_[q] = -1;
}

}  // namespace core
}  // namespace act_color
