// act_benchmark: timings of ACT and of the segmentation on simulator frames, against the classic
// baselines (CMVision-style per-channel bitmasks, per-class cv::inRange), in one run.
//   act_benchmark [--calibration CAL.yaml] [--json FILE] [--sizes 580x580,640x480,1280x1024]
//                 [--samples N] [--sample-ms MS] [--cpu N]
//   act_benchmark --callgrind-cycles N   N ACT cycles on 580x580 frames in runCallgrindCycles(),
//                                        for valgrind --tool=callgrind --toggle-collect=...
// The whole nodelet path is timed through real ros::Publishers (intra-process, shared pointers,
// as in one nodelet manager) when a ROS master is reachable, otherwise as the same calls without
// publishing (the JSON and table say which).
#include <cv_bridge/cv_bridge.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sched.h>
#include <sensor_msgs/Image.h>

#include <boost/make_shared.hpp>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "act_color/ColorLut.h"
#include "act_color/core/act_trainer.hpp"
#include "act_color/core/calibration.hpp"
#include "act_color/core/feature_extractor.hpp"
#include "act_color/core/segmenter.hpp"
#include "act_color/core/self_mask_learner.hpp"
#include "act_color/ros/conversions.hpp"
#include "act_color/sim/renderer.hpp"
#include "act_color/sim/scenario.hpp"
#include "bench_util.hpp"

#ifndef ACT_SOURCE_DIR
#define ACT_SOURCE_DIR "."
#endif

namespace {

using act_color::core::ActParams;
using act_color::core::ActTrainer;
using act_color::core::Calibration;
using act_color::core::ImageView;
using act_color::core::PixelFormat;
using act_color::core::Pose2D;
namespace core = act_color::core;
namespace sim = act_color::sim;
namespace tools = act_color::tools;
namespace conv = act_color::ros_conversions;

struct Frame {
  cv::Mat rgb;
  Pose2D pose;
  sensor_msgs::ImageConstPtr msg;
};

// A few frames of the driving scenario (robots, ball, varying light) at their told poses.
std::vector<Frame> renderFrames(const Calibration& cal, int count) {
  const sim::Renderer renderer(cal);
  const sim::Scenario scenario = sim::makeScenario("driving", sim::ScenarioLength::kSmall, cal, 1);
  std::vector<Frame> frames;
  for (int i = 0; i < count; ++i) {
    const auto& f = scenario.frames[(i * 11) % scenario.frames.size()];
    Frame out;
    out.rgb = renderer.render(f.scene).rgb;
    out.pose = f.told_pose;
    cv_bridge::CvImage image(std_msgs::Header(), "rgb8", out.rgb);
    image.header.seq = static_cast<uint32_t>(i);
    image.header.stamp = ros::Time(100 + i);
    image.header.frame_id = "omni_camera";
    out.msg = image.toImageMsg();
    frames.push_back(out);
  }
  return frames;
}

ImageView view(const Frame& f) { return ImageView::fromMat(f.rgb, PixelFormat::kRgb8); }

// The ACT trainer nodelet's per-image work (src/nodelets/act_trainer_nodelet.cpp, processImage):
// a view of the message, checkImage, one cycle, the table copied into a shared message.
act_color::ColorLutConstPtr trainerCallback(ActTrainer& trainer, const sensor_msgs::ImageConstPtr& msg,
                                            const Pose2D& pose, core::CycleStats::Ball* ball) {
  ImageView v;
  std::string error;
  if (!conv::imageView(*msg, &v, &error)) throw std::runtime_error(error);
  trainer.checkImage(v);
  *ball = trainer.cycle(v, pose).ball;  // published on /act/ball when seen
  return conv::toMsg(trainer, msg->header);
}

// The segmentation nodelet's per-image work (src/nodelets/segmentation_nodelet.cpp, process): a
// view of the message, the labels written straight into a new mono8 message with the shared
// table (no copy of it), white and black beyond the carpet's edge unlabelled (~carpet_edge), the ball the
// trainer saw labelled as its image.
sensor_msgs::ImageConstPtr segmentationCallback(const core::Segmenter& segmenter, const core::CarpetEdge& carpet_edge,
                                                const core::OmniCameraModel& camera,
                                                const sensor_msgs::ImageConstPtr& image,
                                                const act_color::ColorLutConstPtr& lut,
                                                const core::CycleStats::Ball& ball) {
  ImageView v;
  std::string error;
  if (!conv::imageView(*image, &v, &error)) throw std::runtime_error(error);
  cv::Mat labels;
  sensor_msgs::ImagePtr labels_msg = conv::newLabelsMsg(*image, &labels);
  segmenter.classify(conv::lutView(*lut), v, labels);
  carpet_edge.unlabelBeyond(labels);
  if (ball.seen) core::labelBallImage(camera, 0.11, ball.x_m, ball.y_m, labels);
  return labels_msg;
}

// Both nodelets connected by real publishers in this process (one callback queue, as a
// single-threaded nodelet manager): camera image -> trainer and segmentation; table ->
// segmentation; labels -> a sink.
class RosPipeline {
 public:
  RosPipeline(ActTrainer* trainer, const core::Segmenter* segmenter)
      : trainer_(trainer), segmenter_(segmenter), carpet_edge_(trainer->model().camera()) {
    nh_.setCallbackQueue(&queue_);
    image_pub_ = nh_.advertise<sensor_msgs::Image>("act_benchmark/image", 2);
    lut_pub_ = nh_.advertise<act_color::ColorLut>("act_benchmark/color_lut", 2);
    labels_pub_ = nh_.advertise<sensor_msgs::Image>("act_benchmark/labels", 2);
    subs_.push_back(nh_.subscribe<sensor_msgs::Image>("act_benchmark/image", 2, &RosPipeline::onTrainerImage, this));
    subs_.push_back(nh_.subscribe<sensor_msgs::Image>("act_benchmark/image", 2, &RosPipeline::onSegImage, this));
    subs_.push_back(nh_.subscribe<act_color::ColorLut>("act_benchmark/color_lut", 2, &RosPipeline::onTable, this));
    subs_.push_back(nh_.subscribe<sensor_msgs::Image>("act_benchmark/labels", 2, &RosPipeline::onLabels, this));
    // Wait until the intra-process connections exist (the two image subscribers of this process
    // share one subscription: one subscriber for the publisher).
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(5.0);
    while (ros::WallTime::now() < deadline && (image_pub_.getNumSubscribers() < 1 || lut_pub_.getNumSubscribers() < 1 ||
                                               labels_pub_.getNumSubscribers() < 1)) {
      queue_.callAvailable(ros::WallDuration(0.01));
    }
    connected_ = image_pub_.getNumSubscribers() >= 1 && lut_pub_.getNumSubscribers() >= 1 &&
                 labels_pub_.getNumSubscribers() >= 1;
  }
  bool connected() const { return connected_; }
  uint64_t zeroCopyTables() const { return zero_copy_; }

  void frame(const sensor_msgs::ImageConstPtr& image, const Pose2D& pose) {
    pose_ = pose;
    const uint64_t want = labels_ + 1;
    image_pub_.publish(image);
    while (labels_ < want) queue_.callAvailable(ros::WallDuration(0.1));
  }

 private:
  void onTrainerImage(const sensor_msgs::ImageConstPtr& msg) {
    act_color::ColorLutConstPtr lut = trainerCallback(*trainer_, msg, pose_, &ball_);
    published_lut_ = lut.get();
    lut_pub_.publish(lut);
  }
  void onSegImage(const sensor_msgs::ImageConstPtr& msg) {
    pending_ = msg;
    flush();
  }
  void onTable(const act_color::ColorLutConstPtr& lut) {
    if (lut.get() == published_lut_) ++zero_copy_;
    table_ = lut;
    flush();
  }
  void flush() {
    if (!pending_ || !table_ || table_->header.stamp != pending_->header.stamp) return;
    labels_pub_.publish(
        segmentationCallback(*segmenter_, carpet_edge_, trainer_->model().camera(), pending_, table_, ball_));
    pending_.reset();
  }
  void onLabels(const sensor_msgs::ImageConstPtr&) { ++labels_; }

  ActTrainer* trainer_;
  const core::Segmenter* segmenter_;
  const core::CarpetEdge carpet_edge_;
  ros::CallbackQueue queue_;
  ros::NodeHandle nh_;
  ros::Publisher image_pub_, lut_pub_, labels_pub_;
  std::vector<ros::Subscriber> subs_;
  Pose2D pose_;
  core::CycleStats::Ball ball_;  // the trainer's sighting in the image being segmented
  sensor_msgs::ImageConstPtr pending_;
  act_color::ColorLutConstPtr table_;
  const act_color::ColorLut* published_lut_ = nullptr;
  uint64_t labels_ = 0, zero_copy_ = 0;
  bool connected_ = false;
};

struct SizeResult {
  int width, height;
  std::vector<tools::Timing> timings;
  std::map<std::string, double> agreement;  // fraction of pixels with the same label as Segmenter
};

// Issue 13's ball stage off (ActParams::ball_training), the rest as trained.
void switchOffBallStage(ActTrainer& trainer) {
  ActParams params = trainer.params();
  params.ball_training = false;
  trainer.setParams(params);
}

std::string sizeName(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

bool ros_started = false;
bool ros_master = false;

SizeResult benchmarkSize(const Calibration& cal, double sample_ms, int samples) {
  const int w = cal.camera.width, h = cal.camera.height;
  std::cerr << "act_benchmark: " << sizeName(w, h) << ": rendering frames and training the table\n";
  std::vector<Frame> frames = renderFrames(cal, 4);
  ActTrainer trainer(cal);
  trainer.bootstrap(view(frames[0]), frames[0].pose, core::kDefaultBootstrapCycles);
  for (int r = 0; r < 3; ++r) {
    for (const Frame& f : frames) trainer.cycle(view(f), f.pose);
  }
  const core::Segmenter segmenter(cal.camera);
  const core::Segmenter unmasked;  // every pixel, as the baselines
  const core::Segmenter lut_view_segmenter(cal.camera);
  const auto boxes = tools::boxesFromClusters(trainer.clusters());
  const tools::CmvisionClassifier cmvision(boxes);
  const tools::InRangeClassifier in_range(boxes);

  SizeResult result{w, h, {}, {}};
  auto add = [&](const std::string& name, const std::function<void()>& op) {
    result.timings.push_back(tools::timeIt(name, w, h, op, sample_ms, samples));
    const auto& t = result.timings.back();
    std::cerr << "  " << std::left << std::setw(28) << name << std::right << std::fixed << std::setprecision(4)
              << t.median_ms << " ms\n";
  };

  size_t i = 0;
  // ACT cycles on a copy of the trainer, so that every size trains the same way.
  ActTrainer cycling = trainer;
  add("act_cycle", [&] {
    const Frame& f = frames[i++ % frames.size()];
    cycling.cycle(view(f), f.pose);
  });
  // The same without issue 13's ball stage (ActParams::ball_training false): what it costs.
  ActTrainer cycling_no_ball = trainer;
  switchOffBallStage(cycling_no_ball);
  add("act_cycle_no_ball", [&] {
    const Frame& f = frames[i++ % frames.size()];
    cycling_no_ball.cycle(view(f), f.pose);
  });
  // The trainer nodelet's ~learn_self_mask: one pose counted by core::SelfMaskLearner (on the
  // worker's thread, SelfMaskWorker) and the image callback's share of it, the table copied for
  // the worker (once per new pose; every other frame costs one pose comparison).
  {
    core::SelfMaskLearner learner(cal);
    int turn = 0;
    add("self_mask_count_pose", [&] {
      const Frame& f = frames[i++ % frames.size()];
      Pose2D pose = f.pose;
      pose.theta_rad += 0.35 * (++turn % 16);  // 20 degrees on: every call is a new pose, counted
      learner.add(view(f), pose, trainer.lut());
    });
    volatile uint8_t sink = 0;
    add("self_mask_table_copy", [&] {
      const core::ColorLut copy = trainer.lut();
      sink = copy.data()[i++ % copy.size()];
    });
    (void)sink;
  }
  cv::Mat labels, labels_b;
  add("classify", [&] { segmenter.classify(trainer.lut(), view(frames[i++ % frames.size()]), labels); });
  add("classify_unmasked", [&] { unmasked.classify(trainer.lut(), view(frames[i++ % frames.size()]), labels); });
  // The segmentation's labelling of a ball sighting (core::labelBallImage) on classified labels
  // (with a copy of the labels, some 3 us at 580x580, so that every call labels the same).
  {
    ActTrainer seeing = trainer;
    core::CycleStats::Ball seen;
    for (size_t k = 0; k < frames.size() && !seen.seen; ++k) seen = seeing.cycle(view(frames[k]), frames[k].pose).ball;
    if (seen.seen) {
      segmenter.classify(trainer.lut(), view(frames[0]), labels);
      cv::Mat work = labels.clone();
      add("label_ball", [&] {
        labels.copyTo(work);
        core::labelBallImage(trainer.model().camera(), 0.11, seen.x_m, seen.y_m, work);
      });
    }
  }
  // ~carpet_edge's pass over classified labels (with a copy of the labels, as label_ball).
  const core::CarpetEdge carpet_edge(trainer.model().camera());
  {
    segmenter.classify(trainer.lut(), view(frames[0]), labels);
    cv::Mat work = labels.clone();
    add("carpet_edge", [&] {
      labels.copyTo(work);
      carpet_edge.unlabelBeyond(work);
    });
  }
  core::LutView lv{trainer.lut().data(), trainer.lut().size(), trainer.lut().bitsPerChannel(), core::ColorSpace::kRgb};
  add("classify_lutview_nodelet", [&] { lut_view_segmenter.classify(lv, view(frames[i++ % frames.size()]), labels); });
  add("cmvision_bitmask", [&] { cmvision.classify(frames[i++ % frames.size()].rgb, labels); });
  add("inrange_per_class", [&] { in_range.classify(frames[i++ % frames.size()].rgb, labels); });
  // The nodelets' steps one by one.
  add("step_image_view", [&] {
    ImageView v;
    std::string e;
    conv::imageView(*frames[i++ % frames.size()].msg, &v, &e);
  });
  add("step_table_to_msg", [&] { conv::toMsg(trainer, frames[i++ % frames.size()].msg->header); });
  add("step_labels_to_msg", [&] { conv::labelsToMsg(labels, frames[i++ % frames.size()].msg->header); });
  // Both nodelets' per-frame work.
  ActTrainer path_trainer = trainer;
  uint64_t balls_seen = 0;
  add("nodelet_path_calls", [&] {
    const Frame& f = frames[i++ % frames.size()];
    core::CycleStats::Ball ball;
    const auto lut = trainerCallback(path_trainer, f.msg, f.pose, &ball);
    balls_seen += ball.seen;
    segmentationCallback(lut_view_segmenter, carpet_edge, path_trainer.model().camera(), f.msg, lut, ball);
  });
  // How many of the path's images had a ball sighting (labelled as its image by the segmentation).
  result.agreement["nodelet_path_ball_sightings"] = static_cast<double>(balls_seen);
  if (ros_master) {
    ActTrainer ros_trainer = trainer;
    RosPipeline pipeline(&ros_trainer, &lut_view_segmenter);
    if (pipeline.connected()) {
      uint32_t stamp = 1000;
      add("nodelet_path_published", [&] {
        const Frame& f = frames[i++ % frames.size()];
        auto msg = boost::make_shared<sensor_msgs::Image>(*f.msg);  // a fresh stamp per frame
        msg->header.stamp = ros::Time(stamp++);
        pipeline.frame(msg, f.pose);
      });
      result.agreement["zero_copy_tables"] = static_cast<double>(pipeline.zeroCopyTables());
    } else {
      std::cerr << "act_benchmark: publishers did not connect; published path skipped\n";
    }
  }

  // How far the baselines' labels are from the table's (they are thresholds, not the table).
  segmenter.classify(trainer.lut(), view(frames[0]), labels);
  lut_view_segmenter.classify(lv, view(frames[0]), labels_b);
  result.agreement["lutview_vs_classify"] = cv::countNonZero(labels == labels_b) / static_cast<double>(w * h);
  unmasked.classify(trainer.lut(), view(frames[0]), labels);
  cmvision.classify(frames[0].rgb, labels_b);
  result.agreement["cmvision_vs_table"] = cv::countNonZero(labels == labels_b) / static_cast<double>(w * h);
  in_range.classify(frames[0].rgb, labels);
  result.agreement["inrange_vs_cmvision"] = cv::countNonZero(labels == labels_b) / static_cast<double>(w * h);
  return result;
}

const tools::Timing* find(const SizeResult& r, const std::string& name) {
  for (const auto& t : r.timings) {
    if (t.name == name) return &t;
  }
  return nullptr;
}

double ratio(const SizeResult& r, const std::string& slow, const std::string& fast) {
  const auto* a = find(r, slow);
  const auto* b = find(r, fast);
  return a && b && b->median_ms > 0 ? a->median_ms / b->median_ms : 0.0;
}

// Kept out of line so that callgrind can count exactly these cycles (--toggle-collect).
__attribute__((noinline)) void runCallgrindCycles(ActTrainer& trainer, const std::vector<Frame>& frames, int n) {
  for (int i = 0; i < n; ++i) {
    const Frame& f = frames[static_cast<size_t>(i) % frames.size()];
    trainer.cycle(view(f), f.pose);
  }
}

void usage(std::ostream& out) {
  out << "usage: act_benchmark [--calibration CAL.yaml] [--json FILE] [--sizes 580x580,640x480,1280x1024]\n"
         "                     [--samples N (31)] [--sample-ms MS (20)] [--cpu N] [--no-ros]\n"
         "       act_benchmark [--calibration CAL.yaml] --callgrind-cycles N [--no-ball]\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::string calibration_path = std::string(ACT_SOURCE_DIR) + "/config/calibration/msl_2007_580.yaml";
  std::string json_path, sizes_arg = "580x580,640x480,1280x1024";
  int samples = 31, cpu = -1, callgrind_cycles = 0;
  bool ball_stage = true;
  double sample_ms = 20.0;
  bool use_ros = true;
  try {
    for (int a = 1; a < argc; ++a) {
      const std::string arg = argv[a];
      auto value = [&]() -> std::string {
        if (a + 1 >= argc) throw std::invalid_argument(arg + " needs a value");
        return argv[++a];
      };
      if (arg == "--calibration") {
        calibration_path = value();
      } else if (arg == "--json") {
        json_path = value();
      } else if (arg == "--sizes") {
        sizes_arg = value();
      } else if (arg == "--samples") {
        samples = std::max(1, std::stoi(value()));
      } else if (arg == "--sample-ms") {
        sample_ms = std::stod(value());
      } else if (arg == "--cpu") {
        cpu = std::stoi(value());
      } else if (arg == "--callgrind-cycles") {
        callgrind_cycles = std::stoi(value());
      } else if (arg == "--no-ball") {
        ball_stage = false;
      } else if (arg == "--no-ros") {
        use_ros = false;
      } else if (arg == "--help" || arg == "-h") {
        usage(std::cout);
        return 0;
      } else {
        throw std::invalid_argument("unknown option " + arg);
      }
    }
  } catch (const std::exception& e) {
    std::cerr << "act_benchmark: " << e.what() << "\n";
    usage(std::cerr);
    return 2;
  }
  if (cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    if (sched_setaffinity(0, sizeof set, &set) != 0) std::cerr << "act_benchmark: cannot pin to cpu " << cpu << "\n";
  }
  const Calibration base = core::loadCalibration(calibration_path);
  ros::Time::init();

  if (callgrind_cycles > 0) {
    std::vector<Frame> frames = renderFrames(base, 4);
    ActTrainer trainer(base);
    trainer.bootstrap(view(frames[0]), frames[0].pose, core::kDefaultBootstrapCycles);
    for (const Frame& f : frames) trainer.cycle(view(f), f.pose);
    if (!ball_stage) switchOffBallStage(trainer);
    runCallgrindCycles(trainer, frames, callgrind_cycles);
    std::cout << "act_benchmark: " << callgrind_cycles << " ACT cycles on "
              << sizeName(base.camera.width, base.camera.height) << " frames in runCallgrindCycles\n";
    return 0;
  }

  if (use_ros) {
    ros::init(argc, argv, "act_benchmark",
              ros::init_options::AnonymousName | ros::init_options::NoSigintHandler | ros::init_options::NoRosout);
    ros_started = true;
    ros_master = ros::master::check();
    if (ros_master) {
      ros::start();
    } else {
      std::cerr << "act_benchmark: no ROS master at " << ros::master::getURI()
                << ": the nodelet path is timed without publishing (scripts/benchmark.sh starts one)\n";
    }
  }

  std::vector<SizeResult> results;
  std::stringstream sizes(sizes_arg);
  std::string item;
  while (std::getline(sizes, item, ',')) {
    const size_t x = item.find('x');
    if (x == std::string::npos) {
      std::cerr << "act_benchmark: bad size " << item << "\n";
      return 2;
    }
    const int w = std::stoi(item.substr(0, x)), h = std::stoi(item.substr(x + 1));
    const Calibration cal =
        (w == base.camera.width && h == base.camera.height) ? base : tools::scaledCalibration(base, w, h);
    core::validateCalibration(cal, "scaled calibration " + item);
    results.push_back(benchmarkSize(cal, sample_ms, samples));
  }
  if (ros_master) ros::shutdown();

  // Table.
  std::ostringstream out;
  out << std::fixed;
  out << "act_benchmark: medians of " << samples << " samples (each a batch of calls of about " << sample_ms
      << " ms)\n";
  out << std::left << std::setw(12) << "size" << std::setw(28) << "case" << std::right << std::setw(11) << "median ms"
      << std::setw(11) << "min ms" << std::setw(11) << "p90 ms" << std::setw(12) << "Mpixel/s"
      << "\n";
  for (const auto& r : results) {
    for (const auto& t : r.timings) {
      out << std::left << std::setw(12) << sizeName(r.width, r.height) << std::setw(28) << t.name << std::right
          << std::setprecision(4) << std::setw(11) << t.median_ms << std::setw(11) << t.min_ms << std::setw(11)
          << t.p90_ms << std::setprecision(1) << std::setw(12) << t.pixels_per_s() / 1e6 << "\n";
    }
  }
  out << "\nratios (baseline median / ours; > 1: ours faster)\n";
  for (const auto& r : results) {
    const std::string s = sizeName(r.width, r.height);
    out << std::setprecision(2) << s << ": classify vs inRange " << ratio(r, "inrange_per_class", "classify")
        << "x, vs CMVision " << ratio(r, "cmvision_bitmask", "classify") << "x; unmasked classify vs inRange "
        << ratio(r, "inrange_per_class", "classify_unmasked") << "x, vs CMVision "
        << ratio(r, "cmvision_bitmask", "classify_unmasked") << "x; nodelet classify vs inRange "
        << ratio(r, "inrange_per_class", "classify_lutview_nodelet") << "x\n";
  }
  const SizeResult* r580 = nullptr;
  for (const auto& r : results) {
    if (r.width == 580 && r.height == 580) r580 = &r;
  }
  if (r580) {
    const auto* cycle = find(*r580, "act_cycle");
    const auto* cls = find(*r580, "classify");
    const auto* path = find(*r580, "nodelet_path_published") ? find(*r580, "nodelet_path_published")
                                                             : find(*r580, "nodelet_path_calls");
    out << "\ntargets (580x580, one core)\n" << std::setprecision(4);
    out << "  ACT cycle median " << cycle->median_ms
        << " ms <= 0.1 ms: " << (cycle->median_ms <= 0.1 ? "met" : "MISSED") << "\n";
    if (const auto* no_ball = find(*r580, "act_cycle_no_ball")) {
      out << "  (without the ball stage " << no_ball->median_ms << " ms: the stage takes " << std::setprecision(0)
          << 100.0 * (1.0 - no_ball->median_ms / cycle->median_ms) << "% of the cycle)\n"
          << std::setprecision(4);
    }
    if (const auto* pose = find(*r580, "self_mask_count_pose")) {
      const auto* copy = find(*r580, "self_mask_table_copy");
      out << "  (~learn_self_mask: a pose counted in " << pose->median_ms << " ms on its own thread, "
          << std::setprecision(1) << pose->median_ms / cycle->median_ms
          << " ACT cycles; the image callback copies the table, " << std::setprecision(4) << copy->median_ms
          << " ms, once per new pose)\n";
    }
    out << "  classification " << std::setprecision(2) << cls->pixels_per_s() / 1e9
        << " Gpixel/s >= 1: " << (cls->pixels_per_s() >= 1e9 ? "met" : "MISSED") << "; "
        << ratio(*r580, "inrange_per_class", "classify")
        << "x inRange >= 3x: " << (ratio(*r580, "inrange_per_class", "classify") >= 3 ? "met" : "MISSED") << "\n";
    out << "  whole nodelet path (" << path->name << ") " << std::setprecision(4) << path->median_ms
        << " ms <= 1 ms: " << (path->median_ms <= 1.0 ? "met" : "MISSED") << "\n";
  }
  std::cout << out.str();

  if (!json_path.empty()) {
    std::ofstream json(json_path);
    json << std::setprecision(6) << "{\n  \"samples\": " << samples << ",\n  \"sample_ms\": " << sample_ms
         << ",\n  \"ros_master\": " << (ros_master ? "true" : "false") << ",\n  \"sizes\": [\n";
    for (size_t k = 0; k < results.size(); ++k) {
      const auto& r = results[k];
      json << "    {\"width\": " << r.width << ", \"height\": " << r.height << ", \"cases\": [\n";
      for (size_t j = 0; j < r.timings.size(); ++j) {
        const auto& t = r.timings[j];
        json << "      {\"name\": \"" << t.name << "\", \"median_ms\": " << t.median_ms << ", \"min_ms\": " << t.min_ms
             << ", \"p90_ms\": " << t.p90_ms << ", \"pixels_per_s\": " << t.pixels_per_s() << ", \"batch\": " << t.batch
             << "}" << (j + 1 < r.timings.size() ? "," : "") << "\n";
      }
      json << "    ], \"ratios\": {\"classify_vs_inrange\": " << ratio(r, "inrange_per_class", "classify")
           << ", \"classify_vs_cmvision\": " << ratio(r, "cmvision_bitmask", "classify")
           << ", \"classify_unmasked_vs_inrange\": " << ratio(r, "inrange_per_class", "classify_unmasked")
           << ", \"classify_unmasked_vs_cmvision\": " << ratio(r, "cmvision_bitmask", "classify_unmasked")
           << ", \"nodelet_classify_vs_inrange\": " << ratio(r, "inrange_per_class", "classify_lutview_nodelet")
           << "}, \"agreement\": {";
      size_t n = 0;
      for (const auto& [name, v] : r.agreement) json << (n++ ? ", " : "") << "\"" << name << "\": " << v;
      json << "}}" << (k + 1 < results.size() ? "," : "") << "\n";
    }
    json << "  ]\n}\n";
    std::cerr << "act_benchmark: wrote " << json_path << "\n";
  }
  return 0;
}
