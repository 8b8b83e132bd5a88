// ActParams::carpet_edge (core::CarpetEdge): white beyond the carpet's edge, found in the labels
// along each bearing, is labelled unknown, and black there where no robot stands on the carpet;
// white on the carpet stays, however the carpet ends, and so do the robots' bodies.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "act_color/core/act_trainer.hpp"
#include "act_color/core/carpet_edge.hpp"
#include "act_color/core/omni_camera_model.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/core/types.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scene_family.hpp"
#include "test_util.hpp"

namespace act_color {
namespace {

struct Scene {
  cv::Mat labels;
  cv::Mat keep;  // white and black that must stay
  cv::Mat hall;  // white and black that must go
};

double bearingDeg(const core::PixelRay& ray) {
  double b = ray.bearing_rad * 180.0 / M_PI;
  return b < 0 ? b + 360.0 : b;
}

// Labels drawn from the camera model in base_link: a carpet out to 4 m, a line ring at 3.0-3.12 m
// and the outer line right at the carpet's edge (3.88-4.0 m, a lab field's wall behind it); the
// hall beyond it white in patches (5-6 m at bearings 40-80 degrees, and everything above the
// horizon at 200-220 and 355-360 degrees, the last sector of bearings) and black in one (5-6 m at
// 150-170 degrees). A robot (black, 2.0-2.4 m at 100-102 degrees) hides the carpet behind it;
// another stands at the carpet's edge (3.6-4.0 m at 250-254 degrees) and its body reaches on to
// 4.8 m in the image. At 300-340 degrees nothing is green (a part of the image the table does not
// know): the white there (at 6 m, away from the green sectors next to it) stays.
Scene makeScene(const core::OmniCameraModel& camera) {
  Scene s;
  const int w = camera.width(), h = camera.height();
  s.labels = cv::Mat(h, w, CV_8UC1, cv::Scalar(core::kUnknown));
  s.keep = cv::Mat::zeros(h, w, CV_8UC1);
  s.hall = cv::Mat::zeros(h, w, CV_8UC1);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const core::PixelRay& ray = camera.ray(u, v);
      uint8_t& l = s.labels.at<uint8_t>(v, u);
      auto set = [&](uint8_t k, bool stays) {
        l = k;
        (stays ? s.keep : s.hall).at<uint8_t>(v, u) = 1;
      };
      const double b = bearingDeg(ray);
      const bool unknown_sector = b >= 300 && b <= 340;
      if (ray.region == core::PixelRegion::kAboveHorizon && ((b >= 200 && b <= 220) || b >= 355)) {
        set(core::kWhite, false);
      }
      if (ray.region != core::PixelRegion::kFloor) continue;
      const double d = std::hypot(ray.ground_x_m, ray.ground_y_m);
      const bool edge_robot = b >= 250 && b <= 254 && d >= 3.6 && d < 4.8;
      if (edge_robot) {
        set(core::kBlack, true);
      } else if (d < 4.0) {
        const bool line = (d >= 3.0 && d < 3.12) || d >= 3.88;
        const bool robot = b >= 100 && b <= 102 && d >= 2.0;
        if (robot && d < 2.4) {
          set(core::kBlack, true);
        } else if (line) {  // behind the robot too: its sectors have no green beyond it
          set(core::kWhite, true);
        } else if (!unknown_sector && !robot) {
          l = core::kGreen;
        }
      } else if (d >= 5.0 && d < 6.0 && b >= 40 && b <= 80) {
        set(core::kWhite, false);
      } else if (d >= 5.0 && d < 6.0 && b >= 150 && b <= 170) {
        set(core::kBlack, false);
      } else if (b >= 305 && b <= 335 && d >= 6.0 && d < 6.2) {
        set(core::kWhite, true);
      }
    }
  }
  return s;
}

// The rule as CarpetEdge states it, pixel by pixel over the whole image (CarpetEdge reads only the
// cells from the hall to the edge and beyond): the reference its outputs must equal.
uint32_t referenceUnlabelBeyond(const core::OmniCameraModel& camera, cv::Mat& labels) {
  using E = core::CarpetEdge;
  const size_t n = labels.total();
  std::vector<int> cell(n, -1);
  std::vector<uint32_t> imaged(E::kSectors * 256, 0), green(E::kSectors * 256, 0);
  std::vector<int> nearest_black(E::kSectors, 1 << 20);
  uint8_t* l = labels.ptr<uint8_t>();
  for (size_t i = 0; i < n; ++i) {
    const core::PixelRay& ray = camera.ray(i);
    if (ray.region != core::PixelRegion::kFloor && ray.region != core::PixelRegion::kAboveHorizon) continue;
    double turns = ray.bearing_rad / (2 * M_PI);
    turns -= std::floor(turns);
    const int s = std::min(E::kSectors - 1, static_cast<int>(turns * E::kSectors));
    const int b = ray.region == core::PixelRegion::kFloor
                      ? std::min(E::kBins, static_cast<int>(std::hypot(ray.ground_x_m, ray.ground_y_m) / E::kBinM))
                      : E::kBins;
    cell[i] = s * 256 + b;
    ++imaged[cell[i]];
    green[cell[i]] += l[i] == core::kGreen;
    if (l[i] == core::kBlack) nearest_black[s] = std::min(nearest_black[s], b);
  }
  std::vector<int> edge(E::kSectors, -1), limit(E::kSectors);
  for (int s = 0; s < E::kSectors; ++s) {
    for (int b = 0; b < E::kBins; ++b) {
      const uint32_t g = green[s * 256 + b];
      if (g >= E::kMinGreenPixels && g >= E::kMinGreenShare * imaged[s * 256 + b]) edge[s] = b;
    }
  }
  auto at = [](int s, int k) { return (s + k + E::kSectors) % E::kSectors; };
  for (int s = 0; s < E::kSectors; ++s) {
    int e = -1;
    for (int k = -E::kSpreadSectors; k <= E::kSpreadSectors; ++k) e = std::max(e, edge[at(s, k)]);
    limit[s] = e < 0 ? E::kBins : e + static_cast<int>(std::ceil(E::kMarginM / E::kBinM));
  }
  uint32_t unlabelled = 0;
  for (size_t i = 0; i < n; ++i) {
    if (cell[i] < 0) continue;
    const int s = cell[i] / 256, b = cell[i] % 256;
    if (b <= limit[s]) continue;
    bool robot = false;
    for (int k = -E::kSpreadSectors; k <= E::kSpreadSectors; ++k) robot |= nearest_black[at(s, k)] <= limit[at(s, k)];
    if (l[i] == core::kWhite || (l[i] == core::kBlack && !robot)) {
      l[i] = core::kUnknown;
      ++unlabelled;
    }
  }
  return unlabelled;
}

TEST(CarpetEdge, HallWhiteAndBlackGoLinesAndRobotsStay) {
  const core::OmniCameraModel camera(test::defaultCalibration().camera);
  const core::CarpetEdge edge(camera);
  Scene s = makeScene(camera);
  const cv::Mat black_hall = s.hall & (s.labels == core::kBlack), black_kept = s.keep & (s.labels == core::kBlack);
  const int hall = cv::countNonZero(s.hall), kept = cv::countNonZero(s.keep);
  ASSERT_GT(hall, 100);
  ASSERT_GT(kept, 1000);
  ASSERT_GT(cv::countNonZero(black_hall), 100);
  ASSERT_GT(cv::countNonZero(black_kept), 100);
  const cv::Mat before = s.labels.clone();
  cv::Mat reference = s.labels.clone();
  const uint32_t unlabelled = edge.unlabelBeyond(s.labels);
  EXPECT_EQ(unlabelled, static_cast<uint32_t>(hall));
  EXPECT_EQ(referenceUnlabelBeyond(camera, reference), unlabelled);
  EXPECT_EQ(cv::countNonZero(reference != s.labels), 0);
  EXPECT_EQ(cv::countNonZero((s.labels == before) & (s.keep != 0)), kept);
  EXPECT_EQ(cv::countNonZero((s.labels == core::kUnknown) & (s.hall != 0)), hall);
  // Nothing but white and black is touched, and they only become unknown.
  EXPECT_EQ(cv::countNonZero((s.labels != before) & (before != core::kWhite) & (before != core::kBlack)), 0);
  EXPECT_EQ(cv::countNonZero((s.labels != before) & (s.labels != core::kUnknown)), 0);
}

TEST(CarpetEdge, AsTheRuleSaysOnScenesOfTheFamilyAndOnNoise) {
  // Labels as ACT gives them on the first frame of tuning scenes 0-3 (their own cameras), and labels
  // of random classes in random blobs: equal to the reference pixel for pixel.
  for (uint32_t seed = sim::kTuningSeedsBegin; seed < sim::kTuningSeedsBegin + 4; ++seed) {
    const sim::FamilyScene scene = sim::makeFamilyScene(seed);
    const sim::LabeledFrame frame =
        sim::Renderer(scene.calibration, scene.renderer).render(scene.scenario.frames.front().scene);
    const auto view = core::ImageView::fromMat(frame.rgb, core::PixelFormat::kRgb8);
    core::ActTrainer trainer(scene.calibration);
    trainer.bootstrap(view, scene.scenario.frames.front().told_pose, 30);
    cv::Mat labels;
    core::Segmenter(scene.calibration.camera).classify(trainer.lut(), view, labels);
    const core::OmniCameraModel camera(scene.calibration.camera);
    const core::CarpetEdge edge(camera);
    std::vector<cv::Mat> cases = {labels, frame.labels.clone()};
    cv::RNG rng(seed);
    cv::Mat noise(labels.size(), CV_8UC1);
    rng.fill(noise, cv::RNG::UNIFORM, 0, 8);
    cv::resize(noise, noise, labels.size() / 8, 0, 0, cv::INTER_NEAREST);
    cv::resize(noise, noise, labels.size(), 0, 0, cv::INTER_NEAREST);
    cases.push_back(noise);
    for (cv::Mat& c : cases) {
      cv::Mat reference = c.clone();
      const uint32_t expected = referenceUnlabelBeyond(camera, reference);
      EXPECT_EQ(edge.unlabelBeyond(c), expected) << "seed " << seed;
      EXPECT_EQ(cv::countNonZero(reference != c), 0) << "seed " << seed;
    }
  }
}

TEST(CarpetEdge, NoGreenNothingKnownNothingChanged) {
  const core::OmniCameraModel camera(test::defaultCalibration().camera);
  const core::CarpetEdge edge(camera);
  cv::Mat labels(camera.height(), camera.width(), CV_8UC1, cv::Scalar(core::kWhite));
  EXPECT_EQ(edge.unlabelBeyond(labels), 0u);
  EXPECT_EQ(cv::countNonZero(labels != core::kWhite), 0);
  // Labels of another size are left alone.
  cv::Mat small(10, 10, CV_8UC1, cv::Scalar(core::kWhite));
  EXPECT_EQ(edge.unlabelBeyond(small), 0u);
}

}  // namespace
}  // namespace act_color
