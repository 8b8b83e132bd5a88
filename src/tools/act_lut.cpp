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

#include <sys/stat.h>

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
#include "act_color/core/file_io.hpp"
#include "act_color/core/lut_image.hpp"
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

// NuBot's table file (to-nubot): written beside and renamed, so that its input or a table of
// another kind is never truncated on the way; only a regular file is replaced.
void writeWholeFile(const std::string& output, const std::vector<uint8_t>& bytes) {
  struct stat st {};
  if (::lstat(output.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    throw FileError("'" + output + "' exists and is not a regular file: not replaced");
  }
  std::string error;
  if (!core::writeFileAtomically(output, bytes.data(), bytes.size(), &error)) throw FileError(error);
}

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
  // The clusters checked as ~load_lut checks them (a table whose clusters it refuses is no good).
  std::vector<core::ActTrainer::SavedCluster> clusters;
  if (!conv::fromMsg(t.msg, &t.lut, &clusters, &error)) throw FileError(path + ": " + error);
  return t;
}

// A name from a file as it may be printed: bytes outside printable ASCII as \xNN (no terminal
// escapes, no line breaks from a forged frame id).
std::string printable(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte < 0x7f && byte != '\\') {
      out += c;
    } else {
      char escaped[5];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", byte);
      out += escaped;
    }
  }
  return out;
}

const char* spaceName(core::ColorSpace space) { return space == core::ColorSpace::kYuv ? "yuv" : "rgb"; }

// ---------------------------------------------------------------------------------------------
// info

int info(const std::string& path) {
  const Table t = loadTable(path);
  const core::ColorLut& lut = t.lut;
  const core::ColorSpace space = lut.colorSpace();
  const int bits = lut.bitsPerChannel();
  std::printf("file: %s\n", path.c_str());
  std::printf("color space: %s (channels %s, %s, %s)\n", spaceName(space), core::channelName(space, 0),
              core::channelName(space, 1), core::channelName(space, 2));
  std::printf("bits per channel: %d (%u^3 = %zu cells)\n", bits, 1u << bits, lut.size());
  std::printf("revision: %llu\n", static_cast<unsigned long long>(t.msg.revision));
  std::printf("stamp: %u.%09u%s%s%s\n", t.msg.header.stamp.sec, t.msg.header.stamp.nsec,
              t.msg.header.stamp.isZero() ? " (not set)" : "", t.msg.header.frame_id.empty() ? "" : ", frame ",
              printable(t.msg.header.frame_id).c_str());
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
  std::printf("clusters: %zu (mean %s %s %s)\n", t.msg.clusters.size(), core::channelName(space, 0),
              core::channelName(space, 1), core::channelName(space, 2));
  for (const act_color::ClassCluster& c : t.msg.clusters) {
    std::printf("  %-8s mean %6.1f %6.1f %6.1f  sigma %6.2f  samples %u  cells %u\n", core::className(c.class_id),
                c.mean[0], c.mean[1], c.mean[2], c.sigma, c.samples, c.lut_cells);
  }
  return 0;
}

// ---------------------------------------------------------------------------------------------
// export

std::string title(const std::string& path, const act_color::ColorLut& msg, const core::ColorLut& lut) {
  return baseName(path) + ": " + (lut.colorSpace() == core::ColorSpace::kYuv ? "YUV" : "RGB") + " table, " +
         std::to_string(lut.bitsPerChannel()) + " bits per channel, revision " + std::to_string(msg.revision);
}

int exportImage(const std::string& path, const std::string& output, int slices, bool chroma) {
  const Table t = loadTable(path);
  const int n = 1 << t.lut.bitsPerChannel();
  if (!chroma && slices > n) {
    throw std::invalid_argument("--slices " + std::to_string(slices) + ": the table has " + std::to_string(n) +
                                " cells per channel");
  }
  const std::string heading = title(path, t.msg, t.lut);
  const cv::Mat image = chroma ? core::renderLutChroma(t.lut, heading) : core::renderLutSlices(t.lut, slices, heading);
  bool written = false;
  try {
    written = cv::imwrite(output, image);
  } catch (const cv::Exception& e) {
    throw FileError(output + ": " + e.what());
  }
  if (!written) throw FileError("cannot write '" + output + "' (a .png path?)");
  if (chroma) {
    std::printf("wrote %s: %d x %d px, a U-V map, %d px per cell\n", output.c_str(), image.cols, image.rows,
                core::kLutChromaMapPx / n);
  } else {
    std::printf("wrote %s: %d x %d px, %d slices along %s, %d px per cell\n", output.c_str(), image.cols, image.rows,
                slices, core::channelName(t.lut.colorSpace(), 0), core::kLutSliceMapPx / n);
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
  writeWholeFile(output, file);
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
  std::string bytes, error;
  if (!core::readRegularFile(path, kNubotCells, &bytes, &error, "a NuBot table (64^3)")) throw FileError(error);
  const std::vector<uint8_t> file(bytes.begin(), bytes.end());
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
