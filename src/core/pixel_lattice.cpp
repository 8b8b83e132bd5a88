#include "act_color/core/pixel_lattice.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace act_color {
namespace core {

namespace {
// A stride whose lattice is this near the best in the range is taken: fewer samples cost more than
// a slightly better spread gains.
constexpr double kNearBest = 0.95;
// At most this many strides above n are looked at (bounds the search for huge strides).
constexpr int kMaxExtra = 64;
}  // namespace

double latticeSpacing(int stride, int width) {
  if (stride <= 1 || width <= 0) return 1.0;
  const int64_t s = stride;
  const int64_t r = width % s;  // w v = r v (mod s)
  // Vectors (u, v) with u + r v = 0 (mod s); (s, 0) for v = 0, the shortest u for each v > 0 (the
  // lattice is symmetric about the origin). Beyond v = best no vector can be shorter.
  int64_t best_sq = s * s;
  for (int64_t v = 1; v * v < best_sq; ++v) {
    const int64_t u = ((-r * v) % s + s) % s;
    const int64_t du = std::min(u, s - u);
    best_sq = std::min(best_sq, du * du + v * v);
  }
  return std::sqrt(static_cast<double>(best_sq));
}

int latticeStride(int n, int width) {
  if (n <= 1) return n;
  // Quality: the spacing over that of a square lattice of the same density (sqrt(s)); 1.07 at best.
  const int last = n + std::clamp(n / 8, 3, kMaxExtra);
  double best_quality = 0;
  for (int s = n; s <= last; ++s) best_quality = std::max(best_quality, latticeSpacing(s, width) / std::sqrt(s));
  for (int s = n; s < last; ++s) {
    if (latticeSpacing(s, width) / std::sqrt(s) >= kNearBest * best_quality) return s;
  }
  return last;
}

}  // namespace core
}  // namespace act_color
