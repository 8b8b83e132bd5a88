// act_lut: inspects and converts the color table files the trainer's ~save_lut writes
// (include/act_color/ros/lut_file.hpp); needs no ROS master. See README.md, "act_lut".
//   act_lut info FILE
//   act_lut export FILE --output PNG [--slices N | --chroma]
//   act_lut to-nubot FILE --output CTableBGR.dat|CTable.dat
//   act_lut from-nubot CTABLE.dat --output FILE [--color-space rgb|yuv] [--bits B]
//
// NuBot's tables (nubot-nudt/nubot_ws: omni_vision/src/colorsegment.cpp reads them, the
// color_segment tool's calibration_dialog.cpp writes them, omni_vision/.../ballfinder.h names the
// classes): 64^3 bytes, one class code per cell, cell = (c0 / 4) * 4096 + (c1 / 4) * 64 + c2 / 4 over
// the bytes of a pixel as they lie in memory. CTableBGR.dat is for OpenCV's BGR images (c0 B, c1 G,
// c2 R); CTable.dat for the image converted with cv::cvtColor(BGR2YUV) (c0 Y, c1 U, c2 V). Codes:
// 0 ball ("yellow represent for football"), 1 black (obstacles), 2 green (field), 3 unknown; their
// lines are found by brightness along scan lines, not by the table, and there are no goal classes.
//
// Image layout of `export` (tests rely on it): a header of kHeaderPx, then the maps in a grid of
// `cols` columns (N <= 4: N; N <= 16: 4; else 8), each map under a label row of kLabelPx, maps
// kPadPx apart and from the left edge, a legend row of kLegendPx at the bottom; width at least
// kMinWidthPx. A slice map is 256 px square (cells of 256 / 2^bits px), the chroma map 512 px.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "act_color/ColorLut.h"
#include "act_color/core/color_lut.hpp"
#include "act_color/core/types.hpp"
#include "act_color/ros/conversions.hpp"
#include "act_color/ros/lut_file.hpp"

namespace {

namespace core = act_color::core;
namespace conv = act_color::ros_conversions;

const char* const kUsage =
    "usage: act_lut info FILE                                  what a table file holds\n"
    "       act_lut export FILE --output PNG [--slices N]      the table as slices of its color cube\n"
    "       act_lut export FILE --output PNG --chroma          one U-V map, the most frequent class over Y\n"
    "       act_lut to-nubot FILE --output CTABLE.dat           NuBot's 64^3 table\n"
    "       act_lut from-nubot CTABLE.dat --output FILE [--color-space rgb|yuv] [--bits B]\n"
    "  FILE                 a color table file (the trainer's ~save_lut)\n"
    "  --slices N           slices along the first channel (R or Y), 1 .. 2^bits (default 8); each a map\n"
    "                       of the other two channels (x right, y up) with the most frequent class of the\n"
    "                       slice's cells other than unknown; unknown (dark grey) when all are unknown\n"
    "  --chroma             instead: a U-V map; an RGB table is projected with BT.601 (its cells' centres)\n"
    "  --color-space S      the NuBot file's layout: rgb for CTableBGR.dat (B, G, R), yuv for CTable.dat\n"
    "                       (Y, U, V); default from the file's name\n"
    "  --bits B             bits per channel of the table written by from-nubot (default 6; others resampled)\n"
    "Classes to NuBot: orange -> 0 ball, black -> 1, green -> 2, everything else -> 3 unknown (NuBot has\n"
    "no white, yellow or blue class). From NuBot: 0 -> orange, 1 -> black, 2 -> green, 3 -> unknown.\n"
    "Exit status: 0 done, 1 a file that cannot be read or written, 2 wrong arguments.\n";

int usage(const std::string& message) {
  std::cerr << "act_lut: " << message << "\n" << kUsage;
  return 2;
}

// A file that cannot be used: exit status 1.
struct FileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// ---------------------------------------------------------------------------------------------
// NuBot's table

constexpr int kNubotBits = 6;
constexpr size_t kNubotCells = size_t{1} << (3 * kNubotBits);
enum NubotCode : uint8_t { kNubotBall = 0, kNubotBlack = 1, kNubotGreen = 2, kNubotUnknown = 3 };
constexpr int kNubotCodes = 4;
const char* const kNubotNames[kNubotCodes] = {"ball", "black", "green", "unknown"};

uint8_t toNubot(uint8_t class_id) {
  switch (class_id) {
    case core::kOrange:
      return kNubotBall;  // our ball class, whatever the ball's color
    case core::kBlack:
      return kNubotBlack;
    case core::kGreen:
      return kNubotGreen;
    default:
      return kNubotUnknown;  // unknown, white, yellow, blue (and ids that are no class)
  }
}

uint8_t fromNubot(uint8_t code) {
  static const uint8_t kOurs[kNubotCodes] = {core::kOrange, core::kBlack, core::kGreen, core::kUnknown};
  return kOurs[code];
}

// The file's layout: which of our channels (c0, c1, c2 of the table) is the major index.
// CTableBGR.dat indexes B, G, R, the reverse of an RGB table's R, G, B; CTable.dat indexes Y, U, V
// like a YUV table.
size_t nubotIndex(core::ColorSpace space, uint32_t i0, uint32_t i1, uint32_t i2) {
  if (space == core::ColorSpace::kRgb) std::swap(i0, i2);
  return (size_t{i0} << (2 * kNubotBits)) | (size_t{i1} << kNubotBits) | i2;
}

const char* nubotLayout(core::ColorSpace space) {
  return space == core::ColorSpace::kRgb ? "CTableBGR.dat layout (index B/4*4096 + G/4*64 + R/4)"
                                         : "CTable.dat layout (index Y/4*4096 + U/4*64 + V/4)";
}

// The codes of a cube of 2^from cells per channel (index c0 << 2b | c1 << b | c2) at 2^to cells
// per channel. Finer: every cell takes the code of the cell it lies in (nothing changes). Coarser:
// the most frequent code of the cells it covers, ties to the lowest code (NuBot: ball, black,
// green before unknown).
std::vector<uint8_t> resample(const std::vector<uint8_t>& in, int from_bits, int to_bits) {
  const uint32_t n_out = 1u << to_bits;
  std::vector<uint8_t> out(size_t{1} << (3 * to_bits));
  if (to_bits >= from_bits) {
    const int shift = to_bits - from_bits;
    for (uint32_t i0 = 0; i0 < n_out; ++i0) {
      for (uint32_t i1 = 0; i1 < n_out; ++i1) {
        for (uint32_t i2 = 0; i2 < n_out; ++i2) {
          const size_t src =
              (size_t{i0 >> shift} << (2 * from_bits)) | (size_t{i1 >> shift} << from_bits) | (i2 >> shift);
          out[(size_t{i0} << (2 * to_bits)) | (size_t{i1} << to_bits) | i2] = in[src];
        }
      }
    }
    return out;
  }
  const int shift = from_bits - to_bits;
  const uint32_t block = 1u << shift;
  std::vector<uint32_t> counts(256);
  for (uint32_t o0 = 0; o0 < n_out; ++o0) {
    for (uint32_t o1 = 0; o1 < n_out; ++o1) {
      for (uint32_t o2 = 0; o2 < n_out; ++o2) {
        std::fill(counts.begin(), counts.end(), 0u);
        for (uint32_t d0 = 0; d0 < block; ++d0) {
          for (uint32_t d1 = 0; d1 < block; ++d1) {
            for (uint32_t d2 = 0; d2 < block; ++d2) {
              const size_t src = (size_t{(o0 << shift) | d0} << (2 * from_bits)) |
                                 (size_t{(o1 << shift) | d1} << from_bits) | ((o2 << shift) | d2);
              ++counts[in[src]];
            }
          }
        }
        out[(size_t{o0} << (2 * to_bits)) | (size_t{o1} << to_bits) | o2] =
            static_cast<uint8_t>(std::max_element(counts.begin(), counts.end()) - counts.begin());
      }
    }
  }
  return out;
}

std::string baseName(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// ---------------------------------------------------------------------------------------------
// Our table files

struct Table {
  act_color::ColorLut msg;
  core::ColorLut lut;
};

Table loadTable(const std::string& path) {
  Table t;
  std::string error;
  if (!conv::loadLutFile(path, &t.msg, &error)) throw FileError(error);
  if (!conv::fromMsg(t.msg, &t.lut, &error)) throw FileError(path + ": " + error);
  return t;
}

const char* spaceName(core::ColorSpace space) { return space == core::ColorSpace::kYuv ? "yuv" : "rgb"; }

const char* channelName(core::ColorSpace space, int channel) {
  static const char* const kRgb[3] = {"R", "G", "B"};
  static const char* const kYuv[3] = {"Y", "U", "V"};
  return (space == core::ColorSpace::kYuv ? kYuv : kRgb)[channel];
}

// ---------------------------------------------------------------------------------------------
// info

int info(const std::string& path) {
  const Table t = loadTable(path);
  const core::ColorLut& lut = t.lut;
  const core::ColorSpace space = lut.colorSpace();
  const int bits = lut.bitsPerChannel();
  std::printf("file: %s\n", path.c_str());
  std::printf("color space: %s (channels %s, %s, %s)\n", spaceName(space), channelName(space, 0), channelName(space, 1),
              channelName(space, 2));
  std::printf("bits per channel: %d (%u^3 = %zu cells)\n", bits, 1u << bits, lut.size());
  std::printf("revision: %llu\n", static_cast<unsigned long long>(t.msg.revision));
  std::printf("stamp: %u.%09u%s%s%s\n", t.msg.header.stamp.sec, t.msg.header.stamp.nsec,
              t.msg.header.stamp.isZero() ? " (not set)" : "", t.msg.header.frame_id.empty() ? "" : ", frame ",
              t.msg.header.frame_id.c_str());
  std::printf("cells per class:\n");
  const auto counts = lut.cellCounts();
  size_t classified = 0;
  for (int k = 0; k < core::kNumClasses; ++k) {
    classified += counts[k];
    std::printf("  %-8s %9u  %6.2f%%\n", core::className(k), counts[k], 100.0 * counts[k] / lut.size());
  }
  if (classified != lut.size()) {
    const size_t invalid = lut.size() - classified;
    std::printf("  %-8s %9zu  %6.2f%%  (ids >= %d: no class)\n", "invalid", invalid, 100.0 * invalid / lut.size(),
                core::kNumClasses);
  }
  if (t.msg.clusters.empty()) {
    std::printf("clusters: none (not saved by the trainer, e.g. imported)\n");
    return 0;
  }
  std::printf("clusters: %zu (mean %s %s %s)\n", t.msg.clusters.size(), channelName(space, 0), channelName(space, 1),
              channelName(space, 2));
  for (const act_color::ClassCluster& c : t.msg.clusters) {
    std::printf("  %-8s mean %6.1f %6.1f %6.1f  sigma %6.2f  samples %u  cells %u\n", core::className(c.class_id),
                c.mean[0], c.mean[1], c.mean[2], c.sigma, c.samples, c.lut_cells);
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// export

constexpr int kPadPx = 8;
constexpr int kHeaderPx = 44;
constexpr int kLabelPx = 18;
constexpr int kLegendPx = 28;
constexpr int kMinWidthPx = 820;
constexpr int kSliceMapPx = 256;
constexpr int kChromaMapPx = 512;
const cv::Scalar kBackground(235, 235, 235);  // also chroma bins no color of the table falls in
const cv::Scalar kUnknownColor(64, 64, 64);   // darker than the palette's grey: stands back
const cv::Scalar kText(0, 0, 0);

cv::Scalar classColor(int class_id) {
  if (class_id <= core::kUnknown || class_id >= core::kNumClasses) return kUnknownColor;
  const auto& rgb = core::classPalette()[class_id];
  return cv::Scalar(rgb[2], rgb[1], rgb[0]);  // BGR, as cv::imwrite takes it
}

// The most frequent class other than unknown; unknown when there is none; ties to the lower id.
int dominantClass(const uint32_t* counts) {
  int best = core::kUnknown;
  for (int k = 1; k < core::kNumClasses; ++k) {
    if (counts[k] > 0 && (best == core::kUnknown || counts[k] > counts[best])) best = k;
  }
  return best;
}

// A canvas for `maps` square maps of `map_px`, with the header and the legend drawn.
struct Canvas {
  cv::Mat image;
  int cols = 1;
  int map_px = 0;
  cv::Point origin(int k) const {
    return cv::Point(kPadPx + (k % cols) * (map_px + kPadPx),
                     kHeaderPx + (k / cols) * (kLabelPx + map_px + kPadPx) + kLabelPx);
  }
};

void text(cv::Mat& image, const std::string& s, cv::Point at) {
  cv::putText(image, s, at, cv::FONT_HERSHEY_SIMPLEX, 0.4, kText, 1, cv::LINE_AA);
}

Canvas makeCanvas(int maps, int map_px, const std::string& heading, const std::string& subtitle) {
  Canvas c;
  c.cols = maps <= 4 ? maps : (maps <= 16 ? 4 : 8);
  c.map_px = map_px;
  const int rows = (maps + c.cols - 1) / c.cols;
  const int width = std::max(kMinWidthPx, kPadPx + c.cols * (map_px + kPadPx));
  const int height = kHeaderPx + rows * (kLabelPx + map_px + kPadPx) + kLegendPx;
  c.image = cv::Mat(height, width, CV_8UC3, kBackground);
  text(c.image, heading, cv::Point(kPadPx, 17));
  text(c.image, subtitle, cv::Point(kPadPx, 35));
  const int legend_y = height - kLegendPx + 6;
  for (int k = 0; k < core::kNumClasses; ++k) {
    const int x = kPadPx + k * 110;
    cv::rectangle(c.image, cv::Rect(x, legend_y, 14, 14), classColor(k), cv::FILLED);
    cv::rectangle(c.image, cv::Rect(x, legend_y, 14, 14), cv::Scalar(160, 160, 160), 1);
    text(c.image, core::className(k), cv::Point(x + 19, legend_y + 12));
  }
  return c;
}

std::string title(const std::string& path, const act_color::ColorLut& msg, const core::ColorLut& lut) {
  return baseName(path) + ": " + (lut.colorSpace() == core::ColorSpace::kYuv ? "YUV" : "RGB") + " table, " +
         std::to_string(lut.bitsPerChannel()) + " bits per channel, revision " + std::to_string(msg.revision);
}

cv::Mat renderSlices(const std::string& path, const Table& t, int slices) {
  const core::ColorLut& lut = t.lut;
  const core::ColorSpace space = lut.colorSpace();
  const int bits = lut.bitsPerChannel();
  const uint32_t n = 1u << bits;
  const int cell_px = kSliceMapPx / static_cast<int>(n);
  const int shift = 8 - bits;
  const std::string c0 = channelName(space, 0), c1 = channelName(space, 1), c2 = channelName(space, 2);
  Canvas canvas = makeCanvas(slices, kSliceMapPx, title(path, t.msg, lut),
                             "slices along " + c0 + "; in each x = " + c1 + " 0-255 (right), y = " + c2 +
                                 " 0-255 (up), the most frequent class of the slice, unknown dark grey");
  uint32_t counts[core::kNumClasses];
  for (int s = 0; s < slices; ++s) {
    const uint32_t begin = s * n / slices, end = (s + 1) * n / slices;
    const cv::Point o = canvas.origin(s);
    text(canvas.image, c0 + " " + std::to_string(begin << shift) + "-" + std::to_string((end << shift) - 1),
         cv::Point(o.x, o.y - 5));
    for (uint32_t i1 = 0; i1 < n; ++i1) {
      for (uint32_t i2 = 0; i2 < n; ++i2) {
        std::fill(std::begin(counts), std::end(counts), 0u);
        for (uint32_t i0 = begin; i0 < end; ++i0) {
          const uint8_t k = lut.at(lut.cellIndex(i0, i1, i2));
          if (k < core::kNumClasses) ++counts[k];
        }
        const cv::Rect r(o.x + static_cast<int>(i1) * cell_px, o.y + static_cast<int>(n - 1 - i2) * cell_px, cell_px,
                         cell_px);
        cv::rectangle(canvas.image, r, classColor(dominantClass(counts)), cv::FILLED);
      }
    }
  }
  return canvas.image;
}

// BT.601 full range, as core::rgbToUyvy converts.
uint8_t clampByte(double x) { return static_cast<uint8_t>(std::min(255.0, std::max(0.0, std::round(x)))); }

cv::Mat renderChroma(const std::string& path, const Table& t) {
  const core::ColorLut& lut = t.lut;
  const bool yuv = lut.colorSpace() == core::ColorSpace::kYuv;
  const int bits = lut.bitsPerChannel();
  const uint32_t n = 1u << bits;
  const int cell_px = kChromaMapPx / static_cast<int>(n);
  const int shift = 8 - bits;
  const double half = shift > 0 ? 0.5 * (1 << shift) : 0.0;
  Canvas canvas = makeCanvas(1, kChromaMapPx, title(path, t.msg, lut),
                             "U-V map: x = U 0-255 (right), y = V 0-255 (up), the most frequent class over Y, unknown "
                             "dark grey");
  std::vector<uint32_t> counts(size_t{n} * n * core::kNumClasses, 0);
  std::vector<uint8_t> seen(size_t{n} * n, 0);
  for (uint32_t i0 = 0; i0 < n; ++i0) {
    for (uint32_t i1 = 0; i1 < n; ++i1) {
      for (uint32_t i2 = 0; i2 < n; ++i2) {
        uint32_t u = i1, v = i2;
        if (!yuv) {
          const double r = (i0 << shift) + half, g = (i1 << shift) + half, b = (i2 << shift) + half;
          u = clampByte(-0.168736 * r - 0.331264 * g + 0.5 * b + 128) >> shift;
          v = clampByte(0.5 * r - 0.418688 * g - 0.081312 * b + 128) >> shift;
        }
        const size_t bin = size_t{u} * n + v;
        seen[bin] = 1;
        const uint8_t k = lut.at(lut.cellIndex(i0, i1, i2));
        if (k < core::kNumClasses) ++counts[bin * core::kNumClasses + k];
      }
    }
  }
  const cv::Point o = canvas.origin(0);
  text(canvas.image, yuv ? "U-V over all Y" : "RGB cells at their centres' BT.601 U, V; light grey: none",
       cv::Point(o.x, o.y - 5));
  for (uint32_t u = 0; u < n; ++u) {
    for (uint32_t v = 0; v < n; ++v) {
      const size_t bin = size_t{u} * n + v;
      if (!seen[bin]) continue;
      const cv::Rect r(o.x + static_cast<int>(u) * cell_px, o.y + static_cast<int>(n - 1 - v) * cell_px, cell_px,
                       cell_px);
      cv::rectangle(canvas.image, r, classColor(dominantClass(&counts[bin * core::kNumClasses])), cv::FILLED);
    }
  }
  return canvas.image;
}

int exportImage(const std::string& path, const std::string& output, int slices, bool chroma) {
  const Table t = loadTable(path);
  const int n = 1 << t.lut.bitsPerChannel();
  if (!chroma && slices > n) {
    throw std::invalid_argument("--slices " + std::to_string(slices) + ": the table has " + std::to_string(n) +
                                " cells per channel");
  }
  const cv::Mat image = chroma ? renderChroma(path, t) : renderSlices(path, t, slices);
  bool written = false;
  try {
    written = cv::imwrite(output, image);
  } catch (const cv::Exception& e) {
    throw FileError(output + ": " + e.what());
  }
  if (!written) throw FileError("cannot write '" + output + "' (a .png path?)");
  if (chroma) {
    std::printf("wrote %s: %d x %d px, a U-V map, %d px per cell\n", output.c_str(), image.cols, image.rows,
                kChromaMapPx / n);
  } else {
    std::printf("wrote %s: %d x %d px, %d slices along %s, %d px per cell\n", output.c_str(), image.cols, image.rows,
                slices, channelName(t.lut.colorSpace(), 0), kSliceMapPx / n);
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// to-nubot, from-nubot

void printNubotCounts(const std::vector<uint8_t>& codes, const char* indent) {
  size_t counts[kNubotCodes] = {0, 0, 0, 0};
  for (uint8_t c : codes) ++counts[c];
  std::printf("%s", indent);
  for (int c = 0; c < kNubotCodes; ++c) {
    std::printf("%s%d %s %zu", c ? ", " : "", c, kNubotNames[c], counts[c]);
  }
  std::printf(" cells\n");
}

int toNubotFile(const std::string& path, const std::string& output) {
  const Table t = loadTable(path);
  const core::ColorLut& lut = t.lut;
  const core::ColorSpace space = lut.colorSpace();
  const int bits = lut.bitsPerChannel();
  const std::string name = lower(baseName(output));
  if (space == core::ColorSpace::kRgb && name == "ctable.dat") {
    std::cerr << "act_lut: note: an RGB table goes to NuBot's BGR layout; omni_vision reads CTable.dat as YUV "
                 "(name it CTableBGR.dat)\n";
  } else if (space == core::ColorSpace::kYuv && name.find("bgr") != std::string::npos) {
    std::cerr << "act_lut: note: a YUV table goes to NuBot's YUV layout (CTable.dat), not to a BGR table\n";
  }
  // Our classes as NuBot codes, in our cell order, then at NuBot's 6 bits.
  std::vector<uint8_t> codes(lut.size());
  for (size_t i = 0; i < codes.size(); ++i) codes[i] = toNubot(lut.at(static_cast<uint32_t>(i)));
  if (bits != kNubotBits) codes = resample(codes, bits, kNubotBits);
  std::vector<uint8_t> file(kNubotCells);
  const uint32_t n = 1u << kNubotBits;
  for (uint32_t i0 = 0; i0 < n; ++i0) {
    for (uint32_t i1 = 0; i1 < n; ++i1) {
      for (uint32_t i2 = 0; i2 < n; ++i2) {
        file[nubotIndex(space, i0, i1, i2)] = codes[(size_t{i0} << (2 * kNubotBits)) | (size_t{i1} << kNubotBits) | i2];
      }
    }
  }
  std::ofstream out(output, std::ios::binary | std::ios::trunc);
  if (!out) throw FileError("cannot open '" + output + "' for writing");
  out.write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  if (!out.good()) throw FileError("cannot write '" + output + "'");
  std::printf("wrote %s: NuBot %s, 64^3 bytes\n", output.c_str(), nubotLayout(space));
  if (bits != kNubotBits) {
    std::printf("  resampled from %d bits per channel (%s)\n", bits,
                bits < kNubotBits ? "each cell of ours split, nothing changed"
                                  : "each NuBot cell the most frequent class of the cells it covers");
  }
  printNubotCounts(file, "  ");
  const auto counts = lut.cellCounts();
  std::printf("  to unknown, no NuBot class: white %u, yellow %u, blue %u of our %zu cells\n", counts[core::kWhite],
              counts[core::kYellow], counts[core::kBlue], lut.size());
  return 0;
}

std::vector<uint8_t> readNubotFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError("cannot open '" + path + "'");
  std::vector<uint8_t> file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (file.size() != kNubotCells) {
    throw FileError("'" + path + "' has " + std::to_string(file.size()) + " bytes, a NuBot table has " +
                    std::to_string(kNubotCells) + " (64^3)");
  }
  for (size_t i = 0; i < file.size(); ++i) {
    if (file[i] >= kNubotCodes) {
      throw FileError("'" + path + "': cell " + std::to_string(i) + " holds " + std::to_string(file[i]) +
                      "; NuBot's codes are 0 ball, 1 black, 2 green, 3 unknown");
    }
  }
  return file;
}

int fromNubotFile(const std::string& path, const std::string& output, core::ColorSpace space, int bits) {
  const std::vector<uint8_t> file = readNubotFile(path);
  // NuBot's codes in our cell order, at the bits asked for, then as our classes.
  std::vector<uint8_t> codes(kNubotCells);
  const uint32_t n = 1u << kNubotBits;
  for (uint32_t i0 = 0; i0 < n; ++i0) {
    for (uint32_t i1 = 0; i1 < n; ++i1) {
      for (uint32_t i2 = 0; i2 < n; ++i2) {
        codes[(size_t{i0} << (2 * kNubotBits)) | (size_t{i1} << kNubotBits) | i2] = file[nubotIndex(space, i0, i1, i2)];
      }
    }
  }
  if (bits != kNubotBits) codes = resample(codes, kNubotBits, bits);
  act_color::ColorLut msg;
  msg.color_space =
      space == core::ColorSpace::kYuv ? act_color::ColorLut::COLOR_SPACE_YUV : act_color::ColorLut::COLOR_SPACE_RGB;
  msg.bits_per_channel = static_cast<uint8_t>(bits);
  msg.revision = 0;
  msg.table.resize(codes.size());
  for (size_t i = 0; i < codes.size(); ++i) msg.table[i] = fromNubot(codes[i]);
  core::ColorLut check;
  std::string error;
  if (!conv::fromMsg(msg, &check, &error)) throw std::logic_error("imported table: " + error);
  if (!conv::saveLutFile(msg, output, &error)) throw FileError(error);
  std::printf("read %s: NuBot %s as %s table\n", path.c_str(), nubotLayout(space),
              space == core::ColorSpace::kYuv ? "a YUV" : "an RGB");
  printNubotCounts(file, "  ");
  const auto counts = check.cellCounts();
  std::printf(
      "wrote %s: %d bits per channel%s, revision 0, no clusters: orange %u, black %u, green %u, unknown %u "
      "cells\n",
      output.c_str(), bits, bits == kNubotBits ? "" : " (resampled)", counts[core::kOrange], counts[core::kBlack],
      counts[core::kGreen], counts[core::kUnknown]);
  return 0;
}

int parseInt(const std::string& text, const std::string& option) {
  size_t used = 0;
  int v = 0;
  try {
    v = std::stoi(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (text.empty() || used != text.size())
    throw std::invalid_argument(option + " needs an integer, not '" + text + "'");
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  std::string command, output, color_space;
  std::vector<std::string> files;
  int slices = -1, bits = -1;
  bool chroma = false;
  std::vector<std::string> given;  // options given, to refuse those the command does not take
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
        return argv[++i];
      };
      if (arg == "--help" || arg == "-h") {
        std::cout << kUsage;
        return 0;
      } else if (arg == "--output") {
        output = value();
      } else if (arg == "--slices") {
        slices = parseInt(value(), arg);
        if (slices < 1) throw std::invalid_argument("--slices must be at least 1");
      } else if (arg == "--chroma") {
        chroma = true;
      } else if (arg == "--color-space") {
        color_space = value();
        if (color_space != "rgb" && color_space != "yuv")
          throw std::invalid_argument("--color-space must be rgb or yuv");
      } else if (arg == "--bits") {
        bits = parseInt(value(), arg);
        if (bits < 1 || bits > 8) throw std::invalid_argument("--bits must be in [1, 8]");
      } else if (!arg.empty() && arg[0] == '-') {
        return usage("unknown option " + arg);
      } else if (command.empty()) {
        command = arg;
        continue;
      } else {
        files.push_back(arg);
        continue;
      }
      given.push_back(arg);
    }
  } catch (const std::exception& e) {
    return usage(e.what());
  }
  if (command.empty()) return usage("give a command: info, export, to-nubot or from-nubot");
  std::vector<std::string> allowed;
  if (command == "export") {
    allowed = {"--output", "--slices", "--chroma"};
  } else if (command == "to-nubot") {
    allowed = {"--output"};
  } else if (command == "from-nubot") {
    allowed = {"--output", "--color-space", "--bits"};
  } else if (command != "info") {
    return usage("unknown command '" + command + "'");
  }
  for (const std::string& option : given) {
    if (std::find(allowed.begin(), allowed.end(), option) == allowed.end()) {
      return usage(command + " does not take " + option);
    }
  }
  if (files.size() != 1) return usage(command + " takes one file, " + std::to_string(files.size()) + " given");
  if (command != "info" && output.empty()) return usage(command + " needs --output");
  if (chroma && slices != -1) return usage("give --slices or --chroma, not both");

  try {
    if (command == "info") return info(files[0]);
    if (command == "export") return exportImage(files[0], output, slices == -1 ? 8 : slices, chroma);
    if (command == "to-nubot") return toNubotFile(files[0], output);
    // from-nubot: the layout from --color-space or the file's name.
    core::ColorSpace space = core::ColorSpace::kRgb;
    const std::string name = lower(baseName(files[0]));
    if (color_space.empty()) {
      if (name.find("bgr") != std::string::npos) {
        color_space = "rgb";
      } else if (name == "ctable.dat") {
        color_space = "yuv";
      } else {
        return usage("cannot tell the layout from the name '" + baseName(files[0]) +
                     "': give --color-space rgb (CTableBGR.dat: B, G, R) or yuv (CTable.dat: Y, U, V)");
      }
    }
    if (color_space == "yuv") space = core::ColorSpace::kYuv;
    return fromNubotFile(files[0], output, space, bits == -1 ? kNubotBits : bits);
  } catch (const std::invalid_argument& e) {
    return usage(e.what());
  } catch (const std::exception& e) {
    std::cerr << "act_lut: " << e.what() << "\n";
    return 1;
  }
}
