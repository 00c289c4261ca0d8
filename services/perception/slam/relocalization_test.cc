// Relocalisation against a map loaded from a file (SlamOptions::relocalization): a
// textured, tilted plane seen from a first camera makes the map (ORB descriptors and
// patches at its corners, as keyframes describe their points); a second camera, turned
// and moved, is placed in it from its image alone. An unrelated image is not placed, and
// a loaded map the camera never comes back to is given up after reloc_loaded_max_frames.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <unordered_map>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "common/testing/temp_dir.h"
#include "services/perception/geometry/camera.h"
#include "services/perception/slam/slam_system.h"
#include "services/perception/tracking/orb_features.h"
#include "services/perception/tracking/patch_matcher.h"
#include "services/perception/tracking/test_images.h"

namespace mbslam {
namespace {

constexpr int kWidth = 640, kHeight = 480;
constexpr double kTexel = 0.005;  // plane texture resolution (m per texel)

CameraIntrinsics Intrinsics() {
  CameraIntrinsics K;
  K.width = kWidth;
  K.height = kHeight;
  K.fx = K.fy = 500.0;
  K.cx = 320.0;
  K.cy = 240.0;
  return K;
}

// The plane: origin O, texel axes e1, e2 (world), tilted 17 deg about x, 4 m ahead.
struct Plane {
  Eigen::Vector3d origin{-2.5, -2.0, 3.4};
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitX();
  Eigen::Vector3d e2 = Eigen::Vector3d(0.0, 1.0, 0.3).normalized();
  Eigen::Vector3d Normal() const { return e1.cross(e2).normalized(); }
};

cv::Mat Render(const cv::Mat& texture, const Plane& plane, const Rigid3d& cam_from_world) {
  const Eigen::Matrix3d R = cam_from_world.rotation.toRotationMatrix();
  Eigen::Matrix3d M;
  M.col(0) = R * plane.e1 * kTexel;
  M.col(1) = R * plane.e2 * kTexel;
  M.col(2) = R * plane.origin + cam_from_world.translation;
  const Eigen::Matrix3d H = Intrinsics().K() * M;
  cv::Mat Hcv(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) Hcv.at<double>(r, c) = H(r, c);
  }
  cv::Mat image;
  cv::warpPerspective(texture, image, Hcv, cv::Size(kWidth, kHeight), cv::INTER_LINEAR,
                      cv::BORDER_CONSTANT, cv::Scalar(128));
  return image;
}

// The map of camera A's view: its ORB corners back-projected onto the plane, described
// and given patches as the SLAM does at keyframes. Returns the file.
std::string MakeMap(const cv::Mat& image, const Plane& plane, const std::string& dir) {
  const CameraIntrinsics K = Intrinsics();
  std::vector<Eigen::Vector2f> corners;
  std::vector<OrbDescriptor> unused;
  DetectOrb(image, 800, 10, &corners, &unused);
  std::vector<OrbDescriptor> descriptors;
  std::vector<uint8_t> valid;
  DescribeOrbAt(image, corners, &descriptors, &valid);
  Map map;
  Keyframe k;
  k.fixed = true;
  const int64_t kid = map.AddKeyframe(k);  // camera A at the world origin
  const Eigen::Vector3d n = plane.Normal();
  for (size_t i = 0; i < corners.size(); ++i) {
    if (!valid[i]) continue;
    const Eigen::Vector2d xy = K.PixelToNormalized(corners[i].cast<double>());
    const Eigen::Vector3d ray = xy.homogeneous();
    MapPoint p;
    p.position = ray * (n.dot(plane.origin) / n.dot(ray));
    p.has_descriptor = true;
    p.descriptor = descriptors[i];
    ExtractPatch(image, corners[i], 11, &p.patch);
    const int64_t pid = map.AddPoint(p);
    map.AddObservation(pid, kid, xy);
  }
  const std::string path = dir + "/plane.map";
  EXPECT_TRUE(map.Save(path).ok());
  return path;
}

SlamFrame FrameOf(int64_t index, const cv::Mat& image, const CameraIntrinsics& K) {
  SlamFrame f;
  f.frame_index = index;
  f.utime = index * 33333;
  f.focal_px = K.fx;
  f.image = image;
  f.intrinsics = &K;
  return f;
}

// The scene of every test: the textured plane, and the map file of camera A's view.
struct PlaneMapFile {
  const cv::Mat texture = testing_images::Texture(1000, 800, 21);
  const Plane plane;
  const std::string dir;
  const std::string path;
  explicit PlaneMapFile(const std::string& name)
      : dir(testing_util::MakeTestTempDir(name)),
        path(MakeMap(Render(texture, plane, Rigid3d()), plane, dir)) {}
  SlamOptions Options() const {
    SlamOptions options;
    options.map_load_path = path;
    return options;
  }
};

TEST(SlamRelocalization, LoadedMapPlacesATurnedAndMovedCamera) {
  const PlaneMapFile scene("reloc");
  const SlamOptions options = scene.Options();
  SlamSystem slam(options);
  ASSERT_EQ(slam.state(), SlamState::kLost)
      << "a loaded map waits for the camera to relocalise in it";
  ASSERT_GT(slam.map().num_points(), 150u);
  const CameraIntrinsics K = Intrinsics();
  // Camera B: turned 8 deg about y and 4 deg about x, moved 0.4 m right, 0.1 m up, 0.3 m ahead.
  const Eigen::Quaterniond q =
      Eigen::Quaterniond(Eigen::AngleAxisd(8.0 * M_PI / 180.0, Eigen::Vector3d::UnitY())) *
      Eigen::AngleAxisd(4.0 * M_PI / 180.0, Eigen::Vector3d::UnitX());
  const Eigen::Vector3d centre(0.4, -0.1, 0.3);
  const Rigid3d cam_from_world(q.conjugate(), -(q.conjugate() * centre));
  const SlamPose pose =
      slam.TrackPose(FrameOf(0, Render(scene.texture, scene.plane, cam_from_world), K));
  ASSERT_TRUE(pose.valid);
  EXPECT_TRUE(pose.relocalized);
  EXPECT_TRUE(pose.placed_by_relocalization);
  EXPECT_TRUE(pose.relocalized_map);
  EXPECT_EQ(slam.state(), SlamState::kTracking);
  EXPECT_LT(TranslationDistance(pose.cam_from_world, cam_from_world), 0.02);
  EXPECT_LT(RotationDistance(pose.cam_from_world, cam_from_world) * 180.0 / M_PI, 0.3);
  EXPECT_GE(pose.num_inliers, options.reloc_min_inliers);
  EXPECT_GE(pose.refound.size(), static_cast<size_t>(options.reloc_min_inliers))
      << "matched points become tracks";
  EXPECT_EQ(slam.relocalizations(), 1);
  // The matched points lie where the true pose projects them.
  for (const auto& [pid, uv] : pose.refound) {
    const Eigen::Vector2d expected = K.Project(cam_from_world * slam.map().point(pid)->position);
    EXPECT_LT((uv.cast<double>() - expected).norm(), 3.0);
  }
}

TEST(SlamRelocalization, UnrelatedImagesAreNotPlacedAndTheLoadedMapIsGivenUp) {
  const PlaneMapFile scene("reloc_unrelated");
  SlamOptions options = scene.Options();
  options.reloc_loaded_max_frames = 4;
  SlamSystem slam(options);
  ASSERT_EQ(slam.state(), SlamState::kLost);
  const CameraIntrinsics K = Intrinsics();
  const cv::Mat other = testing_images::Texture(1000, 800, 22);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(slam.state(), SlamState::kLost) << "image " << i;
    EXPECT_GT(slam.map().num_points(), 0u);
    const SlamPose pose = slam.TrackPose(FrameOf(i, Render(other, scene.plane, Rigid3d()), K));
    EXPECT_FALSE(pose.valid) << "image " << i;
    EXPECT_FALSE(pose.relocalized);
  }
  // The fourth lost image gave the map up: a new one is to be made.
  EXPECT_NE(slam.state(), SlamState::kLost);
  EXPECT_EQ(slam.map().num_points(), 0u);
  EXPECT_EQ(slam.relocalizations(), 0);
}

TEST(SlamRelocalization, ZeroWaitsForEver) {
  const PlaneMapFile scene("reloc_forever");
  SlamOptions options = scene.Options();
  options.reloc_loaded_max_frames = 0;
  SlamSystem slam(options);
  const CameraIntrinsics K = Intrinsics();
  const cv::Mat other = Render(testing_images::Texture(1000, 800, 23), scene.plane, Rigid3d());
  for (int i = 0; i < 12; ++i) EXPECT_FALSE(slam.TrackPose(FrameOf(i, other, K)).valid);
  EXPECT_EQ(slam.state(), SlamState::kLost);
  EXPECT_GT(slam.map().num_points(), 150u);
  // ... until the camera comes back.
  const SlamPose pose =
      slam.TrackPose(FrameOf(12, Render(scene.texture, scene.plane, Rigid3d()), K));
  EXPECT_TRUE(pose.valid);
  EXPECT_TRUE(pose.placed_by_relocalization);
  EXPECT_LT(TranslationDistance(pose.cam_from_world, Rigid3d()), 0.02);
}

TEST(SlamRelocalization, OffOrWithoutDescriptorsTheLoadedMapIsNotWaitedFor) {
  const PlaneMapFile scene("reloc_off");
  SlamOptions off = scene.Options();
  off.relocalization = false;
  EXPECT_EQ(SlamSystem(off).state(), SlamState::kNotInitialized);
  // A file without descriptors (as version 1 files are).
  Map bare;
  ASSERT_TRUE(bare.Load(scene.path).ok());
  for (auto& [id, p] : bare.points()) p.has_descriptor = false;
  ASSERT_TRUE(bare.Save(scene.dir + "/bare.map").ok());
  SlamOptions on;
  on.map_load_path = scene.dir + "/bare.map";
  EXPECT_EQ(SlamSystem(on).state(), SlamState::kNotInitialized);
}

// A map given up is kept (SlamOptions::lost_maps_kept) and taken up again when the
// camera comes back to it during the re-initialisation: the pose is in its frame.
TEST(SlamRelocalization, AGivenUpMapIsTakenUpAgainWhenTheCameraComesBack) {
  const PlaneMapFile scene("reloc_kept");
  const CameraIntrinsics K = Intrinsics();
  const cv::Mat other = Render(testing_images::Texture(1000, 800, 24), scene.plane, Rigid3d());
  const Eigen::Vector3d centre(0.3, 0.1, 0.2);
  const Rigid3d back(Eigen::Quaterniond::Identity(), -centre);
  const cv::Mat view = Render(scene.texture, scene.plane, back);
  for (const int kept : {3, 0}) {
    SlamOptions options = scene.Options();
    options.reloc_loaded_max_frames = 2;
    options.lost_maps_kept = kept;
    SlamSystem slam(options);
    for (int i = 0; i < 4; ++i) EXPECT_FALSE(slam.TrackPose(FrameOf(i, other, K)).valid);
    EXPECT_EQ(slam.map().num_points(), 0u) << "the loaded map is given up";
    EXPECT_EQ(slam.lost_maps(), kept > 0 ? 1u : 0u);
    const SlamPose pose = slam.TrackPose(FrameOf(30, view, K));
    if (kept == 0) {
      EXPECT_FALSE(pose.valid) << "a map not kept cannot be come back to";
      EXPECT_EQ(slam.maps_rejoined(), 0);
      continue;
    }
    ASSERT_TRUE(pose.valid);
    EXPECT_TRUE(pose.placed_by_relocalization);
    EXPECT_EQ(slam.state(), SlamState::kTracking);
    EXPECT_LT(TranslationDistance(pose.cam_from_world, back), 0.02);
    EXPECT_GT(slam.map().num_points(), 150u);
    EXPECT_EQ(slam.maps_rejoined(), 1);
    EXPECT_EQ(slam.lost_maps(), 0u);
    // The image's tracks are not judged yet: no keyframe of none (keyframe_min_frames
    // have passed since the rejoin), one once enough are static.
    SlamFrame frame = FrameOf(30 + options.keyframe_min_frames, view, K);
    ASSERT_TRUE(slam.TrackPose(frame).valid);
    EXPECT_FALSE(slam.UpdateMap(frame, {}).new_keyframe);
    EXPECT_EQ(slam.map().num_keyframes(), 1u);
    std::unordered_map<int64_t, int> labels;
    for (int t = 0; t < options.min_tracking_inliers; ++t) {
      SlamObservation o;
      o.track_id = 5000 + t;
      o.uv = Eigen::Vector2d(100.0 + 20.0 * t, 200.0);
      o.xy = K.PixelToNormalized(o.uv);
      o.body_id = 0;
      frame.observations.push_back(o);
      labels[o.track_id] = 0;
    }
    EXPECT_TRUE(slam.UpdateMap(frame, labels).new_keyframe);
    EXPECT_EQ(slam.map().num_keyframes(), 2u);
  }
}

// At exit the largest map is saved: a kept one when the current map is smaller (here
// none: the loaded map was given up and nothing replaced it).
TEST(SlamRelocalization, AKeptMapLargerThanTheCurrentOneIsSaved) {
  const PlaneMapFile scene("reloc_save_kept");
  const CameraIntrinsics K = Intrinsics();
  const cv::Mat other = Render(testing_images::Texture(1000, 800, 26), scene.plane, Rigid3d());
  for (const int kept : {3, 0}) {
    SlamOptions options = scene.Options();
    options.reloc_loaded_max_frames = 2;
    options.lost_maps_kept = kept;
    options.map_save_path = scene.dir + "/saved" + std::to_string(kept) + ".map";
    {
      SlamSystem slam(options);
      for (int i = 0; i < 3; ++i) slam.TrackPose(FrameOf(i, other, K));
      ASSERT_EQ(slam.map().num_keyframes(), 0u);
    }
    Map saved;
    if (kept == 0) {
      EXPECT_FALSE(saved.Load(options.map_save_path).ok()) << "nothing to save";
      continue;
    }
    ASSERT_TRUE(saved.Load(options.map_save_path).ok());
    EXPECT_GT(saved.num_points(), 150u);
  }
}

// Points seen by a camera sliding sideways, observations only (the SLAM's tracks).
struct SlidingScene {
  std::vector<Eigen::Vector3d> points;
  SlidingScene() {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0), depth(4.0, 10.0);
    while (points.size() < 600) {
      const double z = depth(rng);
      points.emplace_back(u(rng) * 0.8 * z, u(rng) * 0.5 * z, z);
    }
  }
  SlamFrame Frame(int64_t f, const cv::Mat& image, const CameraIntrinsics& K) const {
    SlamFrame frame = FrameOf(f, image, K);
    const Eigen::Vector3d centre(0.05 * static_cast<double>(f), 0.0, 0.0);
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d p = points[i] - centre;
      const Eigen::Vector2d uv = K.Project(p);
      if (p.z() < 1.0 || uv.x() < 0 || uv.y() < 0 || uv.x() >= kWidth || uv.y() >= kHeight)
        continue;
      SlamObservation o;
      o.track_id = static_cast<int64_t>(i);
      o.uv = uv;
      o.xy = p.hnormalized();
      o.body_id = 0;
      o.p_static = 0.9;
      frame.observations.push_back(o);
    }
    return frame;
  }
};

// A newer map that tracks gives way to an older kept map that places its image
// (lost_map_min_inliers): a robot that started outside a loaded map continues in that
// map's frame once it reaches it; the newer map is kept in turn.
TEST(SlamRelocalization, ATrackingMapGivesWayToAnOlderKeptMap) {
  const PlaneMapFile scene("reloc_give_way");
  const CameraIntrinsics K = Intrinsics();
  const cv::Mat other = Render(testing_images::Texture(1000, 800, 25), scene.plane, Rigid3d());
  const SlidingScene sliding;
  // Kept and searched; not kept; kept, but asking more inliers than there are; kept, but
  // searched again only after the arrival window (the first search was on arriving in
  // tracking, before the camera reached the place).
  enum Case { kKept, kNotKept, kTooFewInliers, kLongInterval };
  for (const Case c : {kKept, kNotKept, kTooFewInliers, kLongInterval}) {
    SCOPED_TRACE(static_cast<int>(c));
    SlamOptions options = scene.Options();
    options.reloc_loaded_max_frames = 2;
    options.lost_maps_kept = c == kNotKept ? 0 : 3;
    if (c == kTooFewInliers) options.lost_map_min_inliers = 100000;
    if (c == kLongInterval) options.lost_map_search_frames = 50;
    const int window = 11;  // images at the place: a search every 10 finds it
    SlamSystem slam(options);
    // The loaded map's ground plane goes with it, and comes back with it.
    const Eigen::Vector4d loaded_ground(0.0, -1.0, 0.0, 1.5), new_ground(0.0, -0.8, 0.6, 0.7);
    slam.SetGroundPlane(loaded_ground);
    int64_t f = 0;
    for (; f < 60 && slam.state() != SlamState::kTracking; ++f) {
      slam.TrackPose(sliding.Frame(f, other, K));
    }
    ASSERT_EQ(slam.state(), SlamState::kTracking) << "the new map was made";
    EXPECT_FALSE(slam.ground_plane().has_value());
    slam.SetGroundPlane(new_ground);
    slam.TrackPose(sliding.Frame(f++, other, K));  // the first search: nothing there
    EXPECT_EQ(slam.maps_rejoined(), 0);
    // The camera reaches the loaded map's place (its tracks go on in the new map).
    SlamPose pose;
    const int64_t arrive = f;
    for (; f < arrive + window && slam.maps_rejoined() == 0; ++f) {
      pose = slam.TrackPose(sliding.Frame(f, Render(scene.texture, scene.plane, Rigid3d()), K));
      EXPECT_TRUE(pose.valid);
    }
    if (c != kKept) {
      EXPECT_EQ(slam.maps_rejoined(), 0);
      EXPECT_GT(TranslationDistance(pose.cam_from_world, Rigid3d()), 0.1)
          << "still the new map's frame";
      continue;
    }
    ASSERT_EQ(slam.maps_rejoined(), 1);
    EXPECT_TRUE(pose.placed_by_relocalization);
    EXPECT_TRUE(pose.rejoined_kept_map);
    EXPECT_LT(TranslationDistance(pose.cam_from_world, Rigid3d()), 0.02)
        << "in the loaded map's frame";
    EXPECT_GT(slam.map().num_points(), 150u);
    EXPECT_EQ(slam.lost_maps(), 1u) << "the new map is kept in turn";
    ASSERT_TRUE(slam.ground_plane().has_value());
    EXPECT_EQ(*slam.ground_plane(), loaded_ground);
    // It is not searched again: only older maps replace the current one.
    for (int64_t end = f + 2 * options.lost_map_search_frames; f < end; ++f) {
      slam.TrackPose(sliding.Frame(f, Render(scene.texture, scene.plane, Rigid3d()), K));
    }
    EXPECT_EQ(slam.maps_rejoined(), 1);
  }
}

// The relocalisation by which a kept map replaces the tracking one places that image
// itself: the image is not relocalised a second time in the map taken up, which would
// ask reloc_min_inliers where the search asked lost_map_min_inliers (and cost a second
// matching).
TEST(SlamRelocalization, TheImageThatRejoinsAMapIsPlacedByThatSearch) {
  const PlaneMapFile scene("reloc_hand_over");
  const CameraIntrinsics K = Intrinsics();
  Map loaded;
  ASSERT_TRUE(loaded.Load(scene.path).ok());
  const cv::Mat other = Render(testing_images::Texture(1000, 800, 26), scene.plane, Rigid3d());
  const SlidingScene sliding;
  const Rigid3d back(Eigen::Quaterniond::Identity(), -Eigen::Vector3d(0.3, 0.1, 0.2));
  SlamOptions options = scene.Options();
  options.reloc_loaded_max_frames = 2;
  options.lost_map_min_inliers = 6;
  // Enough to keep the loaded map, more than one image of it can match.
  options.reloc_min_inliers = static_cast<int>(loaded.num_described_points());
  SlamSystem slam(options);
  int64_t f = 0;
  for (; f < 60 && slam.state() != SlamState::kTracking; ++f) {
    slam.TrackPose(sliding.Frame(f, other, K));
  }
  ASSERT_EQ(slam.state(), SlamState::kTracking) << "the new map was made";
  ASSERT_EQ(slam.lost_maps(), 1u) << "the loaded map is kept";
  SlamPose pose;
  for (const int64_t end = f + 11; f < end && slam.maps_rejoined() == 0; ++f) {
    pose = slam.TrackPose(sliding.Frame(f, Render(scene.texture, scene.plane, back), K));
  }
  ASSERT_EQ(slam.maps_rejoined(), 1);
  EXPECT_GE(pose.num_inliers, options.lost_map_min_inliers);
  EXPECT_LT(pose.num_inliers, options.reloc_min_inliers);
  EXPECT_TRUE(pose.valid);
  EXPECT_TRUE(pose.placed_by_relocalization);
  EXPECT_TRUE(pose.rejoined_kept_map);
  EXPECT_EQ(slam.state(), SlamState::kTracking);
  EXPECT_LT(TranslationDistance(pose.cam_from_world, back), 0.02) << "in the loaded map's frame";
}

// Beyond lost_maps_kept the newest kept map goes, not the oldest: a map made after the
// loaded one was given up, then lost itself, is dropped, and the loaded map is still
// there to come back to.
TEST(SlamRelocalization, TheOldestKeptMapStays) {
  const PlaneMapFile scene("reloc_oldest");
  const CameraIntrinsics K = Intrinsics();
  const cv::Mat other = Render(testing_images::Texture(1000, 800, 27), scene.plane, Rigid3d());
  const cv::Mat dark = Render(testing_images::Texture(1000, 800, 28), scene.plane, Rigid3d());
  const SlidingScene sliding;
  SlamOptions options = scene.Options();
  options.reloc_loaded_max_frames = 2;
  options.lost_maps_kept = 1;
  SlamSystem slam(options);
  int64_t f = 0;
  for (; f < 60 && slam.state() != SlamState::kTracking; ++f)
    slam.TrackPose(sliding.Frame(f, other, K));
  ASSERT_EQ(slam.state(), SlamState::kTracking);
  ASSERT_EQ(slam.lost_maps(), 1u) << "the loaded map, given up";
  // The new map is lost: images of neither map, without tracks.
  for (int i = 0; i < options.lost_frames_to_reinit; ++i)
    EXPECT_FALSE(slam.TrackPose(FrameOf(f++, dark, K)).valid);
  EXPECT_EQ(slam.map().num_keyframes(), 0u) << "re-initialising";
  EXPECT_EQ(slam.lost_maps(), 1u) << "one kept: the new map went";
  const SlamPose pose =
      slam.TrackPose(FrameOf(f, Render(scene.texture, scene.plane, Rigid3d()), K));
  ASSERT_TRUE(pose.valid) << "the loaded map is still there";
  EXPECT_LT(TranslationDistance(pose.cam_from_world, Rigid3d()), 0.02);
  EXPECT_EQ(slam.maps_rejoined(), 1);
}

// A map without described points (no images: nothing to describe) cannot be
// relocalised in, so it is not kept when it is lost.
TEST(SlamRelocalization, AMapWithoutDescriptorsIsNotKept) {
  const CameraIntrinsics K = Intrinsics();
  const SlidingScene sliding;
  SlamSystem slam{SlamOptions()};
  int64_t f = 0;
  for (; f < 60 && slam.state() != SlamState::kTracking; ++f)
    slam.TrackPose(sliding.Frame(f, cv::Mat(), K));
  ASSERT_EQ(slam.state(), SlamState::kTracking);
  for (int i = 0; i < SlamOptions().lost_frames_to_reinit; ++i)
    slam.TrackPose(FrameOf(f++, cv::Mat(), K));
  EXPECT_EQ(slam.map().num_keyframes(), 0u) << "lost and given up";
  EXPECT_EQ(slam.lost_maps(), 0u);
}

// The search by projection finds the points whose descriptors lost among all the
// corners: a camera 0.7 m nearer the plane and turned 12 deg is placed only with it.
TEST(SlamRelocalization, SearchByProjectionFindsMorePoints) {
  const PlaneMapFile scene("reloc_search");
  const CameraIntrinsics K = Intrinsics();
  const Eigen::Quaterniond q(Eigen::AngleAxisd(12.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()));
  const Eigen::Vector3d centre(0.3, 0.0, 0.7);
  const Rigid3d cam_from_world(q.conjugate(), -(q.conjugate() * centre));
  const cv::Mat view = Render(scene.texture, scene.plane, cam_from_world);
  SlamPose with_search, without;
  for (const double radius : {20.0, 0.0}) {
    SlamOptions options = scene.Options();
    options.reloc_search_radius_px = radius;
    SlamSystem slam(options);
    (radius > 0.0 ? with_search : without) = slam.TrackPose(FrameOf(0, view, K));
  }
  // Globally too few matches agree (0 placed); around the first pose's projections
  // enough do.
  EXPECT_FALSE(without.valid);
  ASSERT_TRUE(with_search.valid);
  EXPECT_LT(TranslationDistance(with_search.cam_from_world, cam_from_world), 0.02);
  EXPECT_GE(with_search.refound.size(), 40u);
}

}  // namespace
}  // namespace mbslam
