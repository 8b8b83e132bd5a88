// Issue 15: the calibration loader over seeded mutations of real files. Every mutation is either
// refused with a CalibrationError (a message, never another exception, a crash or a hang) or
// accepted as a calibration that is valid and reads back the same.
#include <gtest/gtest.h>

#include <chrono>
#include <random>
#include <string>

#include "act_color/core/calibration.hpp"
#include "act_color/core/omni_camera_model.hpp"
#include "test_util.hpp"

namespace {

namespace core = act_color::core;

// One random edit of `text`: flip, insert, delete or duplicate bytes, insert YAML punctuation,
// replace a number by an extreme one, truncate, or nest brackets deeply.
std::string mutate(std::string text, std::mt19937& rng) {
  auto pick = [&](size_t n) { return n == 0 ? size_t{0} : std::uniform_int_distribution<size_t>(0, n - 1)(rng); };
  static const std::string kPunctuation = "[]{}:,-#\"' \n\t0123456789.eE+&*!|>%";
  static const char* const kNumbers[] = {
      "4294967297",           "-2147483649", "042", "0x10",  "1e309",  ".nan",  "-.inf",
      "99999999999999999999", "0",           "-1",  "16384", "1e-320", "\"7\"", "~"};
  const int edits = 1 + static_cast<int>(pick(3));
  for (int e = 0; e < edits && !text.empty(); ++e) {
    const size_t at = pick(text.size());
    switch (pick(8)) {
      case 0:
        text[at] = static_cast<char>(text[at] ^ (1 << pick(8)));
        break;
      case 1:
        text.insert(at, 1, kPunctuation[pick(kPunctuation.size())]);
        break;
      case 2:
        text.erase(at, 1 + pick(20));
        break;
      case 3:
        text.insert(at, text.substr(pick(text.size()), 1 + pick(80)));
        break;
      case 4: {
        // Replace the number that starts here (if any) by an extreme one.
        size_t b = text.find_first_of("0123456789", at);
        if (b == std::string::npos) break;
        size_t end = text.find_first_not_of("0123456789.-e", b);
        text.replace(b, (end == std::string::npos ? text.size() : end) - b, kNumbers[pick(std::size(kNumbers))]);
        break;
      }
      case 5:
        text.resize(at);
        break;
      case 6: {
        const size_t depth = 1 + pick(3000);
        text.insert(at, std::string(depth, '[') + std::string(pick(2) ? depth : 0, ']'));
        break;
      }
      default:
        text.insert(at, std::string(1 + pick(8), ' '));
        break;
    }
  }
  return text;
}

TEST(CalibrationFuzz, MutatedFilesAreRefusedWithAMessageOrAcceptedValid) {
  const std::vector<std::string> seeds = {
      act_color::test::readFile(act_color::test::sourcePath("test/data/contract_example.yaml")),
      act_color::test::readFile(act_color::test::sourcePath("config/calibration/msl_2007_640x480.yaml")),
      core::toYaml(act_color::test::defaultCalibration())};
  std::mt19937 rng(15);
  const int kCases = 4000;
  int refused = 0, accepted = 0, models = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < kCases; ++i) {
    const std::string text = mutate(seeds[i % seeds.size()], rng);
    core::Calibration c;
    try {
      c = core::parseCalibration(text, "fuzz.yaml");
    } catch (const core::CalibrationError& e) {
      ++refused;
      EXPECT_NE(std::string(e.what()).find("fuzz.yaml"), std::string::npos) << e.what();
      continue;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "case " << i << ": not a CalibrationError but " << e.what() << "\n" << text.substr(0, 400);
      continue;
    }
    ++accepted;
    // Accepted: valid, and the same once written and read again.
    EXPECT_NO_THROW(core::validateCalibration(c, "fuzz.yaml")) << i;
    const std::string yaml = core::toYaml(c);
    EXPECT_EQ(core::toYaml(core::parseCalibration(yaml, "again")), yaml) << i;
    EXPECT_LE(static_cast<int64_t>(c.camera.width) * c.camera.height, core::kMaxImagePixels);
    if (models < 30) {  // the camera model builds from it (bounded: every 30th of the accepted ones)
      EXPECT_NO_THROW(core::OmniCameraModel model(c.camera)) << i;
      ++models;
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%d mutated calibration files: %d refused with a message, %d accepted valid (%.1f s)\n", kCases, refused,
              accepted, seconds);
  EXPECT_EQ(refused + accepted, kCases);
  EXPECT_GT(refused, kCases / 2);  // the mutations do break files
}

}  // namespace
