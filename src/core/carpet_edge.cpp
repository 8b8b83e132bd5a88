#include "act_color/core/carpet_edge.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "act_color/core/types.hpp"

namespace act_color {
namespace core {

CarpetEdge::CarpetEdge(const OmniCameraModel& camera)
    : width_(camera.width()), height_(camera.height()), cell_start_(kCells + 1, 0) {
  const size_t n = static_cast<size_t>(width_) * height_;
  std::vector<int> cell(n, -1);
  for (size_t i = 0; i < n; ++i) {
    const PixelRay& ray = camera.ray(i);
    if (ray.region != PixelRegion::kFloor && ray.region != PixelRegion::kAboveHorizon) continue;
    double turns = ray.bearing_rad / (2 * M_PI);
    turns -= std::floor(turns);
    const int sector = std::min(kSectors - 1, static_cast<int>(turns * kSectors));
    int bin = kBins;
    if (ray.region == PixelRegion::kFloor) {
      bin = std::min(kBins, static_cast<int>(std::hypot(ray.ground_x_m, ray.ground_y_m) / kBinM));
    }
    cell[i] = sector << 8 | bin;
  }
  for (size_t i = 0; i < n; ++i) {
    if (cell[i] >= 0) ++cell_start_[cell[i] + 1];
  }
  for (int c = 0; c < kCells; ++c) cell_start_[c + 1] += cell_start_[c];
  pixels_.resize(cell_start_[kCells]);
  std::vector<uint32_t> next(cell_start_.begin(), cell_start_.end() - 1);
  for (size_t i = 0; i < n; ++i) {
    if (cell[i] >= 0) pixels_[next[cell[i]]++] = static_cast<uint32_t>(i);
  }
}

uint32_t CarpetEdge::unlabelBeyond(cv::Mat& labels) const {
  if (labels.type() != CV_8UC1 || labels.cols != width_ || labels.rows != height_ || !labels.isContinuous()) return 0;
  uint8_t* l = labels.ptr<uint8_t>();
  const uint32_t* const px = pixels_.data();
  auto begin = [&](int s, int b) { return px + cell_start_[s << 8 | b]; };
  auto end = [&](int s, int b) { return px + cell_start_[(s << 8 | b) + 1]; };
  // The carpet's edge in each sector: its farthest bin with enough green, found from the hall
  // inwards.
  std::array<int, kSectors> edge;
  edge.fill(-1);
  for (int s = 0; s < kSectors; ++s) {
    for (int b = kBins - 1; b >= 0 && edge[s] < 0; --b) {
      uint32_t green = 0;
      for (const uint32_t* p = begin(s, b); p != end(s, b); ++p) green += l[*p] == kGreen;
      const auto imaged = static_cast<uint32_t>(end(s, b) - begin(s, b));
      if (green >= kMinGreenPixels && green >= kMinGreenShare * imaged) edge[s] = b;
    }
  }
  // Beyond `limit`: the farthest edge of the sector and its neighbours, plus the margin. A sector
  // with no green anywhere near keeps everything (nothing is known there).
  auto neighbour = [](int s, int k) { return (s + k + kSectors) % kSectors; };
  const int margin = static_cast<int>(std::ceil(kMarginM / kBinM));
  std::array<int, kSectors> limit;
  for (int s = 0; s < kSectors; ++s) {
    int e = -1;
    for (int k = -kSpreadSectors; k <= kSpreadSectors; ++k) e = std::max(e, edge[neighbour(s, k)]);
    limit[s] = e < 0 ? kBins : e + margin;
  }
  // A robot stands in a sector when black lies within the limit there or in a neighbour; looked at
  // only for sectors with black beyond their limit, from the limit inwards (a robot's body crosses
  // the edge). Nothing within a limit is changed below.
  std::array<int8_t, kSectors> black_within;
  black_within.fill(-1);
  auto blackWithin = [&](int t) {
    if (black_within[t] < 0) {
      black_within[t] = 0;
      for (int b = std::min(limit[t], kBins); b >= 0 && !black_within[t]; --b) {
        for (const uint32_t* p = begin(t, b); p != end(t, b) && !black_within[t]; ++p) {
          black_within[t] = l[*p] == kBlack;
        }
      }
    }
    return black_within[t] == 1;
  };
  uint32_t unlabelled = 0;
  for (int s = 0; s < kSectors; ++s) {
    int robot = -1;  // unknown yet
    for (int b = limit[s] + 1; b <= kBins; ++b) {
      for (const uint32_t* p = begin(s, b); p != end(s, b); ++p) {
        uint8_t& k = l[*p];
        if (k == kBlack && robot < 0) {
          robot = 0;
          for (int i = -kSpreadSectors; i <= kSpreadSectors && !robot; ++i) robot = blackWithin(neighbour(s, i));
        }
        if (k == kWhite || (k == kBlack && !robot)) {
          k = kUnknown;
          ++unlabelled;
        }
      }
    }
  }
  return unlabelled;
}

}  // namespace core
}  // namespace act_color
