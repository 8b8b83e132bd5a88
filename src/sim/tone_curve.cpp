#include "act_color/sim/tone_curve.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <stdexcept>

namespace act_color {
namespace sim {
namespace {

uint8_t toByte(double value) {
  if (!(value > 0.0)) return 0;  // also NaN
  return static_cast<uint8_t>(std::min(255L, std::lround(value)));
}

// A curve from a per-channel function of the input value in [0, 255]. The functions are monotone,
// and rounding and clamping keep them so.
ToneCurve fromFunction(const std::function<double(int channel, double in)>& f) {
  std::array<ToneCurve::Table, 3> tables;
  for (int c = 0; c < 3; ++c) {
    for (int v = 0; v < 256; ++v) tables[c][v] = toByte(f(c, v));
  }
  return ToneCurve(tables);
}

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof(text), pattern, value);
  return text;
}

}  // namespace

ToneCurve::ToneCurve() {
  for (Table& t : tables_) {
    for (int v = 0; v < 256; ++v) t[v] = static_cast<uint8_t>(v);
  }
}

ToneCurve::ToneCurve(const std::array<Table, 3>& tables) : tables_(tables) {
  for (const Table& t : tables_) {
    if (!std::is_sorted(t.begin(), t.end())) throw std::invalid_argument("ToneCurve: tables must be non-decreasing");
  }
}

bool ToneCurve::isIdentity() const {
  for (const Table& t : tables_) {
    for (int v = 0; v < 256; ++v) {
      if (t[v] != v) return false;
    }
  }
  return true;
}

ToneCurve ToneCurve::then(const ToneCurve& next) const {
  std::array<Table, 3> tables;
  for (int c = 0; c < 3; ++c) {
    for (int v = 0; v < 256; ++v) tables[c][v] = next.tables_[c][tables_[c][v]];
  }
  return ToneCurve(tables);
}

void ToneCurve::apply(cv::Mat& rgb) const {
  if (rgb.type() != CV_8UC3) throw std::invalid_argument("ToneCurve::apply: needs a CV_8UC3 image");
  for (int row = 0; row < rgb.rows; ++row) {
    uint8_t* p = rgb.ptr<uint8_t>(row);
    for (int col = 0; col < rgb.cols; ++col, p += 3) {
      p[0] = tables_[0][p[0]];
      p[1] = tables_[1][p[1]];
      p[2] = tables_[2][p[2]];
    }
  }
}

ToneCurve ToneCurve::gain(const Eigen::Vector3d& gain) {
  if (!(gain.minCoeff() >= 0.0)) throw std::invalid_argument("ToneCurve::gain: gains must not be negative");
  return fromFunction([&gain](int c, double in) { return gain[c] * in; });
}

ToneCurve ToneCurve::brightnessContrast(double brightness, double contrast) {
  // A negative factor would turn the curve around: not a change of light or camera.
  if (!(brightness >= 0.0 && contrast >= 0.0)) {
    throw std::invalid_argument("ToneCurve::brightnessContrast: factors must not be negative");
  }
  return fromFunction(
      [brightness, contrast](int, double in) { return ((in - 127.5) * contrast + 127.5) * brightness; });
}

ToneCurve ToneCurve::gamma(double gamma) {
  if (!(gamma > 0.0)) throw std::invalid_argument("ToneCurve::gamma: gamma must be positive");
  return fromFunction([gamma](int, double in) { return 255.0 * std::pow(in / 255.0, gamma); });
}

ToneCurve ToneCurve::whiteBalance(double kelvin_shift) {
  // The renderer's light-color model (relative gains of a color temperature, 1 at 5500 K) at
  // 5500 K + shift, as the camera's fixed white balance sees it; green keeps its level.
  const double t = std::log2(std::max(1000.0, 5500.0 + kelvin_shift) / 5500.0);
  const double r = std::exp2(-0.45 * t), g = std::exp2(-0.05 * t), b = std::exp2(0.65 * t);
  return gain(Eigen::Vector3d(r / g, 1.0, b / g));
}

ToneCurve ToneCurve::blackLevel(double black) {
  if (!(black >= 0.0 && black <= 255.0)) throw std::invalid_argument("ToneCurve::blackLevel: must be in [0, 255]");
  return fromFunction([black](int, double in) { return black + (255.0 - black) * in / 255.0; });
}

ToneCurve ToneCurve::random(std::mt19937& rng, double strength, std::string* description) {
  strength = std::clamp(strength, 0.0, 1.0);
  auto uniform = [&rng](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  const bool darken = uniform(0.0, 1.0) < 0.5;
  // The main change: at strength 1 either the paper's darkening or a 1.6x brightening, reached by
  // one of three camera-like kinds.
  const int kind = std::uniform_int_distribution<int>(0, 2)(rng);
  ToneCurve curve;
  std::string text;
  if (kind == 0) {
    // Gain, slightly different per channel (a light of another color).
    const double g = darken ? 1.0 - 0.5 * strength : 1.0 + 0.6 * strength;
    const Eigen::Vector3d gains(g * (1.0 + 0.06 * strength * uniform(-1, 1)), g,
                                g * (1.0 + 0.06 * strength * uniform(-1, 1)));
    curve = gain(gains);
    text = format("gain%.2f", g);
  } else if (kind == 1) {
    // Brightness and contrast: darkening as in the paper, brightening with some contrast change.
    const double b = darken ? 1.0 - 0.5 * strength : 1.0 + 0.6 * strength;
    const double c = darken ? 1.0 - 0.5 * strength : 1.0 + 0.25 * strength * uniform(-1, 1);
    curve = brightnessContrast(b, c);
    text = format("bc%.2f", b) + format("/%.2f", c);
  } else {
    // Gamma, plus a gain so that the change reaches the strength's level at the mid-tones too.
    const double gm = darken ? 1.0 + 0.6 * strength : 1.0 / (1.0 + 0.6 * strength);
    const double g = darken ? 1.0 - 0.3 * strength : 1.0 + 0.3 * strength;
    curve = gamma(gm).then(gain(Eigen::Vector3d::Constant(g)));
    text = format("gamma%.2f", gm) + format("*%.2f", g);
  }
  // Sometimes a shift of white balance and a raised black level with it.
  if (uniform(0.0, 1.0) < 0.5) {
    const double shift = 1800.0 * strength * uniform(-1, 1);
    curve = curve.then(whiteBalance(shift));
    text += format("+wb%+.0fK", shift);
  }
  if (uniform(0.0, 1.0) < 0.3) {
    const double black = 12.0 * strength * uniform(0, 1);
    curve = curve.then(blackLevel(black));
    text += format("+black%.0f", black);
  }
  if (description) *description = text;
  return curve;
}

}  // namespace sim
}  // namespace act_color
