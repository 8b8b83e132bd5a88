#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include "act_color/core/ball_detector.hpp"
#include "act_color/core/calibration.hpp"
#include "act_color/core/carpet_edge.hpp"
#include "act_color/core/class_cluster.hpp"
#include "act_color/core/color_lut.hpp"
#include "act_color/core/expected_class_model.hpp"
#include "act_color/core/image_view.hpp"
#include "act_color/core/light_model.hpp"
#include "act_color/core/types.hpp"

namespace act_color {
namespace core {

// The range of ActParams::ball_diameter_m (and of the segmentation's, which must equal it).
constexpr double kMinBallDiameterM = 0.05, kMaxBallDiameterM = 1.0;

// Parameters of ACT; defaults are the paper's. validate() throws std::invalid_argument naming
// the parameter and its allowed range.
struct ActParams {
  double eta = 4.0;          // eq. 4, 5
  double zeta = 2.5;         // add c -> k when |mu_k - c| < zeta * sigma_k (2.3)
  double xi = 1.35;          // remove c from k when |mu_k - c| > xi * sigma_k (2.4)
  double sigma_min = 6.0;    // lower bound of sigma_k, channel units (2.2)
  int cluster_stride = 400;  // every n-th pixel updates the clusters (2.2)
  int add_stride = 400;      // every n-th pixel is added (2.3)
  int remove_stride = 20;    // every n-th pixel off the field is removed (2.4)
  int lut_bits = 6;          // bits per channel of the table
  bool white_filter = true;  // eq. 1
  uint32_t seed = 1;         // random start pixels
  // Extensions beyond the paper (0 / false gives the paper's algorithm exactly):
  // An added color also adds the cells within this many cells per channel around it whose
  // centres lie within zeta * sigma_k, unless they belong to a class whose cluster is nearer
  // (distance in sigmas). Sparse samples then cover a class's colors in a few cycles. Such a
  // cell has not been seen in the field itself: until a sample of its own confirms it, it is
  // removed when seen off the field, whatever its distance from the cluster (off-field colors
  // near a class, like a whitish hall floor, do not stay in the class by vicinity alone).
  int add_neighbourhood_cells = 1;
  // When the carpet's median color jumps beyond 0.4 sigma of green (a global change of light or
  // of the camera's settings), the per-channel monotone map of colors estimated by LightModel
  // (quantiles of the carpet, line and chassis pixels before and after) moves every cluster and
  // the table, so that all classes follow at once instead of re-learning from sparse samples.
  // Anchors that do not move as one light would move them are left to the clusters.
  bool light_compensation = true;
  // In the cycle of such a change of light and the seven after it every n-th pixel is added
  // (instead of add_stride), so that what the moved table misses is filled at once (ActTrainer's
  // kDenseAddCycles).
  int light_change_add_stride = 50;
  // A black cell confirmed by an in-field sample (within zeta * sigma) in the last n cycles is not
  // removed for being seen off the field: the robots' colors, which dark hall clutter shows too,
  // stay with black while robots confirm them. 0: the paper's removal.
  int removal_protect_cycles = 10;
  // The other robots' height (m; MSL: at most 0.8). A robot standing on the carpet is imaged
  // farther out than where it stands (its top at h / (h - H) times the floor range, h the camera's
  // height; beyond the horizon when h <= H), so that a robot near the carpet's edge shows its colors
  // where the pose expects the hall. In a sector of bearings where a removal sample on the carpet
  // within that reach of the edge is black in the table, 2.4's samples within the reach do not
  // count against black. 0: every off-field sample counts (the paper).
  double robot_height_m = 0.8;
  // Black is the own chassis and the other robots, but the chassis alone is lit differently from
  // robots elsewhere on the field: a color expected green or a goal that is far from green (beyond
  // zeta times the carpet's own spread, which the robots and struts on it do not widen), dark
  // (intensity below 80% of green's in the light before the first change, a limit carried through
  // changes by its place between the own chassis and the carpet) and unsaturated is a robot
  // standing on the carpet or in front of a goal and trains black instead. A color expected in a
  // goal with less than half the carpet's chroma (grey beside it: a robot or a person in front of
  // the goal) trains no goal.
  bool robots_train_black = true;
  // A color joins class k only when k's cluster mean is the nearest of the trained clusters'
  // means: the table splits mixed colors (the blurred edge of a line on the carpet) where they are
  // half one class and half the other, not at zeta * sigma of the wider cluster. A goal whose mean
  // lies with white's (markAbsentGoals) is absent: a lab field without goals.
  bool nearest_mean = true;
  // Each table cell counts, with a half-life of kEvidenceHalfLifeCycles, the pixels estimated to
  // show its color in the field as its class (in-field samples x add stride) and off the field
  // (off-field samples x remove_stride). A cell whose off-field count exceeds this many times its
  // in-field count is removed whatever its distance from the cluster: the color is more often
  // something else than the class (a spot-lit whitish hall floor next to white). A clipped color
  // (a channel at 254 or 255) needs five times the in-field count: a saturated line and a saturated
  // lamp are one color, and after a brightening that clips the lines' cores the hall's clipped
  // pixels can outnumber them. The carpet's, the goals' and the ball's colors need only the
  // majority (at most this ratio, 1: regions sampled all over need no margin). The other way
  // round, a color seen in the field at least twice as often as off it is not removed for lying
  // beyond xi sigma (kEvidenceKeepRatio). 0: off.
  double evidence_removal_ratio = 3.0;
  // Where the carpet meets a line the image shows mixed colors (blur, a line narrower than a
  // pixel), and the field model says which side of the boundary each pixel lies on. Along the axis
  // from green's mean to white's, the colors of the pixels the model puts on the line (eq. 1) and of
  // the carpet pixels next to it are counted, and the nearest-mean rule splits the two classes where
  // the model's pixels change from one to the other (fewest pixels on the wrong side) instead of at
  // the middle between the means; white's cells wholly on the carpet's side are removed when seen.
  bool learned_boundary = true;
  // "Every n-th pixel" (2.2-2.4) as every s-th, s = latticeStride(n, width) a little above n,
  // whose samples spread over the whole image (pixel_lattice.hpp): every 400th pixel of an 800 px
  // wide image lies in two of its columns, and a frame's samples then miss whatever lies between.
  bool lattice_sampling = true;
  // A frame whose pose the table contradicts trains nothing (2.2-2.4 and the ball are skipped):
  // when far more of its cluster samples than usual (expected green, white or a goal, the classes
  // the pose decides) have a color the table gives to another of these classes, the pose is more
  // likely wrong than the table (kPoseContradiction and those after it). Checked once the start-up
  // training is done, not in the cycles of a change of light; after kMaxPoseRejections frames in a
  // row the table is taken to be the one at fault and trains again until a frame agrees with it.
  bool pose_check = true;
  // Beyond the paper, which leaves the ball out (2.1): the ball's color is learned from its shape.
  // Compact blobs on the carpet of the image size a sphere of ball_diameter_m has at their
  // distance, surrounded by carpet and of a color no trained class has, are ball candidates; a
  // color that is such a candidate in kBallSeedFrames frames (at several places, or twice as many
  // frames at one) seeds the ball's cluster (class 6). From then on the blob classified as the ball
  // updates the cluster (eq. 4, 5) and adds its colors (2.3); the ball never takes a color of
  // another class, and 2.4 removes its colors seen off the field like the others'.
  bool ball_training = true;
  double ball_diameter_m = 0.22;  // in [kMinBallDiameterM, kMaxBallDiameterM]
  // Beyond the paper, in the labels (not the table): white seen beyond the carpet's outer edge is
  // the hall, since the lines lie on the carpet, and so is black there unless a robot stands on
  // the carpet in that direction; the edge is found in each classified image along every bearing,
  // without the pose (core::CarpetEdge, ActTrainer::unlabelBeyondCarpet).
  bool carpet_edge = true;

  void validate() const;
  // Sets the parameter `name` (as the field is named) from text; throws std::invalid_argument for
  // an unknown name or a value that does not parse. validate() checks the range.
  void set(const std::string& name, const std::string& value);
  // set() from "name=value" (the tools' --set); throws std::invalid_argument without the '='.
  void assign(const std::string& assignment);
  // Every extension off: the paper's algorithm exactly.
  void switchOffExtensions();
  static ActParams paper();
};

// Cycles of the start-up training on the first image (paper, section 2): enough for the sparse
// samples to cover every class's colors, so that later cycles only follow changes.
constexpr int kDefaultBootstrapCycles = 100;

// What one cycle did.
struct CycleStats {
  std::array<uint32_t, kNumClasses> cluster_samples{};  // colors that updated each cluster
  std::array<uint32_t, kNumClasses> added{};            // table cells set to each class
  std::array<uint32_t, kNumClasses> removed{};          // cells of each class cleared
  uint32_t remove_candidates = 0;                       // off-field samples whose color is mapped to a class (2.4)
  uint32_t doublings = 0;                               // sigma doublings over all clusters
  bool color_space_changed = false;                     // table reset for a new color space
  bool light_change = false;                            // light compensation applied
  Eigen::Vector3f light_gain{1.f, 1.f, 1.f};            // its per-channel gain at the carpet's color
  bool light_restored = false;                          // a change back to a light seen before: its table restored
  bool ball_seeded = false;                             // the ball's cluster was (re)seeded
  bool pose_contradicted = false;                       // the table contradicts the pose: no training (pose_check)
  float contradiction = 0.f;                            // the share of cluster samples the table gives another class
  // The ball as seen in this image (ActParams::ball_training), under the table before 2.4.
  struct Ball {
    bool seen = false;
    double x_m = 0, y_m = 0;  // its centre on the carpet, base_link
    double distance_m = 0;
    double u = 0, v = 0;  // image centroid of its blob
    uint32_t pixels = 0;
  } ball;
};

// Ball training (ActParams::ball_training): frames of consistent evidence before a color seeds
// the ball's cluster, and the distinct places (ball positions in base_link kBallPlaceSpacingM
// apart) among them; at a single place twice the frames are needed. Over those frames the blobs
// are, on average, no larger than a ball: one frame's noise or blur widens a ball's blob, but a
// ball is not wider frame after frame (a shadow across the carpet's edge, tuning scene 17, was
// 1.8 times as wide as a ball on average and seeded a ball where there was none; the balls that
// seed on the tuning split measure at most 1.43). And round: a mirror strut seen between the
// lines is a blob as long as a ball radially and half as wide, 2.6 times as long as wide on
// average (fresh scene 2031 seeded its struts' blue-grey once 16 blobs a cycle were measured).
constexpr int kBallSeedFrames = 6;
constexpr int kBallSeedPlaces = 2;
constexpr double kBallPlaceSpacingM = 0.3;
constexpr double kBallSeedMaxMeanExtent = 1.5;
constexpr double kBallSeedMaxMeanElongation = 2.0;

// ActParams::pose_check. A frame is refused when the share of its samples that contradict the table
// is above kPoseContradiction and above kPoseContradictionRatio times its running level over the
// frames that trained (exponential, rate kPoseLevelRate): on the simulator's scenes, with the pose
// 2.5 m and 165 deg off (the paper's wrong pose, act_eval's tuning split) 5-14% contradict, with a
// right pose 0.5% (median; 1% of the frames above 4.4%), but on a real camera whose calibration is
// a fit a right pose has 2-7% (act_real_eval, nubot_1_bak_bak). A change of light moves colors
// across classes before the table follows: the kPoseCheckQuietCycles cycles after one are not
// refused. The family's wrong poses last 8-40 frames.
constexpr double kPoseContradiction = 0.05;
constexpr double kPoseContradictionRatio = 3.0;
constexpr double kPoseLevelRate = 0.1;
constexpr int kPoseCheckQuietCycles = 3;
constexpr int kMaxPoseRejections = 30;

// The ACT algorithm (paper, section 2): one cycle per image and pose.
class ActTrainer {
 public:
  explicit ActTrainer(const Calibration& calibration, const ActParams& params = ActParams());

  // Throws std::invalid_argument when the image does not fit the calibration.
  void checkImage(const ImageView& image) const;

  // One training cycle: cluster update (2.2), additions (2.3), removals (2.4).
  CycleStats cycle(const ImageView& image, const Pose2D& pose);
  // The start-up table: `cycles` cycles on one image at a known pose (paper, section 2); the ball
  // stage runs in the last one only.
  void bootstrap(const ImageView& image, const Pose2D& pose, int cycles);

  // New parameters keep the table and clusters unless lut_bits changes.
  void setParams(const ActParams& params);
  // The camera model from now on, e.g. one whose calibration has the own robot's pixels learned
  // while the robot drives as its self mask (they train nothing, 2.4 does not look at them). The
  // table, the clusters and every count stay. Building a model takes some 10 ms at 640x480: build it
  // off the image's thread and hand it over. Throws std::invalid_argument for another image size.
  void replaceModel(ExpectedClassModel model);
  const ActParams& params() const { return params_; }
  // Empty table, clusters at eq. 2-3.
  void reset(ColorSpace space);
  // Installs a saved table (e.g. from a file); throws std::invalid_argument if sizes differ.
  void loadTable(const ColorLut& lut);
  // A cluster as saved with its table (ColorLut message, ~save_lut file).
  struct SavedCluster {
    int class_id = 0;  // 1 .. kNumClasses - 1
    Eigen::Vector3d mean;
    double sigma = 0;
    // Why this is no cluster of a class (class id, NaN, sigma <= 0, mean outside the channel
    // range); empty when it is one.
    std::string problem() const;
  };
  // The first problem of a saved state's clusters: one's (SavedCluster::problem) or a class given
  // twice; empty when there is none.
  static std::string clustersProblem(const std::vector<SavedCluster>& clusters);
  // The largest revision a saved state may have: cycles are stamped in 32 bits (the removal
  // protection, the kept lights), and 2^31 cycles are two years at 30 Hz.
  static constexpr uint64_t kMaxRevision = uint64_t{1} << 31;
  // Why a saved state's revision is none (above kMaxRevision); empty when it is one.
  static std::string revisionProblem(uint64_t revision);
  // Installs a saved state: the table, the clusters it was trained with and its revision, so that
  // training goes on where it stopped. A class whose cluster is not given, or that has no cell in
  // the table, starts at eq. 2-3. Throws std::invalid_argument for sizes that differ, a cluster
  // that is not one (class id, NaN, sigma <= 0, mean outside the channel range) or a revision
  // above kMaxRevision.
  void restore(const ColorLut& lut, const std::vector<SavedCluster>& clusters, uint64_t revision);

  const ColorLut& lut() const { return lut_; }
  const std::array<ClassCluster, kNumClasses>& clusters() const { return clusters_; }
  // A goal (kYellow, kBlue) taken as absent in the last cycle (ActParams::nearest_mean: its mean
  // lies with white's, as on a field without colored goals).
  bool goalAbsent(uint8_t k) const { return k < kNumClasses && absent_[k]; }
  // True for a cell mapped by add_neighbourhood_cells that no in-field sample has confirmed yet.
  bool neighbourOnly(uint32_t cell) const { return neighbour_only_.at(cell) != 0; }
  uint64_t revision() const { return revision_; }
  const ExpectedClassModel& model() const { return model_; }
  // The ball this cycle saw (`stats.ball`), labelled in the labels of its image: labelBallImage
  // with this camera and ActParams::ball_diameter_m. Returns the pixels relabelled (0 when the
  // cycle saw no ball).
  uint32_t labelBall(const CycleStats& stats, cv::Mat& labels) const;
  // ActParams::carpet_edge: white beyond the carpet's edge in these labels (of the camera's size,
  // as core::Segmenter gives them), and black there where no robot stands on the carpet, labelled
  // unknown (core::CarpetEdge::unlabelBeyond); returns how many pixels (0 when off).
  uint32_t unlabelBeyondCarpet(cv::Mat& labels) const;

 private:
  ClusterParams clusterParams() const;
  // 2.3 for one color; returns the number of cells that changed to class k. A pixel of a ball
  // sighting (`ball_sighting`) is the ball's by the blob's shape, not by the cluster: it is added
  // without 2.3's zeta sigma test.
  uint32_t addColor(const uint8_t c[3], uint8_t k, bool ball_sighting = false);
  // ActParams::nearest_mean: another trained cluster's mean is nearer to the color than k's.
  // Uses the boundaries from prepareNearestMean(), made after this cycle's cluster update.
  // Not for a shaded carpet color (shadedCarpet).
  bool nearerToOtherMean(const Eigen::Vector3d& color, uint8_t k) const;
  void prepareNearestMean();
  // ActParams::nearest_mean: a goal whose cluster mean lies nearer to white's than
  // kAbsentGoalFraction of the distance from green's to white's is taken as absent this cycle
  // (a lab field without goals: its region shows the hall's white walls); its cells are cleared.
  void markAbsentGoals(CycleStats& stats);
  // True when the color is mapped to a trained class other than k and is nearer to that class's
  // cluster than to k's, in units of sigma.
  bool claimedByOtherClass(const Eigen::Vector3d& color, uint8_t current, uint8_t k) const;
  // The class a sample expected as k trains (robots_train_black re-routes green and goal colors
  // of robots to black); `dark_limit` is darkLimit() of the clusters the pass samples against.
  uint8_t trainedClass(uint8_t k, const uint8_t c[3], double dark_limit) const;
  // robots_train_black: a robot is a body, not a pixel. Adds the color c of a sample at (u, v) that
  // trained black where the pose expects the carpet or a goal, and those of the pixels around it
  // that do too, together standing for the sample's pixels (add_weight_); the sample alone near
  // the field's edge.
  uint32_t addRobotBody(const ImageView& image, const PoseTransform& transform, int u, int v, const uint8_t c[3],
                        double dark_limit);
  // ActParams::learned_boundary: counts this cycle's pixels near the carpet-line boundary, learns
  // the split from the counts and removes the white cells that lie wholly on the carpet's side.
  void learnBoundary(const ImageView& image, const PoseTransform& transform, CycleStats& stats);
  // ActParams::evidence_removal_ratio for color c of class k (at most 1 for the ball, the carpet
  // and the goals, higher for a clipped color).
  double evidenceRatio(uint8_t k, const uint8_t c[3]) const;
  // The own chassis's colors (chassis_samples_, an anchor of the light model) and their median
  // intensity, robots_train_black's black of this light.
  void measureChassis(const ImageView& image);
  // robots_train_black's measurements of the carpet need it on and enough of this cycle's samples.
  bool carpetMeasurable() const;
  // robots_train_black's scale of "far from green": the carpet's own spread this cycle.
  void measureCarpetSpread();
  // robots_train_black's least chroma of a goal's color, of the carpet's color this cycle.
  void measureCarpetColor();
  // robots_train_black's shade of the carpet: whether a part of the field lies in a shadow this
  // cycle (carpet_shaded_), from the carpet samples that are dark colors of the carpet's own hue.
  void measureCarpetShade();
  // While carpet_shaded_, a color of the carpet's hue in a shadow (carpet_hue_: within
  // kShadedCarpetHueSpreads of the carpet's spread across the line from black through green's mean,
  // where the line lies farther than that from the greys, and below the carpet's median along it by
  // more than zeta times its spread there): carpet in a shadow, not a robot.
  bool shadedCarpet(const Eigen::Vector3d& c) const;
  // False for a color of a goal sample (k yellow or blue) that is no goal's color.
  bool goalColor(uint8_t k, const Eigen::Vector3f& c) const;
  // Light compensation (after 2.2's samples, before the clusters move): observes the anchors, and
  // when the carpet's median moved, takes a closer look (`look_closer` fills anchor_samples_ with
  // this frame's carpet and line colors) and restores a kept light or moves the table.
  template <class LookCloser>
  void followLight(LookCloser&& look_closer, CycleStats& stats);
  // Light compensation: the map moves every cluster and every table cell.
  void applyLightChange(const LightModel::Map& map);
  // Light that comes and goes (flicker, an exposure controller hunting, one dark frame in ten):
  // the state of each light recently left is kept, and a change back to one of them restores its
  // table, clusters and evidence instead of moving the table once more. Moving it to and fro would
  // spread every class a cell further with each round (the table filled to 98% under flicker).
  // Returns true when it restored one (the state left is kept in its place). A restored light's
  // cycle samples the frame kRestoredDensity times as densely (samplingDensity).
  bool restoreLightState();
  void keepLightState();
  // robots_train_black's intensity below which a color is dark, in this cycle's light.
  double darkLimit() const;
  // The intensity darkLimit() is measured in: the sum of the channels in RGB, 3 Y in YUV (where the
  // sum would add U + V, about 256 for every grey: the own chassis as bright as the carpet).
  double intensity(const Eigen::Vector3d& c) const {
    return lut_.colorSpace() == ColorSpace::kYuv ? 3.0 * c[0] : c.sum();
  }
  // The ball stage (ActParams::ball_training), after 2.3; needs sector_safe_range_ of the pose.
  void trainBall(const ImageView& image, const PoseTransform& transform, CycleStats& stats);

  struct Evidence {
    float in_field = 0.f;
    float off_field = 0.f;
    uint32_t stamp = 0;  // cycle up to which the counts are decayed
  };
  static constexpr double kEvidenceHalfLifeCycles = 40.0;  // 20: black's recall swung more
  static constexpr size_t kEvidenceMemory = 256;           // cycles after which counts are 0
  static constexpr int kMinOffFieldSightings = 3;
  // 2.4 counts the off-field sightings of colors no class has at every n-th such removal sample
  // (each for n samples): see removeOffField. Tuning split, white F1 up / down by 0.02 or more in
  // segments: every sample 16 / 1, every 2nd 18 / 1, every 4th 13 / 1, every 8th 15 / 1; the cost
  // (ray casts, robot checks) falls with n.
  static constexpr uint32_t kUnclassedSightingStride = 8;
  // 2.4's removal beyond xi sigma spares a color whose in-field count is at least this many times
  // its off-field count. Tuning split, sample seeds 1, 2 and 3: at 2, F1 up by 0.02 or more in 11,
  // 9 and 11 segments (black, yellow after a wrong pose, the ball), down in 2, 4 and 0; at 1 (seeds
  // 1 and 2), black up in some 20 segments but the flicker runs' blue precision 0.01-0.04 lower;
  // at 3, hardly a change.
  static constexpr float kEvidenceKeepRatio = 2.f;
  // The cell's counts, decayed to this cycle.
  Evidence& evidence(uint32_t cell);
  // Every change of a cell goes through setCell, which keeps mapped_ in step with the table.
  void setCell(uint32_t cell, uint8_t k);
  // The cell back to kUnknown (2.4), no longer neighbour-only.
  void removeCell(uint32_t cell);
  void rebuildMapped();
  bool mapped(uint32_t cell) const { return (mapped_[cell >> 6] >> (cell & 63)) & 1u; }
  // chassis_pixels_ of model_.
  void findChassisPixels();

  ExpectedClassModel model_;
  ActParams params_;
  ColorLut lut_;
  std::array<ClassCluster, kNumClasses> clusters_;
  std::mt19937 rng_;
  uint64_t revision_ = 0;
  bool space_known_ = false;
  // Between the means of class k and of each other trained class j, the boundary of the nearest-
  // mean rule: j's mean is nearer to color c than k's when normal . c < offset (the rule's
  // distance is a quadratic form, so the boundary is a plane).
  struct MeanBoundary {
    Eigen::Vector3d normal;
    double offset;
  };
  std::array<std::vector<MeanBoundary>, kNumClasses> mean_boundaries_;
  // markAbsentGoals: the goals taken as absent this cycle.
  std::array<bool, kNumClasses> absent_{};
  // ActParams::learned_boundary: decayed counts of line (eq. 1) and carpet pixels next to a line by
  // their position t along the axis from green's mean (0) to white's (1), kBoundaryBins bins over
  // [kBoundaryLow, kBoundaryHigh); the split position learned from them (0.5: the middle).
  static constexpr int kBoundaryBins = 24;
  std::array<float, kBoundaryBins> boundary_line_{};
  std::array<float, kBoundaryBins> boundary_carpet_{};
  double boundary_t_ = 0.5;
  // Per-cycle scratch, kept to avoid allocations.
  std::array<std::vector<Eigen::Vector3f>, kNumClasses> samples_;
  // Expected green, before robots_train_black: an anchor, the carpet's spread and color.
  std::vector<Eigen::Vector3f> carpet_samples_;
  std::vector<Eigen::Vector3f> chassis_samples_;  // the own chassis only: an anchor of the light model
  std::array<std::vector<Eigen::Vector3f>, kNumClasses> anchor_samples_;  // scratch of a denser look
  std::vector<uint32_t> chassis_pixels_;  // every n-th pixel of the own chassis, about 192
  double chassis_intensity_ = 0;          // this cycle's median over them (intensity())
  std::vector<double> chassis_intensities_;
  // darkLimit's position between the chassis (0) and the carpet (1), taken until the first change
  // of light; -1 unset.
  double dark_position_ = -1;
  bool dark_frozen_ = false;
  // robots_train_black's spread of the carpet (measureCarpetSpread; -1: not measured), and the
  // scratch of its measurements (the samples' distances, one channel of their colors).
  double carpet_spread_ = -1;
  std::vector<float> carpet_values_;
  // measureCarpetShade: the carpet's hue (the shade line through green's mean), the distance from
  // it within which a color has that hue (kShadedCarpetHueSpreads times the upper quartile of the
  // carpet samples' distances from it), the positions along it between which such a color is in a
  // shadow, whether more than kShadedCarpetShare of the carpet samples are, and the scratch of
  // their positions along it.
  ShadeLine carpet_hue_;
  bool carpet_shaded_ = false;
  std::vector<float> shade_along_;
  double goal_min_chroma_ = 0;  // goalColor's least chroma, of this cycle's carpet (measureCarpetColor)
  LightModel light_;
  std::vector<uint8_t> warped_;
  // Cycle (revision) in which each cell was last confirmed by an in-field sample of its class.
  std::vector<uint32_t> confirmed_;
  // 1 for cells mapped by add_neighbourhood_cells and not yet seen in the field themselves.
  std::vector<uint8_t> neighbour_only_;
  std::vector<uint8_t> warped_neighbour_only_;
  std::vector<Evidence> evidence_;
  std::vector<Evidence> warped_evidence_;
  struct LightState {
    ColorLut lut;
    std::vector<uint8_t> neighbour_only;
    std::vector<Evidence> evidence;
    std::vector<uint32_t> confirmed;
    std::array<ClassCluster, kNumClasses> clusters;
    LightModel light;
    uint64_t left_at = 0;  // revision when this light was left
  };
  // An exposure swinging 1 +- 0.3 passes some 6-8 lights at the trigger of a change (act_trainer.cpp)
  // on the way up and as many on the way down. With 8 kept, act_flicker's tuning scene 5 at 1 Hz
  // made 19 changes instead of 9 and its table grew to 2.2x the steady run's (1.4x with 16). A
  // state takes some 4.7 MB at 6 bits per channel; at most kLightStatesBytes are kept, at least 2
  // lights (maxLightStates).
  static constexpr size_t kMaxLightStates = 16;
  static constexpr size_t kLightStatesBytes = size_t{80} << 20;
  size_t maxLightStates() const;
  std::vector<LightState> light_states_;  // the most recently left last
  // One bit per table cell: mapped to a class (32 KB for 6 bits per channel).
  std::vector<uint64_t> mapped_;
  // The stride "every n-th pixel" takes: latticeStride(n, width) with lattice_sampling, else n.
  int samplingStride(int n);
  std::unordered_map<int, int> sampling_strides_;
  int add_weight_ = 1;              // pixels one in-field sample stands for in this cycle
  uint64_t last_light_change_ = 0;  // revision_ + 1 of the last change of light; 0: none
  // pose_check: true when this cycle is not to train (stats: contradiction, pose_contradicted).
  bool poseContradicted(CycleStats& stats);
  // The share of this cycle's cluster samples of green, white and the goals whose color the table
  // gives to another of them.
  double poseContradiction() const;
  // A new or loaded table: checked from kDefaultBootstrapCycles cycles on, never within bootstrap().
  void restartPoseCheck();
  bool bootstrapping_ = false;
  uint64_t pose_check_from_ = kDefaultBootstrapCycles;  // a table trained for its start-up cycles
  double pose_contradiction_level_ = -1;                // of the frames that trained; -1: none yet
  int pose_rejections_ = 0;                             // frames rejected in a row
  bool pose_released_ = false;                          // kMaxPoseRejections reached: no rejection until a frame agrees
  // This cycle adds at light_change_add_stride (a change of light's cycle or one of the
  // kDenseAddCycles - 1 after it); its additions fill their cells' neighbourhoods only in the
  // change's own cycle.
  bool denseAddCycle() const;
  bool addsNeighbourhoods() const;
  // The removal step's samples start, start + remove_stride, ... that can ever be off the field,
  // with their removal range (ExpectedClassModel::removalRange), by sector of bearings and
  // farthest first within a sector: the samples that may be off the field at a pose are a prefix
  // of each sector's list (range >= the sector's safe range). Built for each start when first
  // used; cleared when remove_stride changes.
  struct RemovalSample {
    uint32_t pixel;
    float range_m;
    uint16_t u, v;  // column and row of the pixel (calibrated images are at most 16384 px wide)
  };
  struct RemovalSamples {
    std::vector<RemovalSample> samples;
    std::array<uint32_t, ExpectedClassModel::kRemovalSectors + 1> sector_begin{};
  };
  const RemovalSamples& removalSamples(size_t start);
  std::unordered_map<size_t, RemovalSamples> removal_samples_;
  std::array<double, ExpectedClassModel::kRemovalSectors> sector_safe_range_{};
  std::array<double, ExpectedClassModel::kRemovalSectors> sector_off_range_{};  // sectorOffRanges
  // This cycle's samples that may be off the field: per sector, a prefix of its list in
  // removalSamples (read in place: copied, they cost a tenth of the cycle's cache misses).
  std::array<std::pair<const RemovalSample*, const RemovalSample*>, ExpectedClassModel::kRemovalSectors>
      candidate_spans_{};
  // Fills candidate_spans_ from the samples of `start` (sector_safe_range_ of the pose).
  void selectRemovalCandidates(size_t start);
  // ActParams::robot_height_m. A robot standing at floor range d is imaged out to d * robot_reach_
  // (its top). Per sector, this cycle's samples on the carpet from safe range / robot_reach_ on (a
  // robot there is imaged beyond the carpet's edge), a range of removalSamples' list; and whether
  // one of them is black in the table, looked at when a black candidate first asks (kRobotUnknown
  // before).
  double robot_reach_ = 1.0;
  std::array<std::pair<const RemovalSample*, const RemovalSample*>, ExpectedClassModel::kRemovalSectors> robot_bands_{};
  std::array<uint8_t, ExpectedClassModel::kRemovalSectors> robot_sectors_{};
  static constexpr uint8_t kRobotUnknown = 0, kNoRobot = 1, kRobot = 2;
  // An off-field sample of `sector` at floor range `range_m` may show such a robot (of this sector
  // or a neighbouring one: a robot at 5 m spans about a sector).
  template <class Pixels>
  bool maybeRobot(int sector, float range_m, const Pixels& pixels);
  // 2.4 on candidate_spans_, reading their colors through `pixels` (see act_trainer.cpp).
  template <class Pixels>
  void removeOffField(const Pixels& pixels, const PoseTransform& transform, CycleStats& stats);
  int removal_samples_stride_ = 0;
  uint32_t unclassed_samples_ = 0;  // removal samples of colors no class has, so far
  CarpetEdge carpet_edge_;          // ActParams::carpet_edge, of model_'s camera
  // Ball training.
  BallDetector ball_detector_;
  std::vector<BallBlob> ball_blobs_;
  std::vector<BallDetector::KnownColor> ball_known_colors_;
  std::vector<uint32_t> ball_off_field_;
  struct BallHypothesis {
    Eigen::Vector3d mean;
    double spread = 0;
    int frames = 0;
    uint32_t last_seen = 0;
    std::vector<Eigen::Vector2d> places;  // base_link
    // Sums over the frames of the logarithms of the blobs' extents over a ball's (BallBlob).
    double log_radial = 0, log_tangential = 0;
  };
  std::vector<BallHypothesis> ball_hypotheses_;
  uint32_t ball_last_seen_ = 0;            // cycle of the last sighting
  Eigen::Vector2d ball_last_place_{0, 0};  // where, on the field
};

}  // namespace core
}  // namespace act_color
