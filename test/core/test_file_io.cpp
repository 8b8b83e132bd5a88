// Issue 15: files read at start-up or on request neither block, stall nor exhaust the robot.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/file_io.hpp"
#include "test_util.hpp"

namespace {

using act_color::core::CalibrationError;
namespace core = act_color::core;
using act_color::test::readFile;
using act_color::test::sourcePath;

std::string tempDir() {
  static std::string dir = [] {
    char pattern[] = "/tmp/act_file_io_XXXXXX";
    return std::string(::mkdtemp(pattern));
  }();
  return dir;
}

void writeBytes(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

// The first 24 bytes of a PNG (signature and IHDR) declaring this size, and nothing else.
std::string pngHeader(uint32_t width, uint32_t height) {
  std::string b = "\x89PNG\r\n\x1a\n";
  b += std::string("\0\0\0\x0d", 4) + "IHDR";
  for (uint32_t x : {width, height}) {
    for (int shift = 24; shift >= 0; shift -= 8) b += static_cast<char>((x >> shift) & 0xff);
  }
  return b + std::string(5, '\0');
}

std::string calibrationError(const std::string& path) {
  try {
    core::loadCalibration(path);
  } catch (const CalibrationError& e) {
    return e.what();
  }
  return "";
}

// A tool's output folder: made with its parents, kept when it is there, refused under a file.
TEST(FileIo, OutputFoldersAreMadeOrRefusedWithTheirName) {
  std::string error;
  const std::string nested = tempDir() + "/out/panels";
  EXPECT_TRUE(core::makeFolder(nested, &error)) << error;
  struct stat st {};
  ASSERT_EQ(::stat(nested.c_str(), &st), 0);
  EXPECT_TRUE(S_ISDIR(st.st_mode));
  EXPECT_TRUE(core::makeFolder(nested, &error)) << error;  // already there
  const std::string file = tempDir() + "/a_file";
  writeBytes(file, "x");
  EXPECT_FALSE(core::makeFolder(file, &error));
  EXPECT_NE(error.find(file + ": cannot make the folder"), std::string::npos) << error;
  EXPECT_FALSE(core::makeFolder(file + "/below", &error));
  EXPECT_NE(error.find(file + "/below: cannot make the folder"), std::string::npos) << error;
}

TEST(FileIo, OnlyBoundedRegularFilesAreRead) {
  std::string bytes, error;
  const std::string fifo = tempDir() + "/fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(core::readRegularFile(fifo, 100, &bytes, &error));  // returns at once, nothing writes to it
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  EXPECT_NE(error.find("not a regular file"), std::string::npos) << error;
  EXPECT_FALSE(core::readRegularFile("/dev/zero", 100, &bytes, &error));
  EXPECT_FALSE(core::readRegularFile(tempDir(), 100, &bytes, &error));
  const std::string big = tempDir() + "/big";
  writeBytes(big, std::string(101, 'x'));
  EXPECT_FALSE(core::readRegularFile(big, 100, &bytes, &error, "a test file"));
  EXPECT_NE(error.find("101 bytes, more than a test file can be (100)"), std::string::npos) << error;
  ASSERT_TRUE(core::readRegularFile(big, 101, &bytes, &error)) << error;
  EXPECT_EQ(bytes, std::string(101, 'x'));
}

TEST(FileIo, ImageSizesAreReadFromTheHeader) {
  const cv::Mat image(37, 53, CV_8UC3, cv::Scalar(10, 200, 30));
  for (const std::string ext : {".png", ".jpg"}) {
    std::vector<uint8_t> encoded;
    ASSERT_TRUE(cv::imencode(ext, image, encoded));
    int w = 0, h = 0;
    ASSERT_TRUE(core::imageHeaderSize(std::string(encoded.begin(), encoded.end()), &w, &h)) << ext;
    EXPECT_EQ(w, 53) << ext;
    EXPECT_EQ(h, 37) << ext;
  }
  int w = 0, h = 0;
  EXPECT_TRUE(core::imageHeaderSize(pngHeader(32000, 32000), &w, &h));
  EXPECT_EQ(w, 32000);
  EXPECT_FALSE(core::imageHeaderSize("not an image at all", &w, &h));
  EXPECT_FALSE(core::imageHeaderSize(std::string("\xff\xd8\xff", 3), &w, &h));
  // A header declaring 32000 x 32000 px is refused before anything is decoded.
  const std::string bomb = tempDir() + "/bomb.png";
  writeBytes(bomb, pngHeader(32000, 32000));
  cv::Mat out;
  std::string error;
  EXPECT_FALSE(core::readImageFile(bomb, cv::IMREAD_COLOR, core::kMaxImageFileBytes, core::kMaxImageSidePx,
                                   core::kMaxImagePixels, &out, &error));
  EXPECT_NE(error.find("32000x32000 px by its header"), std::string::npos) << error;
}

TEST(FileIo, AnAtomicWriteReplacesTheWholeFile) {
  const std::string path = tempDir() + "/atomic";
  writeBytes(path, "old contents, longer than the new");
  std::string error;
  ASSERT_TRUE(core::writeFileAtomically(path, "new", 3, &error)) << error;
  std::string bytes;
  ASSERT_TRUE(core::readRegularFile(path, 100, &bytes, &error));
  EXPECT_EQ(bytes, "new");
  EXPECT_FALSE(core::writeFileAtomically(tempDir() + "/no/such/dir/file", "x", 1, &error));
  EXPECT_NE(error.find("cannot write beside"), std::string::npos) << error;
}

// The self mask of a calibration: a FIFO blocked the loader (and unloading the nodelet then
// blocked its manager), a 1 MB PNG of 32000 x 32000 px took 1 GB to decode before it was refused.
TEST(FileIo, AHostileSelfMaskIsRefusedAtOnce) {
  const std::string contract = readFile(sourcePath("test/data/contract_example.yaml"));
  const std::string with_mask = contract.substr(0, contract.find("  elevation_map:")) + "  self_mask: mask.png\n" +
                                contract.substr(contract.find("  elevation_map:"));
  const std::string calibration = tempDir() + "/with_mask.yaml";
  writeBytes(calibration, with_mask);
  const std::string mask = tempDir() + "/mask.png";
  ASSERT_EQ(::mkfifo(mask.c_str(), 0600), 0);
  std::string error = calibrationError(calibration);
  EXPECT_NE(error.find("camera.self_mask: '" + mask + "' is not a regular file"), std::string::npos) << error;
  ::unlink(mask.c_str());
  writeBytes(mask, pngHeader(32000, 32000));
  error = calibrationError(calibration);
  EXPECT_NE(error.find("camera.self_mask"), std::string::npos) << error;
  EXPECT_NE(error.find("32000x32000 px by its header"), std::string::npos) << error;
  // A mask of the camera's size is read.
  cv::imwrite(mask, cv::Mat(580, 580, CV_8UC1, cv::Scalar(0)));
  EXPECT_EQ(calibrationError(calibration), "");
}

}  // namespace
