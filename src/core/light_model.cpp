#include "act_color/core/light_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace act_color {
namespace core {
namespace {

// Quantile levels per anchor class (chassis, carpet, lines) and the samples each needs. A monotone
// map keeps every channel's quantiles: q(f(X)) = f(q(X)), so matching them recovers f.
const std::array<std::vector<double>, 3> kLevels = {std::vector<double>{0.25, 0.5, 0.75},
                                                    std::vector<double>{0.1, 0.3, 0.5, 0.7, 0.9},
                                                    std::vector<double>{0.25, 0.5, 0.75}};
constexpr std::array<size_t, 3> kMinSamples = {8, 20, 6};
// Slopes of one channel's map between the anchor classes' medians may differ by this factor
// (gamma 1.6 between chassis, carpet and lines: about 1.6; a carpet turned magenta: 19).
constexpr double kMaxSlopeSpread = 4.0;
// The channels' slopes may differ by this factor (color temperature, white balance: about 1.8).
constexpr double kMaxChannelSlopeSpread = 2.5;
// Anchor medians closer than this (channel units) tell no slope.
constexpr double kMinAnchorDistance = 8.0;
constexpr double kMinExtrapolationBase = 24.0;
// Quantiles this close to 0 or 255 are clipped.
constexpr double kClipMargin = 1.5;
// The anchors' quantiles are samples, the lines' the noisiest (a mixture with the carpet whose
// share depends on the view): under a pure gain of 1.14 their ratios scattered from 0.83 to 1.15
// where the carpet's stayed within 0.01 (act_flicker, tuning scenes 0 and 5), and the map through
// them bent every hall color near the lines. Light, exposure, contrast, gamma and white balance all
// map a channel as y = a + b 255 (x / 255)^gamma, or nearly so: the anchors are moved onto the
// curve of that form that fits them best (least squares; gamma on a grid from 1/3 to 3, a gamma
// other than 1 costing kGammaPenalty units^2 of squared error, so that the lines' noise does not
// bend a gain), or, when one anchor misses that curve by more than kMaxCurveResidual, onto the
// curve fitted without it that misses none of the others. A change no such curve describes keeps
// its anchors as seen. The map then follows the curve between the anchors too, every kCurveStep.
// Anchors within kCurveClip of either end of a channel are of a partly clipped distribution (the
// lines' cores after a brightening): they are kept as seen and not fitted.
constexpr double kMaxCurveResidual = 6.0;
constexpr double kGammaPenalty = 60.0;
constexpr double kLnGammaRange = 1.0986;  // ln 3
constexpr int kGammaSteps = 88;
constexpr size_t kMinCurvePoints = 6;
constexpr double kCurveStep = 8.0;
constexpr double kCurveClip = 8.0;

struct Curve {
  double a = 0, b = 0, gamma = 1;
  double operator()(double x) const { return a + b * 255.0 * std::pow(std::max(x, 0.0) / 255.0, gamma); }
};

// Least-squares fits of that form to subsets of a channel's anchor points (x, y).
class CurveFit {
 public:
  explicit CurveFit(const std::vector<std::pair<double, double>>& points) : points_(points) {
    for (int step = 0; step <= kGammaSteps; ++step) {
      const double gamma = std::exp(lnGamma(step));
      for (size_t i = 0; i < points.size(); ++i) {
        u_[static_cast<size_t>(step)][i] = 255.0 * std::pow(std::max(points[i].first, 0.0) / 255.0, gamma);
      }
    }
  }
  static constexpr size_t kMaxPoints = 16;

  // The best curve through the points not excluded, and its largest miss over them; false when no
  // increasing curve fits.
  bool fit(uint32_t excluded, Curve* out, double* miss) const {
    double best_cost = std::numeric_limits<double>::infinity();
    int best_step = 0;
    for (int step = 0; step <= kGammaSteps; ++step) {
      const auto& u = u_[static_cast<size_t>(step)];
      double n = 0, su = 0, sy = 0, suu = 0, suy = 0, syy = 0;
      for (size_t i = 0; i < points_.size(); ++i) {
        if (excluded >> i & 1u) continue;
        const double y = points_[i].second;
        n += 1;
        su += u[i];
        sy += y;
        suu += u[i] * u[i];
        suy += u[i] * y;
        syy += y * y;
      }
      const double var_u = suu - su * su / n, cov = suy - su * sy / n;
      if (var_u < 1e-9 || cov <= 0) continue;
      const double b = cov / var_u;
      const double sse = std::max(0.0, (syy - sy * sy / n) - b * cov);
      const double ln_gamma = lnGamma(step);
      const double cost = sse + (step * 2 == kGammaSteps ? 0.0 : kGammaPenalty);
      if (cost < best_cost) {
        best_cost = cost;
        best_step = step;
        *out = {(sy - b * su) / n, b, std::exp(ln_gamma)};
      }
    }
    if (!std::isfinite(best_cost)) return false;
    *miss = 0;
    const auto& u = u_[static_cast<size_t>(best_step)];
    for (size_t i = 0; i < points_.size(); ++i) {
      if (!(excluded >> i & 1u)) *miss = std::max(*miss, std::abs(out->a + out->b * u[i] - points_[i].second));
    }
    return true;
  }

 private:
  static double lnGamma(int step) { return kLnGammaRange * (2.0 * step / kGammaSteps - 1.0); }
  const std::vector<std::pair<double, double>>& points_;
  std::array<std::array<double, kMaxPoints>, kGammaSteps + 1> u_{};
};

// Moves the points onto the curve fitted to them if it misses none by more than kMaxCurveResidual;
// else onto the best curve fitted without one of them (a quantile of the lines seen in a view unlike
// the reference's: 181 -> 150 under a gain of 1.14) that misses none of the others.
// At least kMinCurvePoints stay; when no curve fits, the points stay as seen.
void smoothOntoCurve(std::vector<std::pair<double, double>>* points) {
  // Quantiles near either end of the channel are of a partly clipped distribution: kept as seen.
  std::vector<std::pair<double, double>> fitted, kept;
  for (const auto& p : *points) {
    const bool inside = std::min(p.first, p.second) >= kCurveClip && std::max(p.first, p.second) <= 255.0 - kCurveClip;
    (inside ? fitted : kept).push_back(p);
  }
  const size_t n = fitted.size();
  if (n < kMinCurvePoints || n > CurveFit::kMaxPoints) return;
  const CurveFit fitter(fitted);
  Curve best;
  double best_miss = std::numeric_limits<double>::infinity();
  auto consider = [&](uint32_t excluded) {
    Curve c;
    double miss = 0;
    if (fitter.fit(excluded, &c, &miss) && miss < best_miss) {
      best = c;
      best_miss = miss;
    }
  };
  consider(0);
  for (size_t i = 0; best_miss > kMaxCurveResidual && i < n && n - 1 >= kMinCurvePoints; ++i) consider(1u << i);
  if (best_miss > kMaxCurveResidual) return;
  // On the curve, also between the anchors: between the carpet and the lines a chord of gamma 1.6
  // misses the curve by 10 units.
  double lo = 255, hi = 0;
  for (auto& [x, y] : fitted) {
    y = best(x);
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  for (double x = lo + kCurveStep; x < hi; x += kCurveStep) fitted.emplace_back(x, best(x));
  fitted.insert(fitted.end(), kept.begin(), kept.end());
  points->swap(fitted);
}

}  // namespace

double LightModel::Map::at(int channel, double x) const {
  const double c = std::clamp(x, 0.0, 256.0);
  const int i = std::min(255, static_cast<int>(c));
  return f[channel][i] + (c - i) * (f[channel][i + 1] - f[channel][i]);
}

Eigen::Vector3d LightModel::Map::apply(const Eigen::Vector3d& color) const {
  return Eigen::Vector3d(at(0, color[0]), at(1, color[1]), at(2, color[2]));
}

double LightModel::Map::maxSlope(const Eigen::Vector3d& x, double half_width) const {
  double slope = 0.0;
  const double h = std::max(half_width, 1.0);
  for (int c = 0; c < 3; ++c) slope = std::max(slope, (at(c, x[c] + h) - at(c, x[c] - h)) / (2.0 * h));
  return slope;
}

void ChannelHistograms::count(const std::vector<Eigen::Vector3f>& colors) {
  for (auto& h : counts) h.fill(0);
  for (const Eigen::Vector3f& color : colors) {
    for (int c = 0; c < 3; ++c) ++counts[c][static_cast<uint8_t>(color[c])];
  }
}

int ChannelHistograms::valueOfRank(int ch, size_t rank) const {
  const std::array<uint32_t, 256>& histogram = counts[static_cast<size_t>(ch)];
  size_t below = 0;
  int value = 0;
  while (value < 255 && below + histogram[value] <= rank) below += histogram[value++];
  return value;
}

void LightModel::observe(const std::vector<Eigen::Vector3f>& green, const std::vector<Eigen::Vector3f>& white,
                         const std::vector<Eigen::Vector3f>& chassis) {
  const std::array<const std::vector<Eigen::Vector3f>*, kAnchorClasses> samples = {&chassis, &green, &white};
  for (int a = 0; a < kAnchorClasses; ++a) {
    auto& q = current_.quantiles[a];
    q.clear();
    const auto& s = *samples[a];
    if (s.size() < kMinSamples[a]) continue;
    q.assign(kLevels[a].size(), Eigen::Vector3d::Zero());
    // Quantiles from a histogram per channel (colors are 8-bit): linear in the samples, no sort.
    histograms_.count(s);
    for (int c = 0; c < 3; ++c) {
      const std::array<uint32_t, 256>& histogram = histograms_.counts[c];
      uint32_t below = 0;  // samples in the bins before `bin`
      int bin = 0;
      for (size_t l = 0; l < kLevels[a].size(); ++l) {
        // The sample of rank pos (0-based, fractional) among the sorted values.
        const double pos = kLevels[a][l] * static_cast<double>(s.size() - 1);
        while (below + histogram[bin] <= pos) below += histogram[bin++];
        const double rank_lo = std::floor(pos);
        const double value_lo = bin;
        // The next rank may lie in a later bin.
        double value_hi = value_lo;
        if (rank_lo + 1 < s.size() && below + histogram[bin] <= rank_lo + 1) {
          int next = bin + 1;
          while (next < 255 && histogram[next] == 0) ++next;
          value_hi = next;
        }
        q[l][c] = value_lo + (pos - rank_lo) * (value_hi - value_lo);
      }
    }
  }
}

bool LightModel::estimate(ColorSpace space, Map* map) const {
  if (!has_reference_ || !observedGreen() || reference_.quantiles[kGreenAnchor].empty()) return false;
  const Eigen::Vector3d& reference_green = referenceGreenMedian();
  const Eigen::Vector3d pivot = LightModel::pivot(space);
  std::array<double, 3> channel_slope = {0.0, 0.0, 0.0};  // 0: no slope seen in the channel
  for (int c = 0; c < 3; ++c) {
    // Anchor points (before, after), and the anchor classes' medians for the slope check.
    std::vector<std::pair<double, double>> points, medians;
    bool top = false;
    int classes = 0;
    for (int a = 0; a < kAnchorClasses; ++a) {
      const auto& cur = current_.quantiles[a];
      const auto& ref = reference_.quantiles[a];
      if (cur.empty() || ref.empty()) continue;
      // A clipped value only bounds where the color went.
      auto clipped = [](double v) { return v <= kClipMargin || v >= 255.0 - kClipMargin; };
      const size_t before = points.size();
      for (size_t l = 0; l < cur.size(); ++l) {
        if (!clipped(cur[l][c]) && !clipped(ref[l][c])) points.emplace_back(ref[l][c], cur[l][c]);
        // Saturated before and after: the top of the channel stays where it is (the clipped core
        // of a line under gamma 1.6 or a brightening; extrapolated instead, the map took 255 some
        // 10 units down and the saturated white cell left the lines).
        top = top || (cur[l][c] >= 255.0 - kClipMargin && ref[l][c] >= 255.0 - kClipMargin);
      }
      if (points.size() == before) continue;
      ++classes;
      const size_t median = cur.size() / 2;
      if (!clipped(cur[median][c]) && !clipped(ref[median][c])) medians.emplace_back(ref[median][c], cur[median][c]);
    }
    if (classes >= 2) smoothOntoCurve(&points);
    if (top) points.emplace_back(255.0, 255.0);
    // One anchor class alone spans too little of the channel: a gain about the channel's zero.
    if (classes < 2 && !points.empty() && std::abs(reference_green[c] - pivot[c]) >= kMinAnchorDistance) {
      points.emplace_back(pivot[c], pivot[c]);
    }
    std::sort(medians.begin(), medians.end());
    double slope_min = 1e9, slope_max = 0.0;
    for (size_t i = 0; i + 1 < medians.size(); ++i) {
      const double dx = medians[i + 1].first - medians[i].first;
      if (dx < kMinAnchorDistance) continue;
      const double slope = (medians[i + 1].second - medians[i].second) / dx;
      slope_min = std::min(slope_min, slope);
      slope_max = std::max(slope_max, slope);
    }
    if (slope_max > 0.0 && (slope_min <= 0.0 || slope_max > kMaxSlopeSpread * slope_min)) return false;
    if (slope_max > 0.0) channel_slope[c] = std::sqrt(slope_min * slope_max);
    // Points with (nearly) the same input are one point; then outputs made non-decreasing by
    // pooling adjacent violators.
    std::sort(points.begin(), points.end());
    struct Block {
      double x, y, n;
    };
    std::vector<Block> blocks;
    for (const auto& [x, y] : points) {
      if (!blocks.empty() && x - blocks.back().x / blocks.back().n < 1.0) {
        blocks.back().x += x;
        blocks.back().y += y;
        blocks.back().n += 1;
      } else {
        blocks.push_back({x, y, 1});
      }
      while (blocks.size() >= 2) {
        Block& b = blocks[blocks.size() - 1];
        Block& a = blocks[blocks.size() - 2];
        if (a.y / a.n <= b.y / b.n) break;
        a.x += b.x;
        a.y += b.y;
        a.n += b.n;
        blocks.pop_back();
      }
    }
    std::vector<std::pair<double, double>> knots;
    for (const Block& b : blocks) knots.emplace_back(b.x / b.n, b.y / b.n);
    if (knots.size() < 2) {
      // One anchor: a gain about the channel's zero through it.
      const double x = knots.empty() ? reference_green[c] : knots[0].first;
      const double y = knots.empty() ? greenMedian()[c] : knots[0].second;
      knots = {{pivot[c], pivot[c]}, {x, y}};
      if (std::abs(x - pivot[c]) < kMinAnchorDistance) knots = {{0.0, 0.0}, {255.0, 255.0}};
      std::sort(knots.begin(), knots.end());
    }
    // Beyond the outer knots the map continues with the slope over the outermost stretch of at
    // least kMinExtrapolationBase (the quantiles of one class lie too close for a slope).
    auto secant = [&](size_t from, int direction) {
      for (size_t j = from; j < knots.size(); j += direction) {
        const double dx = knots[j].first - knots[from].first;
        if (std::abs(dx) >= kMinExtrapolationBase) return (knots[j].second - knots[from].second) / dx;
        if (j == 0 && direction < 0) break;
      }
      const double dx = knots.back().first - knots.front().first;
      return dx > 0 ? (knots.back().second - knots.front().second) / dx : 1.0;
    };
    const double slope_below = secant(0, 1), slope_above = secant(knots.size() - 1, -1);
    size_t segment = 0;
    for (int x = 0; x <= 256; ++x) {
      double y;
      if (x <= knots.front().first) {
        y = knots.front().second + slope_below * (x - knots.front().first);
      } else if (x >= knots.back().first) {
        y = knots.back().second + slope_above * (x - knots.back().first);
      } else {
        while (x > knots[segment + 1].first) ++segment;
        const auto& [x0, y0] = knots[segment];
        const auto& [x1, y1] = knots[segment + 1];
        y = y0 + (y1 - y0) * (x - x0) / (x1 - x0);
      }
      map->f[c][x] = std::clamp(y, 0.0, 256.0);
    }
  }
  // One light changes the channels alike up to its color (white balance, color temperature).
  double lo = 1e9, hi = 0.0;
  for (const double slope : channel_slope) {
    if (slope <= 0.0) continue;
    lo = std::min(lo, slope);
    hi = std::max(hi, slope);
  }
  return hi <= kMaxChannelSlopeSpread * lo || hi == 0.0;
}

void LightModel::follow(double eta) {
  if (!observedGreen()) return;
  for (int a = 0; a < kAnchorClasses; ++a) {
    const auto& cur = current_.quantiles[a];
    auto& ref = reference_.quantiles[a];
    if (cur.empty()) continue;
    if (ref.empty() || !has_reference_) {
      ref = cur;
      continue;
    }
    for (size_t l = 0; l < cur.size(); ++l) ref[l] = (eta * ref[l] + cur[l]) / (eta + 1.0);
  }
  has_reference_ = true;
}

void LightModel::rebase(const Map& map) {
  for (int a = 0; a < kAnchorClasses; ++a) {
    const auto& cur = current_.quantiles[a];
    auto& ref = reference_.quantiles[a];
    if (!cur.empty()) {
      ref = cur;
    } else {
      for (auto& q : ref) q = map.apply(q);
    }
  }
}

void LightModel::reset() { *this = LightModel(); }

}  // namespace core
}  // namespace act_color
