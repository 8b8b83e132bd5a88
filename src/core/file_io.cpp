#include "act_color/core/file_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <vector>

namespace act_color {
namespace core {

bool readRegularFile(const std::string& path, size_t max_bytes, std::string* bytes, std::string* error,
                     const std::string& what) {
  if (path.find('\0') != std::string::npos) {
    *error = "the path contains a NUL byte";
    return false;
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    *error = "cannot open '" + path + "': " + std::strerror(errno);
    return false;
  }
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    *error = "'" + path + "' is not a regular file";
    return false;
  }
  if (static_cast<uint64_t>(st.st_size) > max_bytes) {
    ::close(fd);
    *error = "'" + path + "' is " + std::to_string(st.st_size) + " bytes, more than " + what + " can be (" +
             std::to_string(max_bytes) + ")";
    return false;
  }
  bytes->resize(static_cast<size_t>(st.st_size));
  size_t done = 0;
  while (done < bytes->size()) {
    const ssize_t n = ::read(fd, &(*bytes)[done], bytes->size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<size_t>(n);
  }
  ::close(fd);
  bytes->resize(done);
  return true;
}

bool makeFolder(const std::string& path, std::string* error) {
  std::error_code made, checked;  // the non-throwing overloads
  std::filesystem::create_directories(path, made);
  if (std::filesystem::is_directory(path, checked)) return true;
  *error = path + ": cannot make the folder (" + (made ? made.message() : std::string("not a folder")) + ")";
  return false;
}

bool writeFileAtomically(const std::string& path, const void* data, size_t size, std::string* error) {
  if (path.empty() || path.find('\0') != std::string::npos) {
    *error = "not a file name: '" + path + "'";
    return false;
  }
  std::string tmp = path + ".XXXXXX";
  const int fd = ::mkstemp(&tmp[0]);
  if (fd < 0) {
    *error = "cannot write beside '" + path + "': " + std::strerror(errno);
    return false;
  }
  const auto* p = static_cast<const char*>(data);
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, p + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<size_t>(n);
  }
  const bool written = done == size && ::fchmod(fd, 0644) == 0 && ::fsync(fd) == 0;
  const int saved_errno = errno;
  ::close(fd);
  if (!written || ::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = written ? errno : saved_errno;
    ::unlink(tmp.c_str());
    *error = "cannot write '" + path + "': " + std::strerror(e);
    return false;
  }
  return true;
}

bool imageHeaderSize(const std::string& bytes, int* width, int* height) {
  const auto* b = reinterpret_cast<const unsigned char*>(bytes.data());
  const size_t n = bytes.size();
  auto big16 = [&](size_t i) { return static_cast<uint32_t>(b[i]) << 8 | b[i + 1]; };
  auto big32 = [&](size_t i) { return big16(i) << 16 | big16(i + 2); };
  static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (n >= 24 && std::memcmp(b, kPng, 8) == 0 && std::memcmp(b + 12, "IHDR", 4) == 0) {
    const uint32_t w = big32(16), h = big32(20);
    if (w == 0 || h == 0 || w > 0x7fffffffu || h > 0x7fffffffu) return false;
    *width = static_cast<int>(w);
    *height = static_cast<int>(h);
    return true;
  }
  if (n >= 4 && b[0] == 0xff && b[1] == 0xd8) {
    // JPEG: markers up to the first start of frame (SOF0-15 but DHT C4, JPG C8, DAC CC).
    size_t i = 2;
    while (i + 4 <= n) {
      if (b[i] != 0xff) return false;
      const unsigned char marker = b[i + 1];
      if (marker == 0xff) {
        ++i;  // fill byte
        continue;
      }
      if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd7)) {
        i += 2;  // no length
        continue;
      }
      const size_t length = big16(i + 2);
      if (length < 2) return false;
      if (marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc) {
        if (i + 9 > n) return false;
        const uint32_t h = big16(i + 5), w = big16(i + 7);
        if (w == 0 || h == 0) return false;
        *width = static_cast<int>(w);
        *height = static_cast<int>(h);
        return true;
      }
      if (marker == 0xda || marker == 0xd9) return false;  // scan or end before a frame header
      i += 2 + length;
    }
  }
  return false;
}

bool readImageFile(const std::string& path, int flags, size_t max_bytes, int max_side, int64_t max_pixels,
                   cv::Mat* image, std::string* error) {
  std::string bytes;
  if (!readRegularFile(path, max_bytes, &bytes, error)) return false;
  int width = 0, height = 0;
  if (imageHeaderSize(bytes, &width, &height) &&
      (width > max_side || height > max_side || static_cast<int64_t>(width) * height > max_pixels)) {
    *error = "'" + path + "' is " + std::to_string(width) + "x" + std::to_string(height) +
             " px by its header, more than " + std::to_string(max_side) + " px a side or " +
             std::to_string(max_pixels) + " pixels (limit)";
    return false;
  }
  try {
    const cv::Mat raw(1, static_cast<int>(bytes.size()), CV_8UC1, &bytes[0]);
    *image = bytes.empty() ? cv::Mat() : cv::imdecode(raw, flags);
  } catch (const cv::Exception&) {
    *image = cv::Mat();
  }
  if (image->empty()) {
    *error = "'" + path + "' is not an image OpenCV can read";
    return false;
  }
  if (image->cols > max_side || image->rows > max_side ||
      static_cast<int64_t>(image->cols) * image->rows > max_pixels) {
    *error = "'" + path + "' is " + std::to_string(image->cols) + "x" + std::to_string(image->rows) +
             " px, more than " + std::to_string(max_side) + " px a side or " + std::to_string(max_pixels) +
             " pixels (limit)";
    *image = cv::Mat();
    return false;
  }
  return true;
}

}  // namespace core
}  // namespace act_color
