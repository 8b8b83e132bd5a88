#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "act_color/core/calibration.hpp"
#include "act_color/core/color_lut.hpp"
#include "act_color/core/expected_class_model.hpp"
#include "act_color/core/image_view.hpp"
#include "act_color/core/types.hpp"

namespace act_color {
namespace core {

// Learns the pixels that show the own robot (issue 12): mirror struts, the chassis ring, a camera
// cable. Where the pose expects carpet or a line, they show neither, wherever the robot stands.
// Each frame counts, for every pixel expected carpet or line, whether the table classifies its
// color as carpet or line. A pixel is the own robot when it showed neither in at least
// kMismatchFraction of the frames that looked at it, and its connected part of the image is one
// the own robot makes: touching the chassis, or long along the radius and narrow across it (a
// strut or cable). Robots and people on the field are compact and, once the robot has moved, are
// seen at other pixels. Where a part runs on beyond the field (nothing is expected there), it is
// followed along the radius as far as the pixels keep their color from pose to pose (from
// kMinPosesForConstancy poses on): the own robot moves with the camera, the hall does not. The
// result is the calibration's self mask (CameraCalibration::self_mask).
class SelfMaskLearner {
 public:
  // The calibration's own self mask is ignored: every imaged pixel is looked at.
  explicit SelfMaskLearner(const Calibration& calibration);

  // One frame: the image (the calibration's size), the pose it was taken at and the table that
  // classifies it (e.g. an ActTrainer's after the frame's cycle). A frame whose pose has not moved
  // kMinMoveM or kMinTurnRad from the last frame counted is not counted again, so that a robot
  // standing still for minutes weighs as one look. Throws std::invalid_argument for an image of
  // another size.
  void add(const ImageView& image, const Pose2D& pose, const ColorLut& lut);

  // Frames counted so far (distinct poses).
  int frames() const { return frames_; }
  // Of the kHeadingSectors directions, how many the poses counted so far faced.
  size_t headingsFaced() const;
  // Whether add() counts a frame at `pose` after one counted at `last`: it moved kMinMoveM or
  // turned kMinTurnRad (a caller can tell before it copies a frame and its table for add()).
  static bool isNewPose(const Pose2D& last, const Pose2D& pose);
  // The mask (row-major, 1 = own robot); empty before any frame was counted.
  std::vector<uint8_t> mask() const;

  static constexpr double kMismatchFraction = 0.8;
  static constexpr double kMinMoveM = 0.25;
  static constexpr double kMinTurnRad = 0.17;  // 10 degrees
  static constexpr int kMinPosesForConstancy = 8;
  // A pixel keeps its color when its standard deviation over the poses (RMS over the channels),
  // its colors scaled so that the carpet's mean level is kCarpetLevel in every frame, is at most
  // kConstantSd: sensor noise and light that differs a little from place to place.
  static constexpr double kCarpetLevel = 100.0;
  static constexpr double kConstantSd = 15.0;
  // A part over the hall only is at most this fraction of its distance from the centre wide, and
  // is looked for once the poses counted faced kMinHeadingSectors of kHeadingSectors directions.
  static constexpr double kMaxAcrossFraction = 0.15;
  static constexpr unsigned kHeadingSectors = 8;
  static constexpr size_t kMinHeadingSectors = 4;

 private:
  Calibration calibration_;
  ExpectedClassModel model_;
  std::vector<uint16_t> looked_;
  std::vector<uint16_t> mismatched_;
  // Over the poses counted, in double (a match counts thousands of poses): colors [pixel * 3 +
  // channel] and squares summed over the channels [pixel].
  std::vector<double> color_sum_;
  std::vector<double> color_sum_sq_;
  int frames_ = 0;
  Pose2D last_pose_;
  uint32_t heading_sectors_ = 0;  // bit k: a pose counted faced sector k
};

// When a mask being learned is used while the robot plays (the trainer's ~learn_self_mask, act_replay
// --learn-self-mask): from SelfMaskLearner::kMinPosesForConstancy distinct poses on, whenever the
// mask differs from the one used last in more than kChangedFraction of the image's pixels. The
// calibration's own mask (a team's edits) stays part of it.
class SelfMaskHandOver {
 public:
  explicit SelfMaskHandOver(const Calibration& calibration) : calibration_(calibration) {}
  // The calibration with the learner's mask, united with its own, as the self mask (no
  // self_mask_file), when it is to be used from now on; nullopt when it is not.
  std::optional<Calibration> next(const SelfMaskLearner& learner);
  // Pixels in the mask last handed over (the calibration's own and the learned).
  size_t pixels() const { return pixels_; }

  static constexpr double kChangedFraction = 0.001;

 private:
  const Calibration calibration_;
  std::vector<uint8_t> handed_over_;  // the learned mask last handed over
  size_t pixels_ = 0;
};

}  // namespace core
}  // namespace act_color
