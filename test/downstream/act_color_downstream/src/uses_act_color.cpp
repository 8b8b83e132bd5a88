// Includes every public header of act_color's core and ROS layer and uses the core: trains a
// table from one painted frame at a known pose. Prints what it did; exit 1 when nothing trained.
#include <act_color/ColorLut.h>

#include <act_color/core/act_trainer.hpp>
#include <act_color/core/ball_detector.hpp>
#include <act_color/core/calibration.hpp>
#include <act_color/core/class_cluster.hpp>
#include <act_color/core/color_lut.hpp>
#include <act_color/core/expected_class_model.hpp>
#include <act_color/core/feature_extractor.hpp>
#include <act_color/core/field_model.hpp>
#include <act_color/core/image_view.hpp>
#include <act_color/core/light_model.hpp>
#include <act_color/core/lut_image.hpp>
#include <act_color/core/metrics.hpp>
#include <act_color/core/mirror_calibrator.hpp>
#include <act_color/core/omni_camera_model.hpp>
#include <act_color/core/run_evaluation.hpp>
#include <act_color/core/segmenter.hpp>
#include <act_color/core/self_mask_learner.hpp>
#include <act_color/core/table_ceiling.hpp>
#include <act_color/core/types.hpp>
#include <act_color/ros/bag_replay.hpp>
#include <act_color/ros/checked_reconfigure.hpp>
#include <act_color/ros/conversions.hpp>
#include <act_color/ros/lut_file.hpp>
#include <act_color/ros/nodelet_setup.hpp>
#include <act_color/ros/pose_source.hpp>
#include <act_color/sim/flat_painter.hpp>
#include <cstdio>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: uses_act_color CALIBRATION.yaml\n");
    return 2;
  }
  namespace core = act_color::core;
  const core::Calibration calibration = core::loadCalibration(argv[1]);
  core::ActTrainer trainer(calibration);
  const core::Pose2D pose{1.0, -0.5, 0.3};
  const auto frame = act_color::sim::paintFlatFrame(trainer.model(), pose, 1.0, 1);
  trainer.bootstrap(core::ImageView::fromMat(frame.rgb, core::PixelFormat::kRgb8), pose, 10);
  std_msgs::Header header;
  const act_color::ColorLutPtr msg = act_color::ros_conversions::toMsg(trainer, header);
  const auto counts = trainer.lut().cellCounts();
  std::printf("act_color from a downstream package: revision %lu, %u green cells, %zu clusters in the message\n",
              static_cast<unsigned long>(trainer.revision()), counts[core::kGreen], msg->clusters.size());
  return counts[core::kGreen] > 0 && msg->clusters.size() == core::kNumClasses - 1 ? 0 : 1;
}
