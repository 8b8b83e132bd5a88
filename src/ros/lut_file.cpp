#include "act_color/ros/lut_file.hpp"

#include <fcntl.h>
#include <ros/serialization.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include "act_color/core/file_io.hpp"

namespace act_color {
namespace ros_conversions {

namespace core = act_color::core;
namespace {

namespace fs = std::filesystem;
constexpr size_t kMagicBytes = sizeof(kLutFileMagic) - 1;
constexpr size_t kClusterBytes = 1 + 3 * 4 + 4 + 4 + 4;  // ClassCluster: class_id, mean[3], sigma, samples, lut_cells
constexpr uint32_t kMaxFrameIdBytes = 1024;
constexpr uint32_t kMaxClusters = 64;

// True when the regular file at `path` begins with the `n` bytes of `magic` (reads only those).
bool startsWith(const std::string& path, const char* magic, size_t n) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return false;
  struct stat st {};
  std::vector<char> head(n);
  const bool ok = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) &&
                  ::read(fd, head.data(), n) == static_cast<ssize_t>(n) && std::memcmp(head.data(), magic, n) == 0;
  ::close(fd);
  return ok;
}

// False (and `error` set) when `path` is no file name, or names something that exists and is not a
// regular file beginning with `magic` (`what` it holds): a save replaces only what it wrote before.
bool mayReplace(const std::string& path, const char* magic, size_t n, const std::string& what, std::string* error) {
  if (path.empty() || path.find('\0') != std::string::npos) {
    *error = "not a file name: '" + path + "'";
    return false;
  }
  std::error_code ec;
  const fs::file_status status = fs::symlink_status(path, ec);
  if (fs::exists(status) && !(fs::is_regular_file(status) && startsWith(path, magic, n))) {
    *error = "'" + path + "' exists and is not " + what + ": not overwritten";
    return false;
  }
  return true;
}

// Walks the serialized ColorLut (Header, color_space, bits, revision, table, clusters) checking
// every length against what is left; "" when it is consistent.
std::string checkLayout(const uint8_t* p, size_t size) {
  size_t at = 0;
  auto take = [&](size_t n) {
    if (size - at < n) return false;
    at += n;
    return true;
  };
  auto u32 = [&](uint32_t* v) {
    if (size - at < 4) return false;
    std::memcpy(v, p + at, 4);  // ROS serializes little-endian, as this machine
    at += 4;
    return true;
  };
  uint32_t frame_id = 0, cells = 0, clusters = 0;
  if (!take(12) || !u32(&frame_id)) return "truncated or corrupt: the header is cut off";
  if (frame_id > kMaxFrameIdBytes) return "truncated or corrupt: a frame id of " + std::to_string(frame_id) + " bytes";
  if (!take(frame_id)) return "truncated or corrupt: the frame id is cut off";
  if (size - at < 2) return "truncated or corrupt: no color space and bits";
  const uint8_t bits = p[at + 1];
  if (!take(2 + 8)) return "truncated or corrupt: no revision";
  if (bits < 1 || bits > 8) return "bits_per_channel must be in [1, 8], is " + std::to_string(bits);
  if (!u32(&cells)) return "truncated or corrupt: no table length";
  const uint64_t expected = uint64_t{1} << (3 * bits);
  if (cells != expected) return "table has " + std::to_string(cells) + " cells, expected " + std::to_string(expected);
  if (!take(cells)) return "truncated or corrupt: the table is cut off";
  if (!u32(&clusters)) return "truncated or corrupt: no cluster count";
  if (clusters > kMaxClusters) return "truncated or corrupt: " + std::to_string(clusters) + " clusters";
  if (size - at != clusters * kClusterBytes) {
    return "truncated or corrupt: " + std::to_string(size - at) + " bytes for " + std::to_string(clusters) +
           " clusters of " + std::to_string(kClusterBytes);
  }
  return "";
}

}  // namespace

bool saveLutFile(const act_color::ColorLut& msg, const std::string& path, std::string* error) {
  if (!mayReplace(path, kLutFileMagic, kMagicBytes, "a color table file", error)) return false;
  const uint32_t size = ::ros::serialization::serializationLength(msg);
  std::vector<uint8_t> buffer(kMagicBytes + size);
  std::memcpy(buffer.data(), kLutFileMagic, kMagicBytes);
  ::ros::serialization::OStream stream(buffer.data() + kMagicBytes, size);
  ::ros::serialization::serialize(stream, msg);

  return core::writeFileAtomically(path, buffer.data(), buffer.size(), error);
}

bool savePngFile(const std::vector<uint8_t>& png, const std::string& path, std::string* error) {
  static constexpr char kPngSignature[] = "\x89PNG\r\n\x1a\n";
  if (!mayReplace(path, kPngSignature, sizeof(kPngSignature) - 1, "a PNG image", error)) return false;
  return core::writeFileAtomically(path, png.data(), png.size(), error);
}

bool loadLutFile(const std::string& path, act_color::ColorLut* msg, std::string* error) {
  std::string bytes;
  if (!core::readRegularFile(path, kMaxLutFileBytes, &bytes, error, "a color table file")) return false;
  std::vector<uint8_t> data(bytes.begin(), bytes.end());
  if (data.size() < kMagicBytes || std::memcmp(data.data(), kLutFileMagic, kMagicBytes) != 0) {
    *error = "'" + path + "' is not a color table file (saved by ~save_lut)";
    return false;
  }
  const std::string layout = checkLayout(data.data() + kMagicBytes, data.size() - kMagicBytes);
  if (!layout.empty()) {
    *error = "'" + path + "': " + layout;
    return false;
  }
  try {
    ::ros::serialization::IStream stream(data.data() + kMagicBytes, static_cast<uint32_t>(data.size() - kMagicBytes));
    ::ros::serialization::deserialize(stream, *msg);
  } catch (const std::exception& e) {
    *error = "'" + path + "' is truncated or corrupt: " + e.what();
    return false;
  }
  return true;
}

bool lutPathInside(const std::string& dir, const std::string& requested, std::string* resolved, std::string* error) {
  if (dir.empty()) {
    *error = "~lut_dir is not set: saving is off";
    return false;
  }
  if (requested.empty() || requested.find('\0') != std::string::npos) {
    *error = "not a file name";
    return false;
  }
  if (requested.back() == '/') {
    *error = "'" + requested + "' names a directory, not a file";
    return false;
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  const fs::path base = fs::weakly_canonical(fs::path(dir), ec);
  if (ec || !fs::is_directory(base)) {
    *error = "~lut_dir '" + dir + "' is not a directory that can be created";
    return false;
  }
  fs::path p(requested);
  if (p.is_relative()) p = base / p;
  // Resolves "..", "." and symbolic links of the existing part.
  const fs::path target = fs::weakly_canonical(p, ec);
  if (ec) {
    *error = "cannot resolve '" + requested + "': " + ec.message();
    return false;
  }
  const fs::path rel = target.lexically_relative(base);
  if (rel.empty() || *rel.begin() == ".." || rel == "." || target.filename().empty()) {
    *error = "'" + requested + "' is not inside ~lut_dir '" + base.string() + "': not written";
    return false;
  }
  if (fs::is_directory(target)) {
    *error = "'" + target.string() + "' is a directory";
    return false;
  }
  *resolved = target.string();
  return true;
}

}  // namespace ros_conversions
}  // namespace act_color
