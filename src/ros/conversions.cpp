#include "act_color/ros/conversions.hpp"

#include <boost/make_shared.hpp>
#include <cmath>
#include <sstream>

namespace act_color {
namespace ros_conversions {
namespace {

core::ColorSpace colorSpace(const act_color::ColorLut& msg) {
  return msg.color_space == act_color::ColorLut::COLOR_SPACE_YUV ? core::ColorSpace::kYuv : core::ColorSpace::kRgb;
}

}  // namespace

std::string imageLayoutProblem(const sensor_msgs::Image& image, size_t bytes_per_pixel) {
  const uint64_t min_step = static_cast<uint64_t>(bytes_per_pixel) * image.width;
  const uint64_t min_size = static_cast<uint64_t>(image.step) * image.height;
  const bool empty = image.width == 0 || image.height == 0;
  // Checked for every image (twice in the segmentation: on arrival and when classified): no
  // stream is built for a good one.
  if (!empty && image.step >= min_step && image.data.size() >= min_size) return "";
  std::ostringstream s;
  if (empty) {
    s << "empty image (" << image.width << "x" << image.height << ")";
  } else if (image.step < min_step) {
    s << "step " << image.step << " is less than width " << image.width << " * " << bytes_per_pixel
      << " bytes per pixel (" << image.encoding << ") = " << min_step;
  } else if (image.data.size() < min_size) {
    s << "data has " << image.data.size() << " bytes, less than step " << image.step << " * height " << image.height
      << " = " << min_size;
  }
  return s.str();
}

std::string imageMessageProblem(const sensor_msgs::Image& image) {
  core::PixelFormat format;
  if (!core::pixelFormatFromEncoding(image.encoding, &format)) {
    return "unsupported encoding '" + image.encoding + "' (expected rgb8, bgr8 or yuv422)";
  }
  const std::string problem = imageLayoutProblem(image, core::bytesPerPixel(format));
  if (problem.empty() && format == core::PixelFormat::kUyvy && image.width % 2 != 0) {
    return "yuv422 image with an odd width " + std::to_string(image.width);
  }
  return problem;
}

bool imageView(const sensor_msgs::Image& image, core::ImageView* view, std::string* error) {
  *error = imageMessageProblem(image);
  if (!error->empty()) return false;
  core::PixelFormat format;
  core::pixelFormatFromEncoding(image.encoding, &format);
  *view = core::ImageView(image.data.data(), static_cast<int>(image.width), static_cast<int>(image.height), image.step,
                          format);
  return true;
}

act_color::ColorLutPtr toMsg(const core::ActTrainer& trainer, const std_msgs::Header& header) {
  auto msg = boost::make_shared<act_color::ColorLut>();
  const core::ColorLut& lut = trainer.lut();
  msg->header = header;
  msg->color_space = lut.colorSpace() == core::ColorSpace::kYuv ? act_color::ColorLut::COLOR_SPACE_YUV
                                                                : act_color::ColorLut::COLOR_SPACE_RGB;
  msg->bits_per_channel = static_cast<uint8_t>(lut.bitsPerChannel());
  msg->revision = trainer.revision();
  msg->table = lut.table();
  const auto counts = lut.cellCounts();
  for (int k = 1; k < core::kNumClasses; ++k) {
    const core::ClassCluster& cluster = trainer.clusters()[k];
    act_color::ClassCluster c;
    c.class_id = static_cast<uint8_t>(k);
    for (int i = 0; i < 3; ++i) c.mean[i] = static_cast<float>(cluster.mean()[i]);
    c.sigma = static_cast<float>(cluster.sigma());
    c.samples = cluster.lastSampleCount();
    c.lut_cells = counts[k];
    msg->clusters.push_back(c);
  }
  return msg;
}

bool fromMsg(const act_color::ColorLut& msg, core::ColorLut* lut, std::string* error) {
  if (msg.bits_per_channel < 1 || msg.bits_per_channel > 8) {
    *error = "bits_per_channel must be in [1, 8]";
    return false;
  }
  if (msg.color_space != act_color::ColorLut::COLOR_SPACE_RGB &&
      msg.color_space != act_color::ColorLut::COLOR_SPACE_YUV) {
    *error = "unknown color_space " + std::to_string(msg.color_space);
    return false;
  }
  if (msg.header.stamp.nsec >= 1000000000u) {
    *error = "stamp has " + std::to_string(msg.header.stamp.nsec) + " nanoseconds (at most 999999999)";
    return false;
  }
  *error = core::ActTrainer::revisionProblem(msg.revision);
  if (!error->empty()) return false;
  core::ColorLut out(msg.bits_per_channel, colorSpace(msg));
  if (msg.table.size() != out.size()) {
    *error = "table has " + std::to_string(msg.table.size()) + " cells, expected " + std::to_string(out.size());
    return false;
  }
  for (size_t i = 0; i < msg.table.size(); ++i) {
    if (msg.table[i] >= core::kNumClasses) {
      *error = "cell " + std::to_string(i) + " has class id " + std::to_string(msg.table[i]) + " (classes are 0-" +
               std::to_string(core::kNumClasses - 1) + ")";
      return false;
    }
  }
  out.assign(msg.table);
  *lut = std::move(out);
  return true;
}

bool fromMsg(const act_color::ColorLut& msg, core::ColorLut* lut, std::vector<core::ActTrainer::SavedCluster>* clusters,
             std::string* error) {
  if (!fromMsg(msg, lut, error)) return false;
  clusters->clear();
  for (const act_color::ClassCluster& c : msg.clusters) {
    core::ActTrainer::SavedCluster saved;
    saved.class_id = c.class_id;
    saved.mean = Eigen::Vector3d(c.mean[0], c.mean[1], c.mean[2]);
    saved.sigma = c.sigma;
    clusters->push_back(saved);
  }
  *error = core::ActTrainer::clustersProblem(*clusters);
  return error->empty();
}

bool pose2D(const geometry_msgs::Pose& pose, core::Pose2D* out, std::string* error) {
  const auto& p = pose.position;
  const auto& q = pose.orientation;
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(q.x) || !std::isfinite(q.y) ||
      !std::isfinite(q.z) || !std::isfinite(q.w)) {
    *error = "pose has NaN or infinite values";
    return false;
  }
  if (std::abs(p.z) > kMaxHeightM) {
    std::ostringstream s;
    s << "pose is " << p.z << " m above the floor, a robot's base_link is not";
    *error = s.str();
    return false;
  }
  const double norm = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (std::abs(norm - 1.0) > kMaxQuaternionNormError) {
    std::ostringstream s;
    s << "pose orientation is not a unit quaternion (norm " << norm << ")";
    *error = s.str();
    return false;
  }
  const double x = q.x / norm, y = q.y / norm, z = q.z / norm, w = q.w / norm;
  // A robot on the floor: its z axis stays within a few degrees of the vertical (the cosine of
  // the tilt is the z-z entry of the rotation matrix).
  const double cos_tilt = 1.0 - 2.0 * (x * x + y * y);
  if (cos_tilt < std::cos(kMaxTiltRad)) {
    std::ostringstream s;
    s << "pose is tilted by " << std::acos(std::max(-1.0, std::min(1.0, cos_tilt))) * 180.0 / M_PI
      << " degrees (roll/pitch), a robot on the floor is not";
    *error = s.str();
    return false;
  }
  out->x_m = p.x;
  out->y_m = p.y;
  out->theta_rad = std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
  return true;
}

sensor_msgs::ImagePtr newLabelsMsg(const sensor_msgs::Image& image, cv::Mat* labels) {
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->header = image.header;
  msg->height = image.height;
  msg->width = image.width;
  msg->encoding = "mono8";
  msg->is_bigendian = 0;
  msg->step = image.width;
  msg->data.assign(static_cast<size_t>(image.width) * image.height, core::kUnknown);
  *labels = cv::Mat(static_cast<int>(image.height), static_cast<int>(image.width), CV_8UC1, msg->data.data());
  return msg;
}

core::LutView lutView(const act_color::ColorLut& msg) {
  core::LutView view;
  view.table = msg.table.data();
  view.size = msg.table.size();
  view.bits = msg.bits_per_channel;
  view.space = colorSpace(msg);
  return view;
}

sensor_msgs::ImagePtr labelsToMsg(const cv::Mat& labels, const std_msgs::Header& header) {
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->header = header;
  msg->height = static_cast<uint32_t>(labels.rows);
  msg->width = static_cast<uint32_t>(labels.cols);
  msg->encoding = "mono8";
  msg->is_bigendian = 0;
  msg->step = static_cast<uint32_t>(labels.cols);
  msg->data.resize(static_cast<size_t>(labels.rows) * labels.cols);
  for (int v = 0; v < labels.rows; ++v) {
    std::copy(labels.ptr<uint8_t>(v), labels.ptr<uint8_t>(v) + labels.cols,
              msg->data.begin() + static_cast<size_t>(v) * labels.cols);
  }
  return msg;
}

}  // namespace ros_conversions
}  // namespace act_color
