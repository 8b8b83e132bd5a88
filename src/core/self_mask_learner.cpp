#include "act_color/core/self_mask_learner.hpp"

#include <algorithm>
#include <bitset>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace act_color {
namespace core {
namespace {

Calibration withoutMask(Calibration c) {
  c.camera.self_mask.clear();
  c.camera.self_mask_file.clear();
  return c;
}

// A part of the own robot is a run of candidates along the radius (a strut, a cable) of at least
// this fraction of the imaged ring (chassis to mirror rim) ...
constexpr double kMinRadialFraction = 0.15;
// ... or lies within this fraction of the ring (plus kChassisTouchPx) outside the chassis.
constexpr double kChassisRingFraction = 0.03;
constexpr double kChassisTouchPx = 2.0;
// Either way its connected part of the image reaches, within kAttachedPx, a pixel where no class is
// expected (the chassis, the hall, a goal): a strut runs on beyond the field, a cable into the
// chassis. A ball and its shadow lying on the field make a long radial run too, but carpet is
// expected all round them.
constexpr int kAttachedPx = 2;
// A pixel must have been looked at in this fraction of the frames (at least 1).
constexpr double kMinLookedFraction = 0.3;

// The pixels of `set` (CV_8UC1, nonzero) in an unbroken row through (u, v) along (ex, ey), both
// ways, in steps of one pixel; counting stops once it passes `limit`.
double runThrough(const cv::Mat& set, int u, int v, double ex, double ey, double limit) {
  auto in = [&](double x, double y) {
    const int iu = static_cast<int>(std::lround(x)), iv = static_cast<int>(std::lround(y));
    return iu >= 0 && iv >= 0 && iu < set.cols && iv < set.rows && set.at<uint8_t>(iv, iu) != 0;
  };
  double length = 1;
  for (double s = 1; length <= limit && in(u + s * ex, v + s * ey); ++s) ++length;
  for (double s = 1; length <= limit && in(u - s * ex, v - s * ey); ++s) ++length;
  return length;
}

// The distance of (u, v) from the mirror centre and the unit vector along its ray, (ex, ey) (0, 0
// at the centre).
double radial(const CameraCalibration& cal, int u, int v, double* ex, double* ey) {
  const double du = u - cal.center_u, dv = v - cal.center_v;
  const double r = std::hypot(du, dv);
  *ex = r > 0 ? du / r : 0.0;
  *ey = r > 0 ? dv / r : 0.0;
  return r;
}

}  // namespace

SelfMaskLearner::SelfMaskLearner(const Calibration& calibration)
    : calibration_(withoutMask(calibration)), model_(calibration_) {
  const size_t pixels = model_.pixels();
  looked_.assign(pixels, 0);
  mismatched_.assign(pixels, 0);
  color_sum_.assign(3 * pixels, 0.0);
  color_sum_sq_.assign(pixels, 0.0);
}

size_t SelfMaskLearner::headingsFaced() const { return std::bitset<kHeadingSectors>(heading_sectors_).count(); }

bool SelfMaskLearner::isNewPose(const Pose2D& last, const Pose2D& pose) {
  const double moved = std::hypot(pose.x_m - last.x_m, pose.y_m - last.y_m);
  const double turned = std::abs(std::remainder(pose.theta_rad - last.theta_rad, 2 * M_PI));
  return moved >= kMinMoveM || turned >= kMinTurnRad;
}

void SelfMaskLearner::add(const ImageView& image, const Pose2D& pose, const ColorLut& lut) {
  const auto& camera = model_.camera();
  if (image.width != camera.width() || image.height != camera.height())
    throw std::invalid_argument("image size does not match the calibration");
  if (!pose.isFinite()) throw std::invalid_argument("pose is not finite");
  if (frames_ > 0 && !isNewPose(last_pose_, pose)) return;
  if (frames_ == std::numeric_limits<uint16_t>::max()) return;  // the counts are full
  last_pose_ = pose;
  ++frames_;
  const double turn = std::remainder(pose.theta_rad, 2 * M_PI) + M_PI;  // [0, 2 pi]
  heading_sectors_ |= 1u << (static_cast<unsigned>(turn / (2 * M_PI) * kHeadingSectors) % kHeadingSectors);
  const PoseTransform transform(pose);
  // The carpet's brightness in this frame: colors are summed relative to it, so that a change of
  // light (a gain: auto exposure, lamps) during the drive does not count as a change of color.
  double carpet_sum = 0;
  size_t carpet_pixels = 0;
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      const size_t i = static_cast<size_t>(v) * camera.width() + u;
      const uint8_t expected = model_.geometricClass(i, transform);
      if (expected != kGreen && expected != kWhite) continue;
      uint8_t c[3];
      image.color(u, v, c);
      const uint8_t k = lut.classOf(c[0], c[1], c[2]);
      ++looked_[i];
      if (k != kGreen && k != kWhite) ++mismatched_[i];
      if (expected == kGreen && k == kGreen) {
        carpet_sum += c[0] + c[1] + c[2];
        ++carpet_pixels;
      }
    }
  }
  const double scale = carpet_sum > 0 ? 3.0 * kCarpetLevel * static_cast<double>(carpet_pixels) / carpet_sum : 1.0;
  for (int v = 0; v < camera.height(); ++v) {
    for (int u = 0; u < camera.width(); ++u) {
      const size_t i = static_cast<size_t>(v) * camera.width() + u;
      uint8_t c[3];
      image.color(u, v, c);
      for (int ch = 0; ch < 3; ++ch) {
        const double x = scale * c[ch];
        color_sum_[3 * i + ch] += x;
        color_sum_sq_[i] += x * x;
      }
    }
  }
}

std::vector<uint8_t> SelfMaskLearner::mask() const {
  const auto& camera = model_.camera();
  const int width = camera.width(), height = camera.height();
  std::vector<uint8_t> out;
  if (frames_ == 0) return out;
  const double min_looked = std::max(1.0, kMinLookedFraction * frames_);
  cv::Mat candidates(height, width, CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      if (looked_[i] >= min_looked && mismatched_[i] >= kMismatchFraction * looked_[i])
        candidates.at<uint8_t>(v, u) = 1;
    }
  }
  // The parts the own robot makes, by their shape about the mirror axis: a strut or a cable is a
  // long radial run of candidates (a robot or a person on the field, or the edge of a carpet that
  // is a little smaller than the model's, makes short runs along the radius); the chassis ring
  // lies right outside the chassis.
  const CameraCalibration& cal = calibration_.camera;
  const double ring = std::max(1.0, cal.mirror_radius_px - cal.chassis_radius_px);
  const double min_run = kMinRadialFraction * ring;
  const double chassis_ring = cal.chassis_radius_px + kChassisRingFraction * ring + kChassisTouchPx;
  cv::Mat mask(height, width, CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      if (!candidates.at<uint8_t>(v, u)) continue;
      double ex, ey;
      const double r = radial(cal, u, v, &ex, &ey);
      bool own = r <= chassis_ring;
      if (!own && r > 0) {
        // The run of candidates through this pixel along its ray.
        own = runThrough(candidates, u, v, ex, ey, min_run) >= min_run;
      }
      if (own) mask.at<uint8_t>(v, u) = 255;
    }
  }
  // Only the parts attached to where no class is expected (looked at in fewer frames than
  // min_looked; the counts are whole numbers).
  const cv::Mat looked = cv::Mat(looked_).reshape(1, height);  // a view of the counts, no copy
  cv::Mat unlooked = looked < std::ceil(min_looked);
  cv::dilate(unlooked, unlooked,
             cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * kAttachedPx + 1, 2 * kAttachedPx + 1)));
  cv::Mat labels;
  const int parts = cv::connectedComponents(mask, labels, 8, CV_32S);
  std::vector<uint8_t> attached(static_cast<size_t>(parts), 0);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      if (unlooked.at<uint8_t>(v, u)) attached[static_cast<size_t>(labels.at<int>(v, u))] = 1;
    }
  }
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      if (!attached[static_cast<size_t>(labels.at<int>(v, u))]) mask.at<uint8_t>(v, u) = 0;
    }
  }
  // Where a part runs on beyond the field, along the radius through the pixels nothing was
  // expected at (or that showed neither carpet nor line) as long as they keep their color.
  if (frames_ >= kMinPosesForConstancy) {
    // Open to the walk: imaged pixels past the chassis, nothing expected at them (or candidates),
    // that keep their color; `hall`: those nothing was expected at.
    const double n = frames_;
    cv::Mat open(height, width, CV_8UC1, cv::Scalar(0)), hall(height, width, CV_8UC1, cv::Scalar(0));
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) {
        const size_t i = static_cast<size_t>(v) * width + u;
        const PixelRegion region = camera.ray(i).region;
        if (region == PixelRegion::kNotImaged || region == PixelRegion::kChassis) continue;
        const bool unexpected = looked_[i] < min_looked;
        if (!unexpected && !candidates.at<uint8_t>(v, u)) continue;
        double mean_sq = 0;
        for (int ch = 0; ch < 3; ++ch) {
          const double m = color_sum_[3 * i + ch] / n;
          mean_sq += m * m;
        }
        if ((color_sum_sq_[i] / n - mean_sq) / 3.0 > kConstantSd * kConstantSd) continue;
        open.at<uint8_t>(v, u) = 1;
        hall.at<uint8_t>(v, u) = unexpected;
      }
    }
    // A part that lies over the hall only: a long run along the radius of pixels nothing was
    // expected at that keep their color, narrow across it (a wall or ceiling of one color keeps
    // its color too, but all round). Only once the robot has faced kMinHeadingSectors directions:
    // driving straight on, a pole far to the side stays at its pixels too.
    if (headingsFaced() < kMinHeadingSectors) hall.setTo(0);
    cv::Mat narrow(height, width, CV_8UC1, cv::Scalar(0));
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) {
        if (!hall.at<uint8_t>(v, u)) continue;
        double ex, ey;
        const double r = radial(cal, u, v, &ex, &ey);
        if (r <= 0) continue;
        const double max_across = kMaxAcrossFraction * r;  // across the ray: (-ey, ex)
        if (runThrough(hall, u, v, -ey, ex, max_across) <= max_across) narrow.at<uint8_t>(v, u) = 1;
      }
    }
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) {
        if (!narrow.at<uint8_t>(v, u)) continue;
        double ex, ey;
        radial(cal, u, v, &ex, &ey);
        if (runThrough(narrow, u, v, ex, ey, min_run) >= min_run) mask.at<uint8_t>(v, u) = 255;
      }
    }
    const cv::Mat seeds = mask.clone();
    for (int v = 0; v < height; ++v) {
      for (int u = 0; u < width; ++u) {
        if (!seeds.at<uint8_t>(v, u)) continue;
        double ex, ey;
        if (radial(cal, u, v, &ex, &ey) <= 0) continue;
        for (const double dir : {1.0, -1.0}) {
          for (double s = 1;; ++s) {
            const int gu = static_cast<int>(std::lround(u + dir * s * ex)),
                      gv = static_cast<int>(std::lround(v + dir * s * ey));
            if (gu < 0 || gv < 0 || gu >= width || gv >= height || !open.at<uint8_t>(gv, gu)) break;
            mask.at<uint8_t>(gv, gu) = 255;
          }
        }
      }
    }
  }
  out.assign(static_cast<size_t>(width) * height, 0);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t i = static_cast<size_t>(v) * width + u;
      out[i] = mask.at<uint8_t>(v, u) != 0 && camera.ray(i).region != PixelRegion::kNotImaged;
    }
  }
  return out;
}

std::optional<Calibration> SelfMaskHandOver::next(const SelfMaskLearner& learner) {
  if (learner.frames() < SelfMaskLearner::kMinPosesForConstancy) return std::nullopt;
  const std::vector<uint8_t> mask = learner.mask();
  if (handed_over_.size() != mask.size()) handed_over_.assign(mask.size(), 0);
  size_t changed = 0;
  for (size_t i = 0; i < mask.size(); ++i) changed += (mask[i] != 0) != (handed_over_[i] != 0);
  if (std::count(mask.begin(), mask.end(), 0) == static_cast<long>(mask.size()) ||
      static_cast<double>(changed) <= kChangedFraction * static_cast<double>(mask.size())) {
    return std::nullopt;
  }
  Calibration calibration = calibration_;
  CameraCalibration& camera = calibration.camera;
  addSelfMask(camera, mask.data(), camera.width, camera.height, static_cast<size_t>(camera.width));
  camera.self_mask_file.clear();
  pixels_ = static_cast<size_t>(std::count(camera.self_mask.begin(), camera.self_mask.end(), 1));
  handed_over_ = mask;
  return calibration;
}

}  // namespace core
}  // namespace act_color
