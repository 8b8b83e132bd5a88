#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "act_color/core/color_lut.hpp"
#include "act_color/core/expected_class_model.hpp"
#include "act_color/core/image_view.hpp"

namespace act_color {
namespace core {

// The image of a ball (a sphere of known radius resting on the floor) through the contract's
// camera model. A sphere seen from the viewpoint fills a circular cone of directions around the
// direction to its centre: its image reaches from the elevation e_c - a to e_c + a radially and
// about +-b in bearing, with a = asin(radius / distance to the centre).
class BallGeometry {
 public:
  // Keeps a reference to the camera: a short-lived helper.
  BallGeometry(const OmniCameraModel& camera, double radius_m);

  struct Image {
    double radial_px = 0;      // extent along the image radius
    double tangential_px = 0;  // extent across it, at the centre's radius
    double area_px = 0;        // of the ellipse with these axes
    // The middle of the radial extent beyond the image of the centre's direction, along the image
    // radius (the elevation map is not linear).
    double centre_offset_px = 0;
  };
  // Expected image of a ball whose centre stands at ground distance d from the robot; false when
  // its centre is not imaged.
  bool expected(double ground_distance_m, Image* out) const;
  // Ground distance of the ball's centre from the image radii of its near and far edge (the
  // midpoint of their elevations is the centre's direction); NaN when it is not on the floor.
  double distanceFromRadii(double r_near_px, double r_far_px) const;
  double radius() const { return radius_m_; }

  // The ellipse of the expected image of a ball whose centre stands above the floor point (x, y)
  // of base_link: its centre, the unit vector along the image radius there, and its half extents
  // along and across it; false when the ball's centre is not imaged.
  struct Ellipse {
    double u = 0, v = 0;
    double axis_u = 1, axis_v = 0;
    double half_radial_px = 0, half_tangential_px = 0;
  };
  bool imageEllipse(double x_m, double y_m, Ellipse* out) const;

 private:
  const OmniCameraModel& camera_;
  double radius_m_;
};

// The ball's image in a label image (issue 13), for a ball seen with its centre above (x, y) of
// base_link: every imaged pixel inside its expected image (BallGeometry::imageEllipse) that the
// table left unknown or gave to the lines becomes the ball's. A table classifies colors, and a
// ball's highlight has the clipped lines' colors and its shaded side the hall's: the sighting's
// shape says what they are. Carpet, robots and goals inside the ellipse keep their class (a ball
// partly hidden). And the ball is one: pixels of the ball's class farther from it than 1.5 times
// its image's extent become unknown (a poster or a team marker of its color). Returns the pixels
// labelled as the ball.
uint32_t labelBallImage(const OmniCameraModel& camera, double radius_m, double x_m, double y_m, cv::Mat& labels);

// A connected blob of pixels on the carpet whose table class is unknown or the ball's, measured
// as a ball would be.
struct BallBlob {
  uint32_t pixels = 0;       // in the blob
  uint32_t ball_pixels = 0;  // of them classified as the ball
  double centroid_u = 0, centroid_v = 0;
  double r_near_px = 0, r_far_px = 0;  // image radii of the nearest and farthest pixel
  double distance_m = 0;               // ground distance of the ball's centre (BallGeometry)
  double base_x_m = 0, base_y_m = 0;   // the ball's centre on the carpet, base_link
  // Measured over expected (BallGeometry::expected at distance_m).
  double radial_ratio = 0, tangential_ratio = 0, area_ratio = 0;
  double fill = 0;                  // pixels over the ellipse of the measured extents
  double surround = 0;              // of the pixels around the blob surely on the carpet, the fraction green or white
  Eigen::Vector3d median{0, 0, 0};  // per-channel median color
  double spread = 0;                // RMS distance of the colors to their mean (as eq. 5's sigma)
  std::vector<uint32_t> members;    // pixel indices (row-major), for training
  std::vector<uint8_t> interior;    // 1 where all four neighbours are in the blob too
};

// Finds ball-like blobs on the carpet: a coarse grid of floor pixels (spaced so that the smallest
// ball image on the field covers several of them) is classified with the table; connected runs of
// unknown or ball pixels that are surely on the carpet at this pose are grown at full resolution
// and measured. About 1/stride^2 of the floor pixels are looked up per cycle.
class BallDetector {
 public:
  // Prepared for the model's camera and field (the model is not kept: pass the same to detect).
  BallDetector(const ExpectedClassModel& model, double radius_m);

  // A color a trained class's cluster includes: pixels unknown to the table but of such a color
  // (the carpet in a shadow not yet trained) are not the ball's. The distance weighs the intensity
  // difference by `intensity_weight` (as the trainer's nearest-mean rule): a darker carpet is carpet.
  // An unknown color that several include belongs to the one it is nearest to in units of their
  // radii; the ball's own cluster may be one of them (`ball`): its colors stay the ball's. (After
  // the paper's darkening a light ball's colors lie within the carpet's radius, which does not
  // shrink below zeta sigma_min, and the ball was never seen again.)
  struct KnownColor {
    Eigen::Vector3f mean;
    float radius_sq;
    float intensity_weight = 1.f;
    bool yuv = false;   // channel 0 is the intensity; else it is the channels' mean
    bool ball = false;  // the ball's cluster
  };
  // Blobs of this image at this pose; `sector_safe_range` from ExpectedClassModel::sectorSafeRanges.
  // Blobs far larger than any ball image are skipped.
  // Also lists the grid's pixels that may be off the field and are classified as the ball
  // (`off_field_ball`): the ball is small, the hall large, and the removal step's sparse samples
  // learn too slowly which of its colors the hall shares; each stands for stride()^2 pixels. They
  // lie at the grid points shifted by `phase` (the cycle): over stride()^2 cycles every pixel.
  // Only with `look_off_field` (a table without ball colors needs none of it).
  void detect(const ExpectedClassModel& model, const ImageView& image, const ColorLut& lut,
              const std::array<double, ExpectedClassModel::kRemovalSectors>& sector_safe_range,
              const std::vector<KnownColor>& known, std::vector<BallBlob>* blobs, std::vector<uint32_t>* off_field_ball,
              uint32_t phase, bool look_off_field);

  double radius() const { return radius_m_; }
  int stride() const { return stride_; }

 private:
  using SafeRanges = std::array<double, ExpectedClassModel::kRemovalSectors>;
  // Grows and measures the blob of seeds_.
  void measure(const ExpectedClassModel& model, const ImageView& image, const ColorLut& lut, const SafeRanges& safe,
               const std::vector<KnownColor>& known, BallBlob* blob);
  // The pixel's class for the blobs: the table's, or for unknown colors that a known class's
  // cluster includes, that class.
  static uint8_t classOf(const ColorLut& lut, const std::vector<KnownColor>& known, const uint8_t c[3]);
  // classOf for a color the table does not know.
  static uint8_t knownClassOf(const std::vector<KnownColor>& known, const uint8_t c[3]);

  double radius_m_;
  int stride_ = 3;
  double reach_ = 1.0;  // floor range over the carpet's safe range that a ball's pixels can have
  int grid_w_ = 0, grid_h_ = 0;
  double max_area_px_ = 0;  // the largest ball image on the carpet
  struct GridPoint {
    uint32_t cell;   // index in the grid
    uint32_t pixel;  // index in the image
    float range_m;
    uint16_t u, v;  // the pixel's column and row
    uint8_t sector;
  };
  std::vector<GridPoint> points_;  // the grid's floor pixels
  std::vector<GridPoint> beyond_;  // the grid's pixels above the horizon (range and sector unused)
  std::vector<uint8_t> sectors_;   // every pixel's removal sector (ExpectedClassModel), 255 off the floor
  // Per-cycle scratch.
  std::vector<uint8_t> grid_;
  std::vector<uint32_t> ball_points_;  // this cycle's grid cells of unknown or ball colors
  std::vector<uint32_t> stack_;
  std::vector<uint32_t> component_;
  struct Component {
    size_t begin, end;   // in component_
    bool of_ball_class;  // a point of the ball's class
  };
  std::vector<Component> components_;
  std::vector<uint32_t> seeds_;   // the pixels of one component's grid points
  std::vector<int8_t> window_;    // full-resolution marks of the blob being grown (measure)
  std::vector<uint32_t> looked_;  // the pixels marked in window_, to unmark
  std::vector<uint32_t> pixel_stack_;
  std::array<std::vector<uint8_t>, 3> channels_;  // a blob's colors by channel, for the medians
  std::vector<Eigen::Vector3d> colors_;
};

}  // namespace core
}  // namespace act_color
