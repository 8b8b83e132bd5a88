// Issue 15: color table files. The loader over seeded mutations of a real file (no crash, no huge
// allocation, no wrong accept: whatever is accepted has class ids 0-6, consistent sizes and real
// clusters); forged length fields; saves that stay inside their folder and never overwrite an
// unrelated file.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>
#include <vector>

#include "act_color/core/act_trainer.hpp"
#include "act_color/core/calibration.hpp"
#include "act_color/ros/conversions.hpp"
#include "act_color/ros/lut_file.hpp"
#include "act_color/sim/flat_painter.hpp"
#include "tool_test_util.hpp"

namespace {

namespace core = act_color::core;
namespace conv = act_color::ros_conversions;

std::string scratch() { return act_color_tool_test::tempDir("act_lut_file_test"); }

std::vector<uint8_t> bytesOf(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
}

void write(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

core::Calibration calibration() {
  return core::loadCalibration(std::string(ACT_SOURCE_DIR) + "/config/calibration/msl_2007_580.yaml");
}

// A trained table's file.
std::string trainedTableFile() {
  const core::Calibration cal = calibration();
  core::ActTrainer trainer(cal);
  const core::Pose2D pose{1.0, 0.5, 0.2};
  const auto frame = act_color::sim::paintFlatFrame(trainer.model(), pose, 1.0, 2);
  trainer.bootstrap(core::ImageView::fromMat(frame.rgb, core::PixelFormat::kRgb8), pose, 10);
  std_msgs::Header header;
  header.frame_id = "omni_camera";
  const std::string path = scratch() + "/trained.lut";
  std::string error;
  EXPECT_TRUE(conv::saveLutFile(*conv::toMsg(trainer, header), path, &error)) << error;
  return path;
}

// Loads `path` as the trainer's ~load_lut does; "" when accepted, else the reason.
std::string load(const std::string& path, core::ActTrainer* trainer) {
  act_color::ColorLut msg;
  core::ColorLut lut;
  std::vector<core::ActTrainer::SavedCluster> clusters;
  std::string error;
  if (!conv::loadLutFile(path, &msg, &error)) return error;
  if (!conv::fromMsg(msg, &lut, &clusters, &error)) return error;
  try {
    trainer->restore(lut, clusters, msg.revision);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(LutFileFuzz, MutatedFilesAreRefusedOrAcceptedConsistent) {
  const std::string good = trainedTableFile();
  const std::vector<uint8_t> original = bytesOf(good);
  ASSERT_GT(original.size(), 262144u);
  const core::Calibration cal = calibration();
  core::ActTrainer trainer(cal);
  ASSERT_EQ(load(good, &trainer), "");
  std::mt19937 rng(15);
  auto pick = [&](size_t n) { return std::uniform_int_distribution<size_t>(0, n - 1)(rng); };
  const size_t magic = sizeof(conv::kLutFileMagic) - 1;
  const size_t table_end = original.size() - 4 - 6 * 25;  // the clusters follow the table
  const int kCases = 2000;
  int refused = 0, accepted = 0;
  const std::string path = scratch() + "/mutated.lut";
  for (int i = 0; i < kCases; ++i) {
    std::vector<uint8_t> bytes = original;
    switch (i % 5) {
      case 0:  // bytes of the header and length fields
        for (int k = 0; k < 1 + static_cast<int>(pick(4)); ++k)
          bytes[magic + pick(48)] = static_cast<uint8_t>(pick(256));
        break;
      case 1: {  // a forged 32-bit length at a random place of the header or before the clusters
        const uint32_t huge = 0xFFFFFFF0u - static_cast<uint32_t>(pick(1000));
        const size_t at = pick(2) ? magic + pick(40) : table_end - 4 + pick(8);
        std::memcpy(&bytes[at], &huge, 4);
        break;
      }
      case 2:  // cells of the table: class ids anywhere in 0-255
        for (int k = 0; k < 1 + static_cast<int>(pick(8)); ++k)
          bytes[magic + 40 + pick(262144)] = static_cast<uint8_t>(pick(256));
        break;
      case 3:  // the clusters
        for (int k = 0; k < 1 + static_cast<int>(pick(6)); ++k)
          bytes[table_end + pick(bytes.size() - table_end)] = static_cast<uint8_t>(pick(256));
        break;
      default:  // cut or lengthened
        if (pick(2)) {
          bytes.resize(pick(bytes.size()));
        } else {
          bytes.insert(bytes.end(), 1 + pick(64), static_cast<uint8_t>(pick(256)));
        }
        break;
    }
    write(path, bytes);
    core::ActTrainer& t = trainer;  // restore replaces the whole state (or throws before changing it)
    const std::string error = load(path, &t);
    if (!error.empty()) {
      ++refused;
      continue;
    }
    ++accepted;
    // Accepted: every cell a class, the table of the trainer's size, real clusters.
    const auto counts = t.lut().cellCounts();
    size_t classified = 0;
    for (int k = 0; k < core::kNumClasses; ++k) classified += counts[k];
    EXPECT_EQ(classified, t.lut().size()) << "case " << i << ": cells with no class accepted";
    for (int k = 1; k < core::kNumClasses; ++k) {
      EXPECT_TRUE(t.clusters()[k].mean().allFinite()) << i;
      EXPECT_GT(t.clusters()[k].sigma(), 0.0) << i;
    }
  }
  std::printf("%d mutated table files: %d refused with a message, %d accepted consistent\n", kCases, refused, accepted);
  EXPECT_EQ(refused + accepted, kCases);
  EXPECT_GT(refused, kCases / 4);
}

TEST(LutFile, AForgedLengthIsRefusedBeforeAllocating) {
  const std::vector<uint8_t> original = bytesOf(trainedTableFile());
  const size_t magic = sizeof(conv::kLutFileMagic) - 1;
  std::vector<uint8_t> bytes = original;
  const uint32_t huge = 0xFFFFFFF0u;
  // The frame id's length (after seq and stamp) and the table's length.
  std::memcpy(&bytes[magic + 12], &huge, 4);
  write(scratch() + "/forged_frame.lut", bytes);
  act_color::ColorLut msg;
  std::string error;
  EXPECT_FALSE(conv::loadLutFile(scratch() + "/forged_frame.lut", &msg, &error));
  EXPECT_NE(error.find("frame id of 4294967280 bytes"), std::string::npos) << error;
  bytes = original;
  const size_t table_length_at = magic + 12 + 4 + std::strlen("omni_camera") + 2 + 8;
  std::memcpy(&bytes[table_length_at], &huge, 4);
  write(scratch() + "/forged_table.lut", bytes);
  EXPECT_FALSE(conv::loadLutFile(scratch() + "/forged_table.lut", &msg, &error));
  EXPECT_NE(error.find("table has 4294967280 cells, expected 262144"), std::string::npos) << error;
  // Larger than any table file: refused by its size.
  write(scratch() + "/huge.lut", std::vector<uint8_t>(conv::kMaxLutFileBytes + 1, 0));
  EXPECT_FALSE(conv::loadLutFile(scratch() + "/huge.lut", &msg, &error));
  EXPECT_NE(error.find("more than a color table file can be"), std::string::npos) << error;
}

TEST(LutFile, SavesStayInsideTheirFolderAndReplaceOnlyTables) {
  const std::string dir = scratch() + "/tables";
  std::string resolved, error;
  EXPECT_TRUE(conv::lutPathInside(dir, "robot.lut", &resolved, &error)) << error;
  EXPECT_EQ(resolved, dir + "/robot.lut");
  EXPECT_TRUE(conv::lutPathInside(dir, dir + "/sub/../robot.lut", &resolved, &error)) << error;
  EXPECT_EQ(resolved, dir + "/robot.lut");
  for (const std::string& bad : {std::string("../robot.lut"), std::string("/etc/passwd"), std::string("a/../../x.lut"),
                                 std::string("ok.lut\0/../../x", 15), std::string(""), std::string(".")}) {
    EXPECT_FALSE(conv::lutPathInside(dir, bad, &resolved, &error)) << bad;
  }
  // Said as it is (they read "not inside ~lut_dir" and "cannot resolve").
  EXPECT_FALSE(conv::lutPathInside(dir, "x.lut/", &resolved, &error));
  EXPECT_EQ(error, "'x.lut/' names a directory, not a file");
  EXPECT_FALSE(conv::lutPathInside(dir, std::string(300, 'a') + ".lut", &resolved, &error));
  EXPECT_NE(error.find("File name too long"), std::string::npos) << error;
  // A symbolic link out of the folder is resolved, and refused.
  ASSERT_EQ(::symlink("/tmp", (dir + "/out").c_str()), 0);
  EXPECT_FALSE(conv::lutPathInside(dir, "out/escape.lut", &resolved, &error));
  EXPECT_NE(error.find("not inside"), std::string::npos) << error;

  // An unrelated file is never overwritten; a table is replaced atomically.
  const std::string notes = dir + "/notes.lut";
  write(notes, std::vector<uint8_t>{'h', 'i', '\n'});
  act_color::ColorLut msg;
  msg.bits_per_channel = 1;
  msg.table.assign(8, 0);
  EXPECT_FALSE(conv::saveLutFile(msg, notes, &error));
  EXPECT_NE(error.find("is not a color table file: not overwritten"), std::string::npos) << error;
  EXPECT_EQ(bytesOf(notes), (std::vector<uint8_t>{'h', 'i', '\n'}));
  const std::string table = dir + "/table.lut";
  ASSERT_TRUE(conv::saveLutFile(msg, table, &error)) << error;
  msg.revision = 7;
  ASSERT_TRUE(conv::saveLutFile(msg, table, &error)) << error;
  act_color::ColorLut back;
  ASSERT_TRUE(conv::loadLutFile(table, &back, &error)) << error;
  EXPECT_EQ(back.revision, 7u);
  // No temporary files left beside it.
  int entries = 0;
  for (const char* name : {"/table.lut", "/notes.lut"}) entries += static_cast<bool>(std::ifstream(dir + name));
  EXPECT_EQ(entries, 2);
  EXPECT_EQ(std::system(("test $(ls " + dir + " | wc -l) -eq 3").c_str()), 0) << "temporary files left";
}

// The trainer's ~save_self_mask: the learned mask as a PNG (core::encodeSelfMask), written like a
// table (conv::savePngFile): atomically, and over nothing but a PNG.
TEST(LutFile, ASelfMaskReplacesOnlyAPng) {
  const std::string dir = scratch() + "/masks";
  ASSERT_EQ(std::system(("mkdir -p " + dir).c_str()), 0);
  core::CameraCalibration camera;
  camera.width = 8;
  camera.height = 6;
  camera.self_mask.assign(48, 0);
  camera.self_mask[9] = camera.self_mask[10] = camera.self_mask[47] = 1;
  const std::vector<uint8_t> png = core::encodeSelfMask(camera);
  std::string error;
  const std::string path = dir + "/self_mask.png";
  ASSERT_TRUE(conv::savePngFile(png, path, &error)) << error;
  const cv::Mat back = cv::imread(path, cv::IMREAD_GRAYSCALE);
  ASSERT_EQ(back.cols, 8);
  ASSERT_EQ(back.rows, 6);
  for (int i = 0; i < 48; ++i) EXPECT_EQ(back.data[i] != 0, camera.self_mask[i] != 0) << "pixel " << i;
  camera.self_mask[0] = 1;
  ASSERT_TRUE(conv::savePngFile(core::encodeSelfMask(camera), path, &error)) << error;  // its own PNG: replaced
  EXPECT_NE(cv::imread(path, cv::IMREAD_GRAYSCALE).data[0], 0);
  const std::string notes = dir + "/notes.txt";
  write(notes, std::vector<uint8_t>{'h', 'i', '\n'});
  EXPECT_FALSE(conv::savePngFile(png, notes, &error));
  EXPECT_NE(error.find("is not a PNG image: not overwritten"), std::string::npos) << error;
  EXPECT_EQ(bytesOf(notes), (std::vector<uint8_t>{'h', 'i', '\n'}));
  EXPECT_FALSE(conv::savePngFile(png, std::string("a\0b", 3), &error));
  EXPECT_EQ(std::system(("test $(ls " + dir + " | wc -l) -eq 2").c_str()), 0) << "temporary files left";
  // A mask of another size than the camera's is no mask of it.
  camera.self_mask.pop_back();
  EXPECT_THROW(core::encodeSelfMask(camera), core::CalibrationError);
  EXPECT_THROW(core::saveSelfMask(camera, dir + "/other.png"), core::CalibrationError);
}

}  // namespace
