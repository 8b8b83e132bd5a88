#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "act_color/ColorLut.h"

namespace act_color {
namespace ros_conversions {

// A ColorLut message (table, clusters, revision) in a file: the message's ROS serialization after
// a magic line, so that a file is self-describing and needs no other format.
constexpr char kLutFileMagic[] = "act_color/ColorLut v1\n";
// The largest such file: an 8-bit table (16 Mi cells), its clusters and a short frame id.
constexpr size_t kMaxLutFileBytes = (size_t{1} << 24) + 4096;

// Writes atomically: to a temporary file beside `path`, then renamed over it, so that a crash or a
// full disk never leaves half a table. An existing `path` is replaced only when it is a regular
// file that already holds a color table (never truncates an unrelated file). False with a reason.
bool saveLutFile(const act_color::ColorLut& msg, const std::string& path, std::string* error);

// Writes the bytes of a PNG image (a learned self mask) atomically, as saveLutFile: an existing
// `path` is replaced only when it is a regular file that is a PNG. False with a reason.
bool savePngFile(const std::vector<uint8_t>& png, const std::string& path, std::string* error);

// Reads a file written by saveLutFile: a regular file of at most kMaxLutFileBytes, whose every
// length field is checked against the bytes there before anything is allocated for it (a forged
// length cannot make it allocate gigabytes). False with a reason ("cannot open", "is not a color
// table file", "truncated or corrupt: ...", "table has N cells, expected M", ...). Table contents
// (class ids, clusters) are checked by fromMsg.
bool loadLutFile(const std::string& path, act_color::ColorLut* msg, std::string* error);

// The file a ~save_lut request may write: `requested` relative to `dir` (or absolute), which must
// lie inside `dir` once `..` and symbolic links are resolved; no NUL bytes, not a directory.
// Creates `dir` when missing. False with a reason.
bool lutPathInside(const std::string& dir, const std::string& requested, std::string* resolved, std::string* error);

}  // namespace ros_conversions
}  // namespace act_color
