// The 3D view rendered offscreen (OSMesa) from scenes built in the test: pixels where
// points, trajectories, particles, voxels and volumes project have the legend's colours;
// elsewhere the background stays.

#include "viewer/view3d_renderer.h"

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cmath>
#include <sstream>

#include "viewer/colors.h"

namespace mbslam {
namespace viewer {
namespace {

constexpr int kWidth = 640, kHeight = 480;

View3dOptions PlainOptions() {
  View3dOptions o;
  o.width = kWidth;
  o.height = kHeight;
  o.antialias_samples = 1;
  o.show_legend = false;
  o.show_ground_grid = false;
  o.point_size_px = 9.0;
  o.trajectory_width_px = 5.0;
  o.height_range = {0.0, 4.0};
  return o;
}

// Looking along +z from 10 units behind the origin, up = -y.
ViewCamera FrontCamera() {
  ViewCamera cam =
      LookAt(Eigen::Vector3d(0, 0, -10), Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, -1, 0));
  cam.width = kWidth;
  cam.height = kHeight;
  cam.fov_y_rad = 60.0 * 3.14159265358979 / 180.0;
  cam.near = 0.1;
  cam.far = 100.0;
  return cam;
}

cv::Vec3b At(const cv::Mat& img, const ViewCamera& cam, const Eigen::Vector3d& p) {
  Eigen::Vector2d px;
  EXPECT_TRUE(cam.Project(p, &px)) << p.transpose();
  return img.at<cv::Vec3b>(static_cast<int>(std::lround(px.y())),
                           static_cast<int>(std::lround(px.x())));
}

cv::Vec3b Bgr(const Rgb& c) { return cv::Vec3b(c.b, c.g, c.r); }

bool Near(const cv::Vec3b& a, const cv::Vec3b& b, int tolerance) {
  for (int i = 0; i < 3; ++i) {
    if (std::abs(static_cast<int>(a[i]) - static_cast<int>(b[i])) > tolerance) return false;
  }
  return true;
}

int NonBackground(const cv::Mat& img) {
  cv::Mat mask;
  cv::inRange(img, cv::Scalar(255, 255, 255), cv::Scalar(255, 255, 255), mask);
  return static_cast<int>(img.total()) - cv::countNonZero(mask);
}

class View3dRendererTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Status s;
    renderer_ = View3dRenderer::Create(PlainOptions(), &s);
    ASSERT_TRUE(renderer_) << s.message();
  }
  std::unique_ptr<View3dRenderer> renderer_;
};

TEST_F(View3dRendererTest, EmptySceneIsBackground) {
  SceneState scene;
  cv::Mat img;
  ASSERT_TRUE(renderer_->Render(scene, FrontCamera(), &img).ok());
  ASSERT_EQ(img.size(), cv::Size(kWidth, kHeight));
  ASSERT_EQ(img.type(), CV_8UC3);
  EXPECT_EQ(NonBackground(img), 0);
  EXPECT_FALSE(renderer_->gl_description().empty());
}

TEST_F(View3dRendererTest, StaticPointsAreColouredByHeightAboveTheGround) {
  SceneState scene;
  MapData map;
  map.utime = 1;
  map.ground_plane = Eigen::Vector4d(0, -1, 0, 2.0);  // ground at y = 2, up = -y
  map.points = {Eigen::Vector3f(-3, 2, 0), Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(3, -2, 0)};
  scene.SetMap(map);
  const ViewCamera cam = FrontCamera();
  cv::Mat img;
  ASSERT_TRUE(renderer_->Render(scene, cam, &img).ok());
  // Heights 0, 2 and 4 on the scale [0, 4].
  EXPECT_EQ(At(img, cam, {-3, 2, 0}), Bgr(HeightColor(0.0)));
  EXPECT_EQ(At(img, cam, {0, 0, 0}), Bgr(HeightColor(0.5)));
  EXPECT_EQ(At(img, cam, {3, -2, 0}), Bgr(HeightColor(1.0)));
  // Only the three points (9 px discs) are drawn.
  EXPECT_GT(NonBackground(img), 3 * 40);
  EXPECT_LT(NonBackground(img), 3 * 100);

  // Image colours instead of heights.
  View3dOptions rgb = PlainOptions();
  rgb.static_point_color = "rgb";
  Status s;
  auto renderer = View3dRenderer::Create(rgb, &s);
  ASSERT_TRUE(renderer) << s.message();
  map.colors = {{{10, 20, 30}}, {{40, 50, 60}}, {{70, 80, 90}}};
  scene.SetMap(map);
  ASSERT_TRUE(renderer->Render(scene, cam, &img).ok());
  EXPECT_EQ(At(img, cam, {0, 0, 0}), cv::Vec3b(60, 50, 40));
}

TEST_F(View3dRendererTest, CameraTrajectoryIsRedAndObjectsHaveTheirColours) {
  SceneState scene;
  for (int k = 0; k <= 4; ++k) {
    CameraPoseSample pose;
    pose.utime = 1 + k;
    pose.world_from_cam.position = Eigen::Vector3d(-4 + k, 3, 0);
    pose.tracking_state = TrackingState::kOk;
    scene.AddCameraPose(pose);
  }
  for (int k = 0; k <= 4; ++k) {
    ObjectsData objects;
    objects.utime = 10 + k;
    ObjectData o;
    o.id = 2;
    o.state = ObjectState::kTracked;
    o.position = Eigen::Vector3d(-4 + k, -3, 0);
    if (k == 4) {
      o.points = {Eigen::Vector3f(-2, 0, 0)};
      o.particles = {Eigen::Vector3f(2, 0, 0)};
    }
    objects.objects = {o};
    scene.SetObjects(objects);
  }
  const ViewCamera cam = FrontCamera();
  cv::Mat img;
  ASSERT_TRUE(renderer_->Render(scene, cam, &img).ok());
  EXPECT_EQ(At(img, cam, {-2.5, 3, 0}), Bgr(kCameraTrajectoryColor));
  EXPECT_EQ(At(img, cam, {-1.5, -3, 0}), Bgr(ObjectColor(2)));
  EXPECT_EQ(At(img, cam, {-2, 0, 0}), Bgr(ObjectColor(2)));        // object point
  EXPECT_EQ(At(img, cam, {2, 0, 0}), Bgr(kParticleColor));         // particle
  EXPECT_EQ(At(img, cam, {0, 1.5, 0}), cv::Vec3b(255, 255, 255));  // between them
}

TEST_F(View3dRendererTest, VolumesAreShadedSemiTransparentInTheObjectsColour) {
  SceneState scene;
  ObjectsData objects;
  objects.utime = 1;
  ObjectData o;
  o.id = 1;
  o.state = ObjectState::kTracked;
  OrientedBox now;
  now.center = Eigen::Vector3d(-2, 0, 0);
  now.half_extent = Eigen::Vector3d(1, 1, 1);
  OrientedBox later = now;
  later.center = Eigen::Vector3d(2.5, 0, 0);
  later.horizon_us = 1000000;
  later.world_from_box = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()));
  o.volumes = {now, later};
  objects.objects = {o};
  scene.SetObjects(objects);
  const ViewCamera cam = FrontCamera();
  cv::Mat img;
  ASSERT_TRUE(renderer_->Render(scene, cam, &img).ok());
  const Rgb c = ObjectColor(1);                   // orange: much more red than blue
  const cv::Vec3b a = At(img, cam, {-2, 0, -1});  // the near face of the current box
  EXPECT_FALSE(Near(a, cv::Vec3b(255, 255, 255), 10));
  EXPECT_GT(a[2], a[0] + 40);
  // Semi-transparent: lighter than the opaque colour.
  EXPECT_GT(a[0], c.b + 40);
  // The later box fades: closer to the background than the current one.
  const cv::Vec3b b = At(img, cam, {2.5, 0, 0});
  EXPECT_FALSE(Near(b, cv::Vec3b(255, 255, 255), 5));
  EXPECT_GT(b[0], a[0]);
}

TEST_F(View3dRendererTest, OccupiedVoxelsAreDrawn) {
  octomap::OcTree tree(1.0);
  tree.updateNode(octomap::point3d(0.5f, 0.5f, 0.5f), true);
  std::ostringstream out;
  tree.writeBinary(out);
  const std::string bytes = out.str();
  SceneState scene;
  EncodedOccupancy occupancy;
  occupancy.utime = 1;
  occupancy.data.assign(bytes.begin(), bytes.end());
  scene.SetOccupancy(occupancy);
  const ViewCamera cam = FrontCamera();
  cv::Mat img;
  ASSERT_TRUE(renderer_->Render(scene, cam, &img).ok());
  EXPECT_EQ(scene.occupancy().voxels.size(), 1u);
  EXPECT_FALSE(Near(At(img, cam, {0.5, 0.5, 0.0}), cv::Vec3b(255, 255, 255), 5));
  EXPECT_EQ(At(img, cam, {3, 3, 0}), cv::Vec3b(255, 255, 255));
}

TEST_F(View3dRendererTest, FollowViewShowsTheCurrentCameraAndKeyframes) {
  SceneState scene;
  MapData map;
  map.utime = 1;
  for (int i = 0; i < 400; ++i) {
    map.points.emplace_back(static_cast<float>(i % 20 - 10), 1.5f, static_cast<float>(i / 20 * 2));
  }
  KeyframeData kf;
  kf.world_from_cam.position = Eigen::Vector3d(0, 0, 2);
  map.keyframes = {kf};
  scene.SetMap(map);
  for (int k = 0; k <= 5; ++k) {
    CameraPoseSample pose;
    pose.utime = 2 + k;
    pose.world_from_cam.position = Eigen::Vector3d(0, 0, k);
    pose.tracking_state = TrackingState::kOk;
    scene.AddCameraPose(pose);
  }
  View3dOptions options = PlainOptions();
  options.camera_mode = "follow";
  const ViewCamera cam = ComputeViewCamera(options, scene);
  cv::Mat img;
  ASSERT_TRUE(renderer_->Render(scene, &img).ok());
  // Red (trajectory / current camera) right around the current camera's projection.
  Eigen::Vector2d px;
  ASSERT_TRUE(cam.Project(Eigen::Vector3d(0, 0, 5), &px));
  const cv::Rect around(static_cast<int>(px.x()) - 10, static_cast<int>(px.y()) - 10, 21, 21);
  cv::Mat red;
  cv::inRange(img(around & cv::Rect(0, 0, kWidth, kHeight)), cv::Scalar(0, 0, 150),
              cv::Scalar(80, 80, 255), red);
  EXPECT_GT(cv::countNonZero(red), 5);
  // Keyframe frustum lines near the keyframe.
  ASSERT_TRUE(cam.Project(Eigen::Vector3d(0, 0, 2), &px));
  cv::Mat frustum;
  const cv::Rect kf_box(static_cast<int>(px.x()) - 25, static_cast<int>(px.y()) - 25, 51, 51);
  cv::inRange(img(kf_box & cv::Rect(0, 0, kWidth, kHeight)),
              Bgr(kKeyframeColor) - cv::Vec3b(30, 30, 30),
              Bgr(kKeyframeColor) + cv::Vec3b(30, 30, 30), frustum);
  EXPECT_GT(cv::countNonZero(frustum), 5);
}

TEST_F(View3dRendererTest, LegendAndLabelsAreDrawnOnTop) {
  View3dOptions options = PlainOptions();
  options.show_legend = true;
  Status s;
  auto renderer = View3dRenderer::Create(options, &s);
  ASSERT_TRUE(renderer) << s.message();
  SceneState scene;
  cv::Mat img;
  ASSERT_TRUE(renderer->Render(scene, FrontCamera(), &img).ok());
  cv::Mat header = img(cv::Rect(0, 0, kWidth, 12));
  EXPECT_GT(NonBackground(header), kWidth * 10);  // the dark header band
  EXPECT_GT(NonBackground(img(cv::Rect(0, kHeight / 2, kWidth / 2, kHeight / 2))), 500);
}

TEST(View3dRenderer, RejectsBadOptionsAndCameraSizes) {
  View3dOptions options = PlainOptions();
  options.antialias_samples = 3;
  Status s;
  EXPECT_FALSE(View3dRenderer::Create(options, &s));
  EXPECT_FALSE(s.ok());
  auto renderer = View3dRenderer::Create(PlainOptions(), &s);
  ASSERT_TRUE(renderer);
  ViewCamera cam = FrontCamera();
  cam.width = 100;
  cv::Mat img;
  EXPECT_FALSE(renderer->Render(SceneState(), cam, &img).ok());
}

// Render time at 1280x720 with the default options on a scene of 20k points, a 2k-voxel
// occupancy and a few objects: printed for the report, loosely bounded.
TEST(View3dRenderer, RenderTimeAt1280x720) {
  View3dOptions options;  // defaults: 1280x720, 4x multisampling, legend
  SceneState scene;
  MapData map;
  map.utime = 1;
  map.ground_plane = Eigen::Vector4d(0, -1, 0, 1.5);
  octomap::OcTree tree(0.5);
  for (int i = 0; i < 20000; ++i) {
    const float x = static_cast<float>((i * 7919) % 2000) / 100.0f - 10.0f;
    const float z = static_cast<float>((i * 104729) % 4000) / 100.0f;
    const float y =
        1.5f - static_cast<float>((i * 31) % 300) / 100.0f * (std::abs(x) > 8 ? 1.0f : 0.0f);
    map.points.emplace_back(x, y, z);
    if (i % 10 == 0) tree.updateNode(octomap::point3d(x, y, z), true);
  }
  scene.SetMap(map);
  std::ostringstream out;
  tree.writeBinary(out);
  EncodedOccupancy occupancy;
  occupancy.utime = 1;
  const std::string bytes = out.str();
  occupancy.data.assign(bytes.begin(), bytes.end());
  scene.SetOccupancy(occupancy);
  for (int k = 0; k < 100; ++k) {
    CameraPoseSample pose;
    pose.utime = 2 + k;
    pose.world_from_cam.position = Eigen::Vector3d(0, 0, 0.2 * k);
    pose.tracking_state = TrackingState::kOk;
    scene.AddCameraPose(pose);
  }
  ObjectsData objects;
  objects.utime = 200;
  for (int id = 1; id <= 5; ++id) {
    ObjectData o;
    o.id = id;
    o.state = ObjectState::kTracked;
    o.position = Eigen::Vector3d(-6 + 2 * id, 0.5, 15);
    for (int p = 0; p < 100; ++p) o.particles.emplace_back(o.position.cast<float>());
    for (int h = 0; h <= 4; ++h) {
      OrientedBox b;
      b.center = o.position + Eigen::Vector3d(0.3 * h, 0, 0);
      b.half_extent = Eigen::Vector3d(0.5, 1, 0.5);
      b.horizon_us = h * 250000;
      o.volumes.push_back(b);
    }
    objects.objects.push_back(o);
  }
  scene.SetObjects(objects);
  Status s;
  const auto t0 = std::chrono::steady_clock::now();
  auto renderer = View3dRenderer::Create(options, &s);
  ASSERT_TRUE(renderer) << s.message();
  const auto t1 = std::chrono::steady_clock::now();
  cv::Mat img;
  ASSERT_TRUE(renderer->Render(scene, &img).ok());
  const auto t2 = std::chrono::steady_clock::now();
  const int kSteady = 5;
  for (int i = 0; i < kSteady; ++i) ASSERT_TRUE(renderer->Render(scene, &img).ok());
  const auto t3 = std::chrono::steady_clock::now();
  auto ms = [](auto d) { return std::chrono::duration<double, std::milli>(d).count(); };
  const double create_ms = ms(t1 - t0), first_ms = ms(t2 - t1), steady_ms = ms(t3 - t2) / kSteady;
  std::printf("3D view 1280x720: context %.1f ms, first frame %.1f ms, steady %.1f ms/frame\n",
              create_ms, first_ms, steady_ms);
  RecordProperty("create_ms", std::to_string(create_ms));
  RecordProperty("first_frame_ms", std::to_string(first_ms));
  RecordProperty("steady_ms", std::to_string(steady_ms));
  EXPECT_EQ(img.size(), cv::Size(1280, 720));
  EXPECT_GT(NonBackground(img), 10000);
  EXPECT_LT(steady_ms, 2000.0);
}

}  // namespace
}  // namespace viewer
}  // namespace mbslam
