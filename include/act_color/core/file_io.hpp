#pragma once

#include <cstddef>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>

namespace act_color {
namespace core {

// Files a robot reads at start-up or on request must not block, stall or exhaust it: a FIFO or a
// device named by mistake, a huge file, an image whose header declares billions of pixels.

// Reads the whole regular file at `path` when it has at most `max_bytes`. It is opened without
// blocking (a FIFO or a device is refused, not waited on) and its size checked before anything is
// allocated. False with a message naming the file (and `what` it should be) otherwise.
bool readRegularFile(const std::string& path, size_t max_bytes, std::string* bytes, std::string* error,
                     const std::string& what = "this file");

// Writes `size` bytes to `path` as a temporary file beside it, synced and renamed over it: a
// reader sees the old file or the new one, never a part; a failed write leaves the old one. False
// with a message naming the file otherwise.
bool writeFileAtomically(const std::string& path, const void* data, size_t size, std::string* error);

// Makes the folder `path` and its parents when missing (a tool's output folder, which the tools'
// image writes do not make). False with a message naming the folder when it cannot be made or is
// not a folder.
bool makeFolder(const std::string& path, std::string* error);

// The width and height a PNG or JPEG file declares in its header, read without decoding; false for
// other or malformed bytes.
bool imageHeaderSize(const std::string& bytes, int* width, int* height);

// An image file read with readRegularFile (at most `max_bytes`) and decoded by OpenCV (`flags` as
// cv::imread's) only when its header declares at most `max_side` px a side and `max_pixels` in all
// (PNG and JPEG; another format is decoded when OpenCV knows it, bounded by its size in bytes).
// False with a message naming the file otherwise.
bool readImageFile(const std::string& path, int flags, size_t max_bytes, int max_side, int64_t max_pixels,
                   cv::Mat* image, std::string* error);

// Bounds of the images the tools read (camera images, self masks): the calibration's own limits
// (kMaxImageSidePx, kMaxImagePixels) and a file size no camera image comes near.
constexpr size_t kMaxImageFileBytes = size_t{256} << 20;

}  // namespace core
}  // namespace act_color
