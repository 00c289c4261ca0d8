// The image view: colours of the track classes, hull shading, epipolar lines, labels.

#include "viewer/image_view.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <limits>

#include "viewer/colors.h"

namespace mbslam {
namespace viewer {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

cv::Vec3b Bgr(const Rgb& c) { return cv::Vec3b(c.b, c.g, c.r); }

TrackFeature Track(float u, float v, int body_id, bool occluded = false) {
  TrackFeature t;
  t.u = u;
  t.v = v;
  t.prev_u = kNaN;
  t.prev_v = kNaN;
  t.body_id = body_id;
  t.occluded = occluded;
  t.epipolar_px = 0.5f;
  return t;
}

class ImageViewTest : public ::testing::Test {
 protected:
  void SetUp() override {
    options_.dim_image = false;
    options_.show_legend = false;  // pixels of the output are pixels of the image
    options_.min_width = 0;
    image_ = cv::Mat(240, 320, CV_8UC3, cv::Scalar(128, 128, 128));
    tracks_.utime = 5;
    tracks_.width = 320;
    tracks_.height = 240;
    tracks_.tracks = {Track(40, 40, 0), Track(80, 40, 3), Track(120, 40, -1),
                      Track(160, 40, 0, /*occluded=*/true)};
    ImageHull hull;
    hull.body_id = 3;
    hull.points = {Eigen::Vector2f(200, 150), Eigen::Vector2f(300, 150), Eigen::Vector2f(300, 220),
                   Eigen::Vector2f(200, 220)};
    tracks_.hulls = {hull};
    ObjectData object;
    object.id = 3;
    object.state = ObjectState::kTracked;
    object.linear_velocity = Eigen::Vector3d(3, 4, 0);  // 5 m/s
    objects_.metric = true;
    objects_.objects = {object};
  }
  cv::Mat Render(int* image_top = nullptr) {
    ImageViewInput input;
    input.image = image_;
    input.tracks = &tracks_;
    input.objects = &objects_;
    input.utime = 5;
    cv::Mat out;
    RenderImageView(options_, input, &out, image_top);
    return out;
  }

  ImageViewOptions options_;
  cv::Mat image_;
  TracksData tracks_;
  ObjectsData objects_;
};

TEST_F(ImageViewTest, TrackClassesHaveTheirColours) {
  const cv::Mat out = Render();
  ASSERT_EQ(out.size(), image_.size());
  EXPECT_EQ(out.at<cv::Vec3b>(40, 40), Bgr(kStaticTrackColor));
  EXPECT_EQ(out.at<cv::Vec3b>(40, 80), Bgr(kMovingTrackColor));
  EXPECT_EQ(out.at<cv::Vec3b>(40, 120), Bgr(kUnassignedTrackColor));
  // Occluded: a blue ring, the image inside.
  EXPECT_EQ(out.at<cv::Vec3b>(40, 160), cv::Vec3b(128, 128, 128));
  EXPECT_EQ(out.at<cv::Vec3b>(40, 164), Bgr(kOccludedTrackColor));
  EXPECT_EQ(ClassifyTrack(Track(0, 0, 0, true)), TrackClass::kOccluded);
  EXPECT_EQ(ClassifyTrack(Track(0, 0, 7)), TrackClass::kMoving);
}

TEST_F(ImageViewTest, HullIsShadedInTheObjectsColour) {
  const cv::Mat out = Render();
  const cv::Vec3b inside = out.at<cv::Vec3b>(200, 230);
  const Rgb c = ObjectColor(3);
  const double a = options_.hull_alpha;
  EXPECT_NEAR(inside[0], a * c.b + (1 - a) * 128, 2);
  EXPECT_NEAR(inside[1], a * c.g + (1 - a) * 128, 2);
  EXPECT_NEAR(inside[2], a * c.r + (1 - a) * 128, 2);
  EXPECT_EQ(out.at<cv::Vec3b>(100, 100), cv::Vec3b(128, 128, 128));  // outside
}

TEST_F(ImageViewTest, LabelWithIdAndSpeedAboveTheHull) {
  options_.show_labels = false;
  const cv::Mat without = Render();
  options_.show_labels = true;
  const cv::Mat with = Render();
  cv::Mat diff;
  cv::absdiff(with, without, diff);
  cv::Mat gray;
  cv::cvtColor(diff, gray, cv::COLOR_BGR2GRAY);
  // Text appears just above the hull's top edge (v = 150), at its left (u = 200).
  EXPECT_GT(cv::countNonZero(gray(cv::Rect(195, 125, 110, 25))), 30);
  EXPECT_EQ(cv::countNonZero(gray(cv::Rect(0, 160, 190, 80))), 0);
}

TEST_F(ImageViewTest, FlowIsDrawnFromThePreviousPosition) {
  tracks_.tracks = {Track(100, 100, 0)};
  tracks_.tracks[0].prev_u = 60;
  tracks_.tracks[0].prev_v = 100;
  const cv::Mat out = Render();
  const cv::Vec3b flow = out.at<cv::Vec3b>(100, 75);  // anti-aliased: nearly the colour
  EXPECT_GT(flow[1], 180);
  EXPECT_LT(flow[0], 40);
  EXPECT_LT(flow[2], 40);
  options_.show_flow = false;
  EXPECT_EQ(Render().at<cv::Vec3b>(100, 75), cv::Vec3b(128, 128, 128));
}

TEST_F(ImageViewTest, EpipolarLinesThroughDegenerateMovingFeatures) {
  tracks_.tracks = {Track(200, 50, 3), Track(60, 200, 3)};
  tracks_.tracks[0].epipolar_px = 0.5f;   // on its epipolar line: degenerate
  tracks_.tracks[1].epipolar_px = 12.0f;  // clearly off it
  tracks_.hulls.clear();
  tracks_.epipole = Eigen::Vector3d(2 * 100, 2 * 50, 2);  // (100, 50), homogeneous
  auto magenta_on_segment = [](const cv::Mat& out, Eigen::Vector2d a, Eigen::Vector2d b) {
    int hits = 0;
    for (double s = 0.2; s <= 0.8; s += 0.1) {
      const Eigen::Vector2d p = a + s * (b - a);
      const cv::Vec3b px = out.at<cv::Vec3b>(static_cast<int>(std::lround(p.y())),
                                             static_cast<int>(std::lround(p.x())));
      hits += px[1] < 100 && px[0] > 150 && px[2] > 150 ? 1 : 0;
    }
    return hits;
  };
  options_.epipolar_lines = "degenerate";
  cv::Mat out = Render();
  // Horizontal ray from the epipole (100, 50) through (200, 50) to the border.
  EXPECT_GE(magenta_on_segment(out, {210, 50}, {318, 50}), 6);
  EXPECT_EQ(magenta_on_segment(out, {20, 50}, {90, 50}), 0);    // not behind the epipole
  EXPECT_EQ(magenta_on_segment(out, {100, 50}, {60, 200}), 0);  // not through the other one
  options_.epipolar_lines = "moving";
  out = Render();
  EXPECT_GE(magenta_on_segment(out, {95, 70}, {65, 180}), 5);
  options_.epipolar_lines = "off";
  out = Render();
  EXPECT_EQ(magenta_on_segment(out, {210, 50}, {318, 50}), 0);
}

TEST_F(ImageViewTest, BadValuesAreSkippedAndMissingPartsStillRender) {
  tracks_.tracks.push_back(Track(kNaN, 3, 0));
  tracks_.tracks.push_back(Track(1e9f, -1e9f, 3));
  tracks_.epipole = Eigen::Vector3d(std::nan(""), 0, 1);
  ImageHull degenerate;
  degenerate.body_id = 4;
  degenerate.points = {Eigen::Vector2f(1, 1)};
  tracks_.hulls.push_back(degenerate);
  cv::Mat out = Render();
  EXPECT_EQ(out.size(), image_.size());

  // No image: a grey canvas of the tracks' size (enlarged to min_width).
  options_.show_legend = true;
  options_.min_width = 640;
  ImageViewInput input;
  input.tracks = &tracks_;
  RenderImageView(options_, input, &out);
  EXPECT_EQ(out.cols, 640);
  EXPECT_GT(out.rows, 480);  // header and legend bands
  // Nothing at all.
  RenderImageView(options_, ImageViewInput(), &out);
  EXPECT_FALSE(out.empty());
}

// Regression (issue 9, found profiling fuzz_viewer_lcm): tracks or an image 1 px wide
// and 8192 px tall were enlarged to min_width, a 640 x 5 M pixel canvas (~10 GB).
TEST_F(ImageViewTest, EnlargingNeverExceedsTheMaximumViewSize) {
  options_.show_legend = true;
  options_.min_width = 640;
  TracksData thin;
  thin.width = 1;
  thin.height = 8192;
  ImageViewInput input;
  input.tracks = &thin;
  cv::Mat out;
  RenderImageView(options_, input, &out);
  EXPECT_LE(out.cols, kMaxViewDimension);
  EXPECT_LE(out.rows, kMaxViewDimension + 600);  // header and legend bands
  input = ImageViewInput();
  input.image = cv::Mat(4000, 2, CV_8UC3, cv::Scalar(1, 2, 3));
  options_.scale = 8.0;
  RenderImageView(options_, input, &out);
  EXPECT_LE(out.cols, kMaxViewDimension);
  EXPECT_LE(out.rows, kMaxViewDimension + 600);
}

// Regression (fuzz_viewer_lcm, issue 9): a hull with finite but huge vertices put
// its label at static_cast<int>(-1.7e30), undefined behaviour (UBSan).
TEST_F(ImageViewTest, HullWithHugeVerticesIsLabelledInsideTheImage) {
  ImageHull far;
  far.body_id = 3;
  far.points = {Eigen::Vector2f(-1.7e30f, 1e30f), Eigen::Vector2f(1e30f, -1e30f),
                Eigen::Vector2f(0.f, 3e30f)};
  tracks_.hulls.push_back(far);
  options_.show_labels = true;
  const cv::Mat out = Render();
  EXPECT_EQ(out.size(), image_.size());
}

TEST_F(ImageViewTest, LegendBandsAndScalingMoveTheImage) {
  options_.show_legend = true;
  options_.scale = 2.0;
  int top = -1;
  const cv::Mat out = Render(&top);
  EXPECT_GT(top, 0);
  EXPECT_EQ(out.cols, 640);
  EXPECT_GT(out.rows, 480 + top);
  // The static track at (40, 40) of the 320x240 image is at (80.5, 80.5) + band.
  EXPECT_EQ(out.at<cv::Vec3b>(80 + top, 80), Bgr(kStaticTrackColor));
}

TEST(MakeImageViewInput, DecodesTheMatchingImage) {
  SceneState scene;
  EncodedImage image;
  image.utime = 7;
  image.width = 8;
  image.height = 4;
  image.row_stride = 8;
  image.encoding = ImageEncoding::kGray8;
  image.data.assign(32, 200);
  scene.AddImage(image);
  TracksData tracks;
  tracks.utime = 7;
  tracks.width = 8;
  tracks.height = 4;
  scene.AddTracks(tracks);
  ImageViewInput input;
  ASSERT_TRUE(MakeImageViewInput(scene, 8192, &input).ok());
  EXPECT_EQ(input.image.size(), cv::Size(8, 4));
  ASSERT_NE(input.tracks, nullptr);
  EXPECT_EQ(input.utime, 7);

  image.utime = 9;
  image.data.resize(5);  // does not fit 8x4
  scene.AddImage(image);
  tracks.utime = 9;
  scene.AddTracks(tracks);
  EXPECT_FALSE(MakeImageViewInput(scene, 8192, &input).ok());
  EXPECT_TRUE(input.image.empty());
  EXPECT_EQ(input.tracks->utime, 9);
}

}  // namespace
}  // namespace viewer
}  // namespace mbslam
