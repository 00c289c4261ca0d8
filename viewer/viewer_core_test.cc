// Unit tests of the viewer's core without GL or LCM: colours, the view camera and its
// framing, the scene bookkeeping, occupancy and image decoding, snapshot files, options.

#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>
#include <sstream>

#include "common/config/options_yaml.h"
#include "common/util/atomic_file.h"
#include "viewer/colors.h"
#include "viewer/image_decode.h"
#include "viewer/occupancy_decode.h"
#include "viewer/scene.h"
#include "viewer/snapshot_files.h"
#include "viewer/view_camera.h"

namespace mbslam {
namespace viewer {
namespace {

std::string TempDir(const std::string& name) {
  const std::string dir =
      std::string(::testing::TempDir()) + "viewer_core_" + name + "_" + std::to_string(::getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

CameraPoseSample Pose(int64_t utime, const Eigen::Vector3d& position,
                      TrackingState state = TrackingState::kOk, bool metric = false) {
  CameraPoseSample p;
  p.utime = utime;
  p.world_from_cam.position = position;
  p.tracking_state = state;
  p.metric = metric;
  return p;
}

// ---------------------------------------------------------------- colours

TEST(Colors, ObjectPaletteIsDistinctAndAvoidsTheLegendsFixedColours) {
  std::set<std::tuple<int, int, int>> seen;
  for (int id = 1; id <= kObjectPaletteSize; ++id) {
    const Rgb c = ObjectColor(id);
    seen.insert({c.r, c.g, c.b});
    EXPECT_FALSE(c == kCameraTrajectoryColor);
    EXPECT_FALSE(c == kParticleColor);
  }
  EXPECT_EQ(static_cast<int>(seen.size()), kObjectPaletteSize);
  EXPECT_TRUE(ObjectColor(1) == ObjectColor(1 + kObjectPaletteSize));
  // Odd ids (0, negative) still give a colour.
  (void)ObjectColor(0);
  (void)ObjectColor(-5);
}

TEST(Colors, HeightScaleIsClampedAndChangesWithHeight) {
  EXPECT_TRUE(HeightColor(-1.0) == HeightColor(0.0));
  EXPECT_TRUE(HeightColor(2.0) == HeightColor(1.0));
  EXPECT_TRUE(HeightColor(std::nan("")) == HeightColor(0.0));
  EXPECT_FALSE(HeightColor(0.0) == HeightColor(1.0));
  EXPECT_FALSE(HeightColor(0.0) == HeightColor(0.5));
}

// ---------------------------------------------------------------- view camera

TEST(ViewCamera, LookAtProjectsTheTargetToTheCentreAndUpToTheTop) {
  ViewCamera cam =
      LookAt(Eigen::Vector3d(0, -2, -10), Eigen::Vector3d(0, -2, 0), Eigen::Vector3d(0, -1, 0));
  cam.width = 640;
  cam.height = 480;
  cam.near = 0.1;
  cam.far = 100;
  Eigen::Vector2d px;
  ASSERT_TRUE(cam.Project(Eigen::Vector3d(0, -2, 0), &px));
  EXPECT_NEAR(px.x(), 319.5, 1e-9);
  EXPECT_NEAR(px.y(), 239.5, 1e-9);
  // A point above the target (smaller y) is higher in the image (smaller v).
  ASSERT_TRUE(cam.Project(Eigen::Vector3d(0, -3, 0), &px));
  EXPECT_LT(px.y(), 239.5);
  // With y down, looking along +z: +x is to the right.
  ASSERT_TRUE(cam.Project(Eigen::Vector3d(1, -2, 0), &px));
  EXPECT_GT(px.x(), 319.5);
  // Behind the eye: not projected.
  EXPECT_FALSE(cam.Project(Eigen::Vector3d(0, -2, -20), &px));
}

TEST(ViewCamera, PerspectiveProjectionMatchesThePinholeModel) {
  ViewCamera cam;  // identity: the view frame is the world frame
  cam.width = 800;
  cam.height = 600;
  cam.fov_y_rad = 2.0 * std::atan(0.5);  // f = height
  cam.near = 0.1;
  cam.far = 100;
  Eigen::Vector2d px;
  ASSERT_TRUE(cam.Project(Eigen::Vector3d(0.1, 0.05, 1.0), &px));
  EXPECT_NEAR(px.x(), 399.5 + 600.0 * 0.1, 1e-6);
  EXPECT_NEAR(px.y(), 299.5 + 600.0 * 0.05, 1e-6);
  EXPECT_NEAR(cam.UnitsPerPixel(Eigen::Vector3d(0, 0, 6)), 6.0 / 600.0, 1e-12);
}

TEST(ViewCamera, UpIsTheGroundNormalElseMinusY) {
  MapData map;
  EXPECT_TRUE(UpDirection(map).isApprox(Eigen::Vector3d(0, -1, 0)));
  map.ground_plane = Eigen::Vector4d(0, 0, 2, 1);  // normalised on use
  EXPECT_TRUE(UpDirection(map).isApprox(Eigen::Vector3d(0, 0, 1)));
  map.ground_plane = Eigen::Vector4d(0, 0, 0, 0);  // unknown
  EXPECT_TRUE(UpDirection(map).isApprox(Eigen::Vector3d(0, -1, 0)));
}

SceneState StreetScene() {
  SceneState scene;
  MapData map;
  map.utime = 1;
  for (int i = 0; i < 200; ++i) {
    map.points.emplace_back(static_cast<float>((i % 20) - 10), 1.5f, static_cast<float>(i / 2));
  }
  map.points.emplace_back(1e6f, 1e6f, 1e6f);  // an outlier the framing ignores
  map.ground_plane = Eigen::Vector4d(0, -1, 0, 1.5);
  scene.SetMap(map);
  for (int k = 0; k <= 10; ++k) scene.AddCameraPose(Pose(k + 1, Eigen::Vector3d(0, 0, k)));
  return scene;
}

TEST(ViewCamera, SceneBoundsIgnoreOutliers) {
  const SceneState scene = StreetScene();
  const Eigen::AlignedBox3d box = SceneBounds(scene, 2.0);
  EXPECT_LT(box.max().maxCoeff(), 200.0);
  EXPECT_LE(box.min().z(), 0.0);  // the trajectory starts at z = 0
  EXPECT_GE(box.max().z(), 90.0);
}

TEST(ViewCamera, FollowModeIsBehindAndAboveTheCameraAndSeesIt) {
  const SceneState scene = StreetScene();
  View3dOptions options;
  options.camera_mode = "follow";
  const ViewCamera cam = ComputeViewCamera(options, scene);
  const Eigen::Vector3d eye = cam.eye_in_world();
  const Eigen::Vector3d current(0, 0, 10);
  EXPECT_LT(eye.z(), current.z());  // behind (the camera looks along +z)
  EXPECT_LT(eye.y(), current.y());  // above (up is -y)
  Eigen::Vector2d px;
  ASSERT_TRUE(cam.Project(current, &px));
  EXPECT_GT(px.y(), cam.height / 2.0);  // the camera is in the lower half, the scene ahead
  ASSERT_TRUE(cam.Project(Eigen::Vector3d(0, 1.5, 20), &px));  // the road ahead is in view
}

TEST(ViewCamera, FollowDistancesFromOptions) {
  const SceneState scene = StreetScene();
  View3dOptions options;
  options.follow_distance = 3.0;
  options.follow_height = 2.0;
  const ViewCamera cam = ComputeViewCamera(options, scene);
  EXPECT_TRUE(cam.eye_in_world().isApprox(Eigen::Vector3d(0, -2, 7), 1e-9));
}

TEST(ViewCamera, TopDownLooksDownAndFramesTheScene) {
  const SceneState scene = StreetScene();
  View3dOptions options;
  options.camera_mode = "top_down";
  const ViewCamera cam = ComputeViewCamera(options, scene);
  EXPECT_TRUE(cam.orthographic);
  // The viewing direction (view z in the world) is -up = +y.
  const Eigen::Vector3d view_z = cam.view_from_world.rotation().transpose().col(2);
  EXPECT_NEAR(view_z.y(), 1.0, 1e-9);
  Eigen::Vector2d start, end;
  ASSERT_TRUE(cam.Project(Eigen::Vector3d(0, 0, 0), &start));
  ASSERT_TRUE(cam.Project(Eigen::Vector3d(0, 0, 10), &end));
  EXPECT_LT(end.y(), start.y());  // forward (world z) points up the picture
  for (const auto& corner : {Eigen::Vector3d(-9, 1.5, 1), Eigen::Vector3d(9, 1.5, 98)}) {
    EXPECT_TRUE(cam.Project(corner, &start)) << corner.transpose();
  }
}

TEST(ViewCamera, FixedModeUsesTheConfiguredPose) {
  const SceneState scene = StreetScene();
  View3dOptions options;
  options.camera_mode = "fixed";
  options.fixed_position = {5, -5, -5};
  options.fixed_look_at = {0, 0, 10};
  const ViewCamera cam = ComputeViewCamera(options, scene);
  EXPECT_TRUE(cam.eye_in_world().isApprox(Eigen::Vector3d(5, -5, -5), 1e-9));
  Eigen::Vector2d px;
  ASSERT_TRUE(cam.Project(Eigen::Vector3d(0, 0, 10), &px));
  EXPECT_NEAR(px.x(), (cam.width - 1) / 2.0, 1e-6);
  EXPECT_NEAR(px.y(), (cam.height - 1) / 2.0, 1e-6);
}

TEST(ViewCamera, EmptySceneStillGivesAUsableCamera) {
  const SceneState scene;
  for (const char* mode : {"follow", "top_down", "fixed"}) {
    View3dOptions options;
    options.camera_mode = mode;
    const ViewCamera cam = ComputeViewCamera(options, scene);
    EXPECT_TRUE(cam.ClipFromWorld().allFinite()) << mode;
    EXPECT_GT(cam.far, cam.near) << mode;
  }
}

// ---------------------------------------------------------------- scene state

TEST(SceneState, TrajectoryHasOnlyEstimatedPoses) {
  SceneState scene;
  scene.AddCameraPose(Pose(1, Eigen::Vector3d::Zero(), TrackingState::kNotInitialized));
  scene.AddCameraPose(Pose(2, Eigen::Vector3d::Zero(), TrackingState::kInitializing));
  scene.AddCameraPose(Pose(3, Eigen::Vector3d(0, 0, 1)));
  scene.AddCameraPose(Pose(4, Eigen::Vector3d(0, 0, 1), TrackingState::kLost));
  scene.AddCameraPose(Pose(5, Eigen::Vector3d(0, 0, 2), TrackingState::kRelocalized));
  EXPECT_EQ(scene.camera_trajectory().size(), 2u);
  ASSERT_TRUE(scene.current_camera().has_value());
  EXPECT_EQ(scene.current_camera()->utime, 5);
  EXPECT_EQ(scene.latest_utime(), 5);
}

TEST(SceneState, TrajectoriesRestartWhenTheScaleBecomesMetric) {
  SceneState scene;
  scene.AddCameraPose(Pose(1, Eigen::Vector3d(0, 0, 1)));
  scene.AddCameraPose(Pose(2, Eigen::Vector3d(0, 0, 2)));
  ObjectsData objects;
  objects.utime = 2;
  ObjectData o;
  o.id = 3;
  o.state = ObjectState::kTracked;
  objects.objects.push_back(o);
  scene.SetObjects(objects);
  EXPECT_EQ(scene.object_trajectories().size(), 1u);
  scene.AddCameraPose(Pose(3, Eigen::Vector3d(0, 0, 30), TrackingState::kOk, /*metric=*/true));
  EXPECT_EQ(scene.camera_trajectory().size(), 1u);
  EXPECT_TRUE(scene.object_trajectories().empty());
  EXPECT_TRUE(scene.metric());
}

TEST(SceneState, TimeGoingBackwardsStartsAgain) {
  SceneState scene;
  scene.AddCameraPose(Pose(100, Eigen::Vector3d(0, 0, 1)));
  scene.AddCameraPose(Pose(200, Eigen::Vector3d(0, 0, 2)));
  scene.AddCameraPose(Pose(50, Eigen::Vector3d(0, 0, 0)));
  EXPECT_EQ(scene.resets(), 1);
  EXPECT_EQ(scene.camera_trajectory().size(), 1u);
  EXPECT_EQ(scene.latest_utime(), 50);
}

TEST(SceneState, LongTrajectoriesAreThinnedNotCut) {
  SceneOptions options;
  options.max_trajectory_points = 100;
  SceneState scene(options);
  for (int k = 0; k < 1000; ++k) scene.AddCameraPose(Pose(k + 1, Eigen::Vector3d(0, 0, k)));
  EXPECT_LE(scene.camera_trajectory().size(), 100u);
  EXPECT_EQ(scene.camera_trajectory().front().utime, 1);
  EXPECT_EQ(scene.camera_trajectory().back().utime, 1000);
}

TEST(SceneState, ObjectTrajectoriesSkipDetectedObjectsAndAreBounded) {
  SceneOptions options;
  options.max_object_trajectories = 2;
  SceneState scene(options);
  for (int k = 1; k <= 4; ++k) {
    ObjectsData objects;
    objects.utime = k;
    ObjectData tracked;
    tracked.id = k;  // a new object every time
    tracked.state = ObjectState::kTracked;
    ObjectData detected;
    detected.id = 100;
    detected.state = ObjectState::kDetected;
    objects.objects = {tracked, detected};
    scene.SetObjects(objects);
  }
  EXPECT_EQ(scene.object_trajectories().size(), 2u);
  EXPECT_EQ(scene.object_trajectories().count(100), 0u);
  EXPECT_EQ(scene.object_trajectories().count(4), 1u);  // the newest are kept
  EXPECT_EQ(scene.object_trajectories().count(1), 0u);
}

TEST(SceneState, ImageFrameMatchesTracksAndImagesByUtime) {
  SceneState scene;
  EXPECT_EQ(scene.LatestImageFrame().tracks, nullptr);
  EXPECT_EQ(scene.LatestImageFrame().image, nullptr);
  for (int64_t t : {10, 20, 30}) {
    EncodedImage image;
    image.utime = t;
    scene.AddImage(image);
    ObjectsData objects;
    objects.utime = t;
    scene.SetObjects(objects);
  }
  // Only images: the newest.
  EXPECT_EQ(scene.LatestImageFrame().image->utime, 30);
  TracksData tracks;
  tracks.utime = 20;
  scene.AddTracks(tracks);
  ImageFrame frame = scene.LatestImageFrame();
  ASSERT_NE(frame.tracks, nullptr);
  ASSERT_NE(frame.image, nullptr);
  EXPECT_EQ(frame.image->utime, 20);
  ASSERT_NE(frame.objects, nullptr);
  EXPECT_EQ(frame.objects->utime, 20);
  // Tracks newer than every image: drawn alone.
  tracks.utime = 40;
  scene.AddTracks(tracks);
  frame = scene.LatestImageFrame();
  ASSERT_NE(frame.tracks, nullptr);
  EXPECT_EQ(frame.tracks->utime, 20);  // the newest tracks that have their image win
  EncodedImage image;
  image.utime = 40;
  scene.AddImage(image);
  frame = scene.LatestImageFrame();
  EXPECT_EQ(frame.tracks->utime, 40);
  EXPECT_EQ(frame.image->utime, 40);
  EXPECT_EQ(frame.objects->utime, 30);  // none at 40: the newest
}

TEST(SceneState, ImageBufferIsBounded) {
  SceneOptions options;
  options.image_buffer = 2;
  SceneState scene(options);
  for (int64_t t = 1; t <= 5; ++t) {
    EncodedImage image;
    image.utime = t;
    scene.AddImage(image);
  }
  TracksData tracks;
  tracks.utime = 3;  // its image has left the buffer
  scene.AddTracks(tracks);
  const ImageFrame frame = scene.LatestImageFrame();
  EXPECT_EQ(frame.tracks, nullptr);
  ASSERT_NE(frame.image, nullptr);
  EXPECT_EQ(frame.image->utime, 5);
}

// ---------------------------------------------------------------- occupancy

std::vector<uint8_t> TreeBytes(const octomap::OcTree& tree) {
  std::ostringstream out;
  octomap::OcTree copy(tree);
  copy.writeBinary(out);
  const std::string s = out.str();
  return std::vector<uint8_t>(s.begin(), s.end());
}

TEST(Occupancy, DecodesTheOccupiedLeavesOfAWrittenTree) {
  octomap::OcTree tree(0.25);
  tree.updateNode(octomap::point3d(1.1f, 2.1f, 3.1f), true);
  tree.updateNode(octomap::point3d(-1.1f, 0.1f, 0.1f), true);
  tree.updateNode(octomap::point3d(5.1f, 5.1f, 5.1f), false);  // free
  const std::vector<uint8_t> bytes = TreeBytes(tree);
  OccupancyData out;
  const Status s = DecodeOccupancy(bytes.data(), bytes.size(), 100, &out);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_DOUBLE_EQ(out.resolution, 0.25);
  ASSERT_EQ(out.voxels.size(), 2u);
  EXPECT_EQ(out.num_occupied, 2);
  bool found = false;
  for (const Voxel& v : out.voxels) {
    EXPECT_FLOAT_EQ(v.size, 0.25f);
    found = found || (v.center - Eigen::Vector3f(1.125f, 2.125f, 3.125f)).norm() < 1e-4;
  }
  EXPECT_TRUE(found);
  // The cap on drawn voxels keeps the count.
  ASSERT_TRUE(DecodeOccupancy(bytes.data(), bytes.size(), 1, &out).ok());
  EXPECT_EQ(out.voxels.size(), 1u);
  EXPECT_EQ(out.num_occupied, 2);
}

TEST(Occupancy, RejectsGarbageTruncationAndCraftedDepth) {
  OccupancyData out;
  const std::string junk = "not a tree at all";
  EXPECT_FALSE(
      DecodeOccupancy(reinterpret_cast<const uint8_t*>(junk.data()), junk.size(), 10, &out).ok());
  EXPECT_TRUE(DecodeOccupancy(nullptr, 0, 10, &out).ok());  // empty = no tree yet
  EXPECT_TRUE(out.voxels.empty());

  octomap::OcTree tree(0.5);
  for (int i = 0; i < 50; ++i) tree.updateNode(octomap::point3d(0.5f * i, 0.1f, 0.3f * i), true);
  std::vector<uint8_t> bytes = TreeBytes(tree);
  std::vector<uint8_t> truncated(bytes.begin(),
                                 bytes.begin() + static_cast<long>(bytes.size() - 7));
  EXPECT_FALSE(DecodeOccupancy(truncated.data(), truncated.size(), 1000, &out).ok());

  // A header followed by "every child is an inner node" forever: readBinaryData would
  // recurse once per two bytes; the check refuses it before.
  std::string crafted = "# Octomap OcTree binary file\nid OcTree\nsize 1\nres 0.1\ndata\n";
  crafted += std::string(200000, '\xff');
  EXPECT_FALSE(
      DecodeOccupancy(reinterpret_cast<const uint8_t*>(crafted.data()), crafted.size(), 1000, &out)
          .ok());
  std::string other_type = "# Octomap OcTree binary file\nid ColorOcTree\nsize 1\nres 0.1\ndata\n";
  other_type += std::string(2, '\0');
  EXPECT_FALSE(DecodeOccupancy(reinterpret_cast<const uint8_t*>(other_type.data()),
                               other_type.size(), 1000, &out)
                   .ok());
}

TEST(SceneState, OccupancyIsDecodedLazilyAndErrorsAreCounted) {
  SceneState scene;
  EncodedOccupancy bad;
  bad.utime = 5;
  bad.data = {1, 2, 3};
  scene.SetOccupancy(bad);
  EXPECT_TRUE(scene.occupancy().voxels.empty());
  EXPECT_EQ(scene.occupancy_decode_errors(), 1);
  (void)scene.occupancy();  // not decoded again
  EXPECT_EQ(scene.occupancy_decode_errors(), 1);
  octomap::OcTree tree(1.0);
  tree.updateNode(octomap::point3d(0.5f, 0.5f, 0.5f), true);
  EncodedOccupancy good;
  good.utime = 6;
  good.data = TreeBytes(tree);
  scene.SetOccupancy(good);
  EXPECT_EQ(scene.occupancy().voxels.size(), 1u);
  EXPECT_EQ(scene.occupancy().utime, 6);
}

// ---------------------------------------------------------------- images

cv::Mat TestPattern(int w, int h) {
  cv::Mat bgr(h, w, CV_8UC3);
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      bgr.at<cv::Vec3b>(r, c) = cv::Vec3b(static_cast<uint8_t>(c * 4), static_cast<uint8_t>(r * 4),
                                          static_cast<uint8_t>((r + c) * 2));
    }
  }
  return bgr;
}

TEST(ImageDecode, RawEncodingsWithStride) {
  const cv::Mat bgr = TestPattern(40, 30);
  EncodedImage image;
  image.width = 40;
  image.height = 30;
  image.encoding = ImageEncoding::kBgr8;
  image.row_stride = 40 * 3 + 8;  // padded rows
  image.data.assign(static_cast<size_t>(image.row_stride) * 30, 0);
  for (int r = 0; r < 30; ++r) {
    std::memcpy(&image.data[static_cast<size_t>(r) * image.row_stride], bgr.ptr(r), 40 * 3);
  }
  cv::Mat out;
  ASSERT_TRUE(DecodeToBgr(image, 8192, &out).ok());
  EXPECT_EQ(cv::norm(out, bgr, cv::NORM_INF), 0.0);

  // RGB: channels swapped on the way.
  image.encoding = ImageEncoding::kRgb8;
  ASSERT_TRUE(DecodeToBgr(image, 8192, &out).ok());
  EXPECT_EQ(out.at<cv::Vec3b>(5, 7)[0], bgr.at<cv::Vec3b>(5, 7)[2]);

  // Gray.
  EncodedImage gray;
  gray.width = 4;
  gray.height = 2;
  gray.row_stride = 4;
  gray.encoding = ImageEncoding::kGray8;
  gray.data = {0, 50, 100, 150, 200, 250, 10, 20};
  ASSERT_TRUE(DecodeToBgr(gray, 8192, &out).ok());
  EXPECT_EQ(out.type(), CV_8UC3);
  EXPECT_EQ(out.at<cv::Vec3b>(1, 1), cv::Vec3b(250, 250, 250));
}

TEST(ImageDecode, RejectsSizesThatDoNotFit) {
  EncodedImage image;
  image.width = 100;
  image.height = 100;
  image.row_stride = 100;
  image.encoding = ImageEncoding::kGray8;
  image.data.assign(100 * 99, 0);  // one row short
  cv::Mat out;
  EXPECT_FALSE(DecodeToBgr(image, 8192, &out).ok());
  image.data.assign(100 * 100, 0);
  image.row_stride = 50;  // shorter than a row
  EXPECT_FALSE(DecodeToBgr(image, 8192, &out).ok());
  image.row_stride = 100;
  EXPECT_TRUE(DecodeToBgr(image, 8192, &out).ok());
  EXPECT_FALSE(DecodeToBgr(image, 64, &out).ok());  // larger than allowed
  image.width = -3;
  EXPECT_FALSE(DecodeToBgr(image, 8192, &out).ok());
}

TEST(ImageDecode, CompressedImagesAndTheirAnnouncedSize) {
  const cv::Mat bgr = TestPattern(48, 32);
  for (const char* ext : {".png", ".jpg"}) {
    std::vector<uint8_t> bytes;
    ASSERT_TRUE(cv::imencode(ext, bgr, bytes));
    EncodedImage image;
    image.width = 48;
    image.height = 32;
    image.encoding = std::string(ext) == ".png" ? ImageEncoding::kPng : ImageEncoding::kJpeg;
    image.data = bytes;
    cv::Mat out;
    const Status s = DecodeToBgr(image, 8192, &out);
    ASSERT_TRUE(s.ok()) << ext << ": " << s.message();
    EXPECT_EQ(out.size(), bgr.size());
    // The file is larger than the limit: refused from its header.
    EXPECT_FALSE(DecodeToBgr(image, 40, &out).ok()) << ext;
    // The message announces another size.
    image.width = 64;
    EXPECT_FALSE(DecodeToBgr(image, 8192, &out).ok()) << ext;
    // Not an image file.
    image.width = 48;
    image.data.assign(100, 7);
    EXPECT_FALSE(DecodeToBgr(image, 8192, &out).ok()) << ext;
  }
}

// ---------------------------------------------------------------- snapshot files

TEST(SnapshotFiles, NamesSortByTime) {
  EXPECT_EQ(SnapshotPath("out/", "view3d", 1234), "out/view3d_0000000000001234.png");
  EXPECT_EQ(SnapshotPath("out/run_", "image", -1), "out/run_image_latest.png");
  EXPECT_LT(SnapshotPath("", "v", 999), SnapshotPath("", "v", 1000));
}

TEST(SnapshotFiles, RequestPrefixesStayInTheOutputDirectoryUnlessAllowed) {
  std::string prefix;
  ASSERT_TRUE(ResolveRequestPrefix("out", "", false, &prefix).ok());
  EXPECT_EQ(prefix, "out/");
  ASSERT_TRUE(ResolveRequestPrefix("out", "req/snap_", false, &prefix).ok());
  EXPECT_EQ(prefix, "out/req/snap_");
  EXPECT_FALSE(ResolveRequestPrefix("out", "/etc/x", false, &prefix).ok());
  EXPECT_EQ(prefix, "out/");
  EXPECT_FALSE(ResolveRequestPrefix("out", "a/../../x", false, &prefix).ok());
  ASSERT_TRUE(ResolveRequestPrefix("out", "/tmp/x_", true, &prefix).ok());
  EXPECT_EQ(prefix, "/tmp/x_");
}

TEST(SnapshotFiles, PngIsWrittenAtomicallyAndDecodes) {
  const std::string dir = TempDir("png");
  const std::string path = dir + "/sub/dir/a.png";
  const cv::Mat bgr = TestPattern(20, 10);
  ASSERT_TRUE(WritePngAtomically(path, bgr).ok());
  const cv::Mat back = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(back.empty());
  EXPECT_EQ(cv::norm(back, bgr, cv::NORM_INF), 0.0);
  // Nothing else (no temporary file) is left next to it.
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir + "/sub/dir")) {
    (void)e;
    ++files;
  }
  EXPECT_EQ(files, 1);
  EXPECT_FALSE(WritePngAtomically(path, cv::Mat()).ok());
  std::filesystem::remove_all(dir);
}

// ---------------------------------------------------------------- options

TEST(RenderOptions, DefaultsPassAndBadValuesFail) {
  EXPECT_TRUE(SceneOptions().Check());
  EXPECT_TRUE(View3dOptions().Check());
  EXPECT_TRUE(ImageViewOptions().Check());
  View3dOptions v;
  v.camera_mode = "orbit";
  EXPECT_FALSE(v.Check());
  v = View3dOptions();
  v.antialias_samples = 3;
  EXPECT_FALSE(v.Check());
  v = View3dOptions();
  v.fixed_look_at = v.fixed_position;
  EXPECT_FALSE(v.Check());
  ImageViewOptions i;
  i.epipolar_lines = "all";
  EXPECT_FALSE(i.Check());
  View3dOptions from_yaml;
  EXPECT_TRUE(
      LoadOptionsFromYamlText("camera_mode: top_down\nheight_range: [0, 3]\n", "", &from_yaml)
          .ok());
  EXPECT_EQ(from_yaml.camera_mode, "top_down");
  EXPECT_DOUBLE_EQ(from_yaml.height_range[1], 3.0);
  EXPECT_FALSE(LoadOptionsFromYamlText("camera_mod: top_down\n", "", &from_yaml).ok());
}

}  // namespace
}  // namespace viewer
}  // namespace mbslam
