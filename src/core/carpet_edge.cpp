#include "act_color/core/carpet_edge.hpp"

#include <algorithm>
#include <cmath>

#include "act_color/core/types.hpp"

namespace act_color {
namespace core {

CarpetEdge::CarpetEdge(const OmniCameraModel& camera)
    : width_(camera.width()),
      height_(camera.height()),
      cell_(static_cast<size_t>(camera.width()) * camera.height(), kNoCell),
      pixels_in_cell_(kSectors << 8, 0) {
  for (size_t i = 0; i < cell_.size(); ++i) {
    const PixelRay& ray = camera.ray(i);
    if (ray.region != PixelRegion::kFloor && ray.region != PixelRegion::kAboveHorizon) continue;
    double turns = ray.bearing_rad / (2 * M_PI);
    turns -= std::floor(turns);
    const int sector = std::min(kSectors - 1, static_cast<int>(turns * kSectors));
    int bin = kBins;
    if (ray.region == PixelRegion::kFloor) {
      bin = std::min(kBins, static_cast<int>(std::hypot(ray.ground_x_m, ray.ground_y_m) / kBinM));
    }
    cell_[i] = static_cast<uint16_t>(sector << 8 | bin);
    ++pixels_in_cell_[cell_[i]];
  }
}

uint32_t CarpetEdge::unlabelBeyond(cv::Mat& labels) const {
  if (labels.type() != CV_8UC1 || labels.cols != width_ || labels.rows != height_ || !labels.isContinuous()) return 0;
  uint8_t* l = labels.ptr<uint8_t>();
  const size_t n = cell_.size();
  // Per cell the green pixels; per sector the nearest bin labelled black.
  std::vector<uint32_t> green(kSectors << 8, 0);
  std::vector<int> nearest_black(kSectors, kBins + 1);
  for (size_t i = 0; i < n; ++i) {
    if (cell_[i] == kNoCell) continue;
    if (l[i] == kGreen) {
      ++green[cell_[i]];
    } else if (l[i] == kBlack) {
      int& b = nearest_black[cell_[i] >> 8];
      b = std::min(b, cell_[i] & 0xff);
    }
  }
  // The carpet's edge in each sector: its farthest bin with enough green.
  std::vector<int> edge(kSectors, -1);
  for (int s = 0; s < kSectors; ++s) {
    for (int b = kBins - 1; b >= 0; --b) {
      const uint32_t g = green[s << 8 | b];
      if (g >= kMinGreenPixels && g >= kMinGreenShare * pixels_in_cell_[s << 8 | b]) {
        edge[s] = b;
        break;
      }
    }
  }
  // Beyond `limit`: the farthest edge of the sector and its neighbours, plus the margin. A sector
  // with no green anywhere near keeps everything (nothing is known there).
  auto neighbours = [](int s, int k) { return (s + k + kSectors) % kSectors; };
  const int margin = static_cast<int>(std::ceil(kMarginM / kBinM));
  std::vector<int> limit(kSectors);
  for (int s = 0; s < kSectors; ++s) {
    int e = -1;
    for (int k = -kSpreadSectors; k <= kSpreadSectors; ++k) e = std::max(e, edge[neighbours(s, k)]);
    limit[s] = e < 0 ? kBins : e + margin;
  }
  // A robot stands in a sector when black lies within its limit there or in a neighbour.
  std::vector<uint8_t> robot(kSectors, 0);
  for (int s = 0; s < kSectors; ++s) {
    for (int k = -kSpreadSectors; k <= kSpreadSectors; ++k) {
      const int t = neighbours(s, k);
      robot[s] = robot[s] || nearest_black[t] <= limit[t];
    }
  }
  uint32_t unlabelled = 0;
  for (size_t i = 0; i < n; ++i) {
    if (cell_[i] == kNoCell) continue;
    const int s = cell_[i] >> 8;
    if ((cell_[i] & 0xff) <= limit[s]) continue;
    if (l[i] == kWhite || (l[i] == kBlack && !robot[s])) {
      l[i] = kUnknown;
      ++unlabelled;
    }
  }
  return unlabelled;
}

}  // namespace core
}  // namespace act_color
