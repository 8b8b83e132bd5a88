#pragma once

#include <ros/serialization.h>

#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "act_color/ColorLut.h"

namespace act_color {
namespace ros_conversions {

// A ColorLut message (table and clusters) in a file: the message's ROS serialization after a
// magic line, so that a file is self-describing and needs no other format.
constexpr char kLutFileMagic[] = "act_color/ColorLut v1\n";

inline bool saveLutFile(const act_color::ColorLut& msg, const std::string& path, std::string* error) {
  const uint32_t size = ::ros::serialization::serializationLength(msg);
  std::vector<uint8_t> buffer(size);
  ::ros::serialization::OStream stream(buffer.data(), size);
  ::ros::serialization::serialize(stream, msg);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    *error = "cannot open '" + path + "' for writing";
    return false;
  }
  out << kLutFileMagic;
  out.write(reinterpret_cast<const char*>(buffer.data()), static_cast<std::streamsize>(buffer.size()));
  if (!out.good()) {
    *error = "cannot write '" + path + "'";
    return false;
  }
  return true;
}

inline bool loadLutFile(const std::string& path, act_color::ColorLut* msg, std::string* error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *error = "cannot open '" + path + "'";
    return false;
  }
  std::string magic(sizeof(kLutFileMagic) - 1, '\0');
  in.read(&magic[0], static_cast<std::streamsize>(magic.size()));
  if (!in || magic != kLutFileMagic) {
    *error = "'" + path + "' is not a color table file (saved by ~save_lut)";
    return false;
  }
  std::vector<uint8_t> buffer((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    ::ros::serialization::IStream stream(buffer.data(), static_cast<uint32_t>(buffer.size()));
    ::ros::serialization::deserialize(stream, *msg);
  } catch (const std::exception& e) {
    *error = "'" + path + "' is truncated or corrupt: " + e.what();
    return false;
  }
  return true;
}

}  // namespace ros_conversions
}  // namespace act_color
