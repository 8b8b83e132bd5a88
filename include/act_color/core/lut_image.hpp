#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "act_color/core/color_lut.hpp"

namespace act_color {
namespace core {

// Images of a color table for people (act_lut export, the trainer's table view in rviz), BGR as
// cv::imwrite takes it.
//
// Layout (act_lut's tests rely on it): a header of 44 px, then the maps in a grid of `cols` columns
// (N <= 4: N; N <= 16: 4; else 8), each map under a label row of 18 px, maps 8 px apart and from
// the left edge, a legend row of 28 px at the bottom; width at least 820 px. A slice map is
// kLutSliceMapPx square (cells of kLutSliceMapPx / 2^bits px), the chroma map kLutChromaMapPx.
constexpr int kLutSliceMapPx = 256;
constexpr int kLutChromaMapPx = 512;

// "R", "G", "B" or "Y", "U", "V".
const char* channelName(ColorSpace space, int channel);

// Slices along the first channel (R or Y): `slices` maps (1 .. 2^bits) of the other two channels,
// x right, y up, each cell in the palette color of the most frequent class of the slice's cells
// other than unknown (dark grey when all are unknown), under `heading`. Throws
// std::invalid_argument for a number of slices out of range.
cv::Mat renderLutSlices(const ColorLut& lut, int slices, const std::string& heading);

// One U-V map: the most frequent class over Y; an RGB table projected with BT.601 (its cells'
// centres), U-V bins no RGB color reaches in light grey.
cv::Mat renderLutChroma(const ColorLut& lut, const std::string& heading);

}  // namespace core
}  // namespace act_color
