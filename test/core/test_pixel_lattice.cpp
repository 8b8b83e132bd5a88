#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "act_color/core/pixel_lattice.hpp"

using namespace act_color::core;

namespace {

// The nearest other sample to one in the middle of a width x height image, by brute force.
double nearestSample(int stride, int width, int height) {
  const long centre = static_cast<long>(height / 2) * width + width / 2;
  const long start = centre % stride;
  double best = 1e9;
  for (long i = start; i < static_cast<long>(width) * height; i += stride) {
    if (i == centre) continue;
    const double du = static_cast<double>(i % width - centre % width);
    const double dv = static_cast<double>(i / width - centre / width);
    best = std::min(best, std::hypot(du, dv));
  }
  return best;
}

}  // namespace

TEST(PixelLattice, SpacingIsTheDistanceBetweenNeighbouringSamples) {
  for (int stride = 2; stride <= 60; stride += 3) {
    for (int width = stride + 1; width <= 3 * stride; width += 7) {
      EXPECT_DOUBLE_EQ(latticeSpacing(stride, width), nearestSample(stride, width, 4 * stride + 8))
          << "stride " << stride << " width " << width;
    }
  }
  // Every 400th pixel of an 800 px wide image is two columns.
  EXPECT_DOUBLE_EQ(latticeSpacing(400, 800), 1.0);
  EXPECT_DOUBLE_EQ(latticeSpacing(400, 640), 5.0);
}

TEST(PixelLattice, TheChosenStrideSpreadsItsSamplesOverTheImage) {
  for (const int n : {20, 50, 400}) {
    for (int width = 320; width <= 1600; width += 8) {
      const int s = latticeStride(n, width);
      ASSERT_GE(s, n);
      ASSERT_LE(s, n + std::clamp(n / 8, 3, 64));
      // A square lattice of the same density has spacing sqrt(s); the best possible 1.07 sqrt(s).
      EXPECT_GE(latticeSpacing(s, width), 0.6 * std::sqrt(s)) << "n " << n << " width " << width;
    }
  }
  // On an 800 x 600 image, the samples of every 400th pixel from any start leave no 40 x 40 block
  // empty (every 400th pixel proper leaves 798 of 800 columns empty).
  const int width = 800, height = 600, s = latticeStride(400, width), block = 40;
  for (int start = 0; start < s; start += 37) {
    std::set<int> hit;
    for (int i = start; i < width * height; i += s)
      hit.insert((i / width / block) * (width / block) + i % width / block);
    EXPECT_EQ(hit.size(), static_cast<size_t>((width / block) * (height / block))) << "start " << start;
  }
  EXPECT_EQ(latticeStride(1, 800), 1);
  // The largest stride a parameter may take: at most 64 strides above it.
  const int huge = latticeStride(1 << 20, 1280);
  EXPECT_GE(huge, 1 << 20);
  EXPECT_LE(huge, (1 << 20) + 64);
}
