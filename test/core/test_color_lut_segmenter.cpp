#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <type_traits>

#include "act_color/core/color_lut.hpp"
#include "act_color/core/image_view.hpp"
#include "act_color/core/segmenter.hpp"
#include "test_util.hpp"

using namespace act_color::core;

TEST(ColorLut, CellIndexUsesTheHighBitsOfEachChannel) {
  ColorLut lut(6);
  EXPECT_EQ(lut.size(), 262144u);  // 64^3
  EXPECT_EQ(lut.index(255, 0, 0), 63u << 12);
  EXPECT_EQ(lut.index(0, 255, 0), 63u << 6);
  EXPECT_EQ(lut.index(0, 0, 255), 63u);
  EXPECT_EQ(lut.index(4, 8, 12), (1u << 12) | (2u << 6) | 3u);
  EXPECT_EQ(lut.index(7, 11, 15), lut.index(4, 8, 12));  // same cell
  lut.set(lut.index(100, 150, 30), kGreen);
  EXPECT_EQ(lut.classOf(101, 149, 31), kGreen);
  EXPECT_EQ(lut.classOf(104, 150, 30), kUnknown);
  EXPECT_EQ(lut.cellCounts()[kGreen], 1u);
  ColorLut small(4, ColorSpace::kYuv);
  EXPECT_EQ(small.size(), 4096u);
  EXPECT_EQ(small.colorSpace(), ColorSpace::kYuv);
  EXPECT_THROW(ColorLut(0), std::invalid_argument);
  EXPECT_THROW(ColorLut(9), std::invalid_argument);
  EXPECT_THROW(lut.assign(std::vector<uint8_t>(10)), std::invalid_argument);
}

TEST(Segmenter, ClassifiesEveryFormatAlike) {
  ColorLut rgb_lut(6, ColorSpace::kRgb);
  rgb_lut.set(rgb_lut.index(40, 140, 50), kGreen);
  rgb_lut.set(rgb_lut.index(230, 230, 230), kWhite);
  rgb_lut.set(rgb_lut.index(230, 200, 30), kYellow);
  cv::Mat rgb(4, 6, CV_8UC3, cv::Scalar(40, 140, 50));
  rgb.at<cv::Vec3b>(1, 2) = cv::Vec3b(230, 230, 230);
  rgb.at<cv::Vec3b>(2, 3) = cv::Vec3b(230, 200, 30);
  rgb.at<cv::Vec3b>(3, 5) = cv::Vec3b(0, 0, 0);
  cv::Mat labels;
  const Segmenter segmenter;
  segmenter.classify(rgb_lut, ImageView::fromMat(rgb, PixelFormat::kRgb8), labels);
  ASSERT_EQ(labels.type(), CV_8UC1);
  EXPECT_EQ(labels.at<uint8_t>(0, 0), kGreen);
  EXPECT_EQ(labels.at<uint8_t>(1, 2), kWhite);
  EXPECT_EQ(labels.at<uint8_t>(2, 3), kYellow);
  EXPECT_EQ(labels.at<uint8_t>(3, 5), kUnknown);
  // bgr8: the same colors with swapped channels give the same labels.
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  cv::Mat labels_bgr;
  segmenter.classify(rgb_lut, ImageView::fromMat(bgr, PixelFormat::kBgr8), labels_bgr);
  EXPECT_EQ(cv::countNonZero(labels != labels_bgr), 0);
  // yuv422 with a YUV table built from the image's own colors.
  const cv::Mat uyvy = rgbToUyvy(rgb);
  const ImageView yuv_view = ImageView::fromMat(uyvy, PixelFormat::kUyvy);
  ColorLut yuv_lut(6, ColorSpace::kYuv);
  uint8_t c[3];
  yuv_view.color(2, 1, c);
  yuv_lut.set(yuv_lut.index(c[0], c[1], c[2]), kWhite);
  cv::Mat labels_yuv;
  segmenter.classify(yuv_lut, yuv_view, labels_yuv);
  EXPECT_EQ(labels_yuv.at<uint8_t>(1, 2), kWhite);
  EXPECT_EQ(labels_yuv.at<uint8_t>(0, 0), kUnknown);
  // A table of the wrong color space is refused.
  EXPECT_THROW(segmenter.classify(yuv_lut, ImageView::fromMat(rgb, PixelFormat::kRgb8), labels), std::invalid_argument);
}

TEST(Segmenter, OnlyPixelsInsideTheMirrorAreClassified) {
  const auto cal = act_color::test::defaultCalibration();
  ColorLut lut(6);
  lut.set(lut.index(40, 140, 50), kGreen);
  cv::Mat img(580, 580, CV_8UC3, cv::Scalar(40, 140, 50));
  cv::Mat labels;
  Segmenter(cal.camera).classify(lut, ImageView::fromMat(img, PixelFormat::kRgb8), labels);
  EXPECT_EQ(labels.at<uint8_t>(0, 0), kUnknown);
  EXPECT_EQ(labels.at<uint8_t>(290, 290 + 280), kGreen);
  EXPECT_EQ(labels.at<uint8_t>(290, 290 + 290), kUnknown);
  const int inside = cv::countNonZero(labels == kGreen);
  EXPECT_NEAR(inside, M_PI * 286 * 286, 0.01 * M_PI * 286 * 286);
  cv::Mat wrong(100, 100, CV_8UC3);
  EXPECT_THROW(Segmenter(cal.camera).classify(lut, ImageView::fromMat(wrong, PixelFormat::kRgb8), labels),
               std::invalid_argument);
}

TEST(Segmenter, TheOwnRobotsPixelsOfTheSelfMaskAreBlack) {
  auto cal = act_color::test::defaultCalibration();
  // A strut from the chassis to the rim along +u, 3 px wide, in the camera's self mask.
  cal.camera.self_mask.assign(580 * 580, 0);
  for (int u = 340; u < 570; ++u) {
    for (int v = 289; v <= 291; ++v) cal.camera.self_mask[static_cast<size_t>(v) * 580 + u] = 1;
  }
  ColorLut lut(6);
  lut.set(lut.index(40, 140, 50), kGreen);
  cv::Mat img(580, 580, CV_8UC3, cv::Scalar(40, 140, 50));
  img(cv::Rect(340, 289, 230, 3)).setTo(cv::Scalar(170, 170, 180));  // a bright metal the table does not know
  cv::Mat labels;
  Segmenter(cal.camera).classify(lut, ImageView::fromMat(img, PixelFormat::kRgb8), labels);
  EXPECT_EQ(cv::countNonZero(labels == kBlack), 230 * 3);
  EXPECT_EQ(labels.at<uint8_t>(290, 400), kBlack);
  EXPECT_EQ(labels.at<uint8_t>(288, 400), kGreen);  // beside it: the table's class
  EXPECT_EQ(labels.at<uint8_t>(292, 400), kGreen);
  // Without the mask the strut's color is no class.
  cal.camera.self_mask.clear();
  Segmenter(cal.camera).classify(lut, ImageView::fromMat(img, PixelFormat::kRgb8), labels);
  EXPECT_EQ(labels.at<uint8_t>(290, 400), kUnknown);
  EXPECT_EQ(cv::countNonZero(labels == kBlack), 0);
}

TEST(Segmenter, ColorizeUsesThePalette) {
  cv::Mat labels = (cv::Mat_<uint8_t>(1, 3) << kGreen, kBlue, kNotImaged);
  cv::Mat rgb;
  colorizeLabels(labels, rgb);
  const auto& palette = classPalette();
  EXPECT_EQ(rgb.at<cv::Vec3b>(0, 0), cv::Vec3b(palette[kGreen][0], palette[kGreen][1], palette[kGreen][2]));
  EXPECT_EQ(rgb.at<cv::Vec3b>(0, 1), cv::Vec3b(palette[kBlue][0], palette[kBlue][1], palette[kBlue][2]));
}

TEST(ImageView, YuvConversionOfGrey) {
  cv::Mat grey(2, 2, CV_8UC3, cv::Scalar(100, 100, 100));
  const cv::Mat uyvy = rgbToUyvy(grey);
  uint8_t c[3];
  ImageView::fromMat(uyvy, PixelFormat::kUyvy).color(1, 1, c);
  EXPECT_EQ(c[0], 100);
  EXPECT_EQ(c[1], 128);
  EXPECT_EQ(c[2], 128);
  PixelFormat f;
  EXPECT_TRUE(pixelFormatFromEncoding("yuv422", &f));
  EXPECT_EQ(f, PixelFormat::kUyvy);
  EXPECT_FALSE(pixelFormatFromEncoding("mono8", &f));
  EXPECT_THROW(ImageView::fromMat(grey, PixelFormat::kUyvy), std::invalid_argument);
}

// withPixels picks the accessor that fits the layout; each reads what ImageView::color reads, at
// every pixel (packed rgb8 and bgr8 at 3 x the index, padded rows and UYVY through the view).
TEST(ImageView, WithPixelsReadsAsColorInEveryLayout) {
  cv::Mat rgb(5, 8, CV_8UC3);
  cv::randu(rgb, cv::Scalar::all(0), cv::Scalar::all(256));
  cv::Mat padded_storage(5, 10, CV_8UC3, cv::Scalar::all(0));
  rgb.copyTo(padded_storage(cv::Rect(0, 0, 8, 5)));
  const cv::Mat padded = padded_storage(cv::Rect(0, 0, 8, 5));  // rows of 30 bytes, 24 used
  const cv::Mat uyvy = rgbToUyvy(rgb);
  struct Case {
    ImageView view;
    bool packed;
  };
  const Case cases[] = {{ImageView::fromMat(rgb, PixelFormat::kRgb8), true},
                        {ImageView::fromMat(rgb, PixelFormat::kBgr8), true},
                        {ImageView::fromMat(padded, PixelFormat::kRgb8), false},
                        {ImageView::fromMat(uyvy, PixelFormat::kUyvy), false}};
  for (const Case& c : cases) {
    int calls = 0;
    withPixels(c.view, [&](const auto& pixels) {
      ++calls;
      using Pixels = std::decay_t<decltype(pixels)>;
      const bool packed = !std::is_same_v<Pixels, AnyPixels>;
      EXPECT_EQ(packed, c.packed) << encodingName(c.view.format);
      for (int v = 0; v < c.view.height; ++v) {
        for (int u = 0; u < c.view.width; ++u) {
          const uint32_t index = static_cast<uint32_t>(v * c.view.width + u);
          uint8_t expected[3], got[3];
          c.view.color(u, v, expected);
          pixels.color(index, u, v, got);
          for (int ch = 0; ch < 3; ++ch) ASSERT_EQ(got[ch], expected[ch]) << u << "," << v << " channel " << ch;
          EXPECT_EQ(pixels.address(index, u, v), c.view.data + v * c.view.step + u * bytesPerPixel(c.view.format))
              << encodingName(c.view.format);
        }
      }
    });
    EXPECT_EQ(calls, 1);
  }
}
