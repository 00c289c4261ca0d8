// The LCM side of the viewer on memq://: conversions, bad-message counting, snapshot
// requests and the periodic schedule on message time.

#include "viewer/lcm_adapter.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <limits>

#include "common/config/options_yaml.h"
#include "common/util/atomic_file.h"
#include "viewer/testing/synthetic_outputs.h"
#include "viewer/viewer_app.h"
#include "common/lcm/wire_check.h"

namespace mbslam {
namespace viewer {
namespace {

std::string TempDir(const std::string& name) {
  const std::string dir =
      std::string(::testing::TempDir()) + "viewer_lcm_" + name + "_" + std::to_string(::getpid());
  std::filesystem::remove_all(dir);
  return dir;
}

int CountFiles(const std::string& dir, const std::string& prefix) {
  int n = 0;
  if (!std::filesystem::exists(dir)) return 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().filename().string().rfind(prefix, 0) == 0) ++n;
  }
  return n;
}

TEST(FromLcm, CameraPoseQuaternionIsWxyz) {
  mbslam::camera_pose_t m{};
  m.utime = 42;
  m.position[0] = 1;
  m.position[1] = 2;
  m.position[2] = 3;
  // 90 degrees about z: [w, x, y, z] = [cos 45, 0, 0, sin 45].
  m.orientation[0] = std::sqrt(0.5);
  m.orientation[3] = std::sqrt(0.5);
  m.tracking_state = mbslam::camera_pose_t::TRACKING_OK;
  m.scale_state = mbslam::camera_pose_t::SCALE_METRIC;
  CameraPoseSample pose;
  ASSERT_TRUE(FromLcm(m, &pose).ok());
  EXPECT_EQ(pose.utime, 42);
  EXPECT_TRUE(pose.metric);
  EXPECT_EQ(pose.tracking_state, TrackingState::kOk);
  EXPECT_TRUE((pose.world_from_cam.orientation * Eigen::Vector3d::UnitX())
                  .isApprox(Eigen::Vector3d::UnitY(), 1e-12));
  m.orientation[0] = m.orientation[3] = 0.0;  // not a rotation
  EXPECT_FALSE(FromLcm(m, &pose).ok());
  m.orientation[0] = 1.0;
  m.position[1] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(FromLcm(m, &pose).ok());
}

TEST(FromLcm, SyntheticFrameConvertsCompletely) {
  const testing::SyntheticOutputs outputs;
  const testing::SyntheticFrame f = outputs.Frame(5);
  ASSERT_TRUE(f.map && f.occupancy);
  MapData map;
  ASSERT_TRUE(FromLcm(*f.map, &map).ok());
  EXPECT_EQ(map.points.size(), f.map->points.size());
  EXPECT_EQ(map.colors.size(), f.map->points.size());
  EXPECT_EQ(map.keyframes.size(), f.map->keyframes.size());
  ASSERT_TRUE(map.ground_plane.has_value());
  EXPECT_DOUBLE_EQ((*map.ground_plane)[3], 1.5);
  ObjectsData objects;
  ASSERT_TRUE(FromLcm(f.objects, &objects).ok());
  ASSERT_EQ(objects.objects.size(), 2u);
  EXPECT_EQ(objects.objects[0].volumes.size(), 5u);
  EXPECT_FALSE(objects.objects[0].particles.empty());
  TracksData tracks;
  ASSERT_TRUE(FromLcm(f.tracks, &tracks).ok());
  EXPECT_EQ(tracks.tracks.size(), f.tracks.tracks.size());
  EXPECT_EQ(tracks.hulls.size(), f.tracks.hulls.size());
  EncodedOccupancy occupancy;
  ASSERT_TRUE(FromLcm(*f.occupancy, &occupancy).ok());
  EXPECT_EQ(occupancy.data.size(), f.occupancy->data.size());
  mbslam::image_t image = f.image;
  EncodedImage encoded;
  ASSERT_TRUE(FromLcm(std::move(image), &encoded).ok());
  EXPECT_EQ(encoded.encoding, ImageEncoding::kBgr8);
  mbslam::image_t bad = f.image;
  bad.encoding = 42;
  EXPECT_FALSE(FromLcm(std::move(bad), &encoded).ok());
}

class AdapterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Status s;
    bus_ = LcmBus::Create("memq://", &s);
    ASSERT_TRUE(bus_) << s.message();
    adapter_ =
        std::make_unique<ViewerLcmAdapter>(bus_.get(), channels_, 100, size_t{1} << 20, &scene_);
  }
  void Send(const std::string& channel, const std::vector<uint8_t>& bytes) {
    bus_->PublishRaw(channel, bytes.data(), static_cast<unsigned>(bytes.size()));
    while (bus_->HandleTimeout(0) > 0) {
    }
  }
  ChannelOptions channels_;
  std::unique_ptr<LcmBus> bus_;
  SceneState scene_;
  std::unique_ptr<ViewerLcmAdapter> adapter_;
};

TEST_F(AdapterTest, GoodMessagesReachTheScene) {
  const testing::SyntheticOutputs outputs;
  std::vector<int64_t> times;
  adapter_->SetMessageTimeHook([&times](int64_t t) { times.push_back(t); });
  for (int k = 0; k < 6; ++k) {
    const testing::SyntheticFrame f = outputs.Frame(k);
    Send(channels_.camera_image, mbslam::EncodeLcmMessage(f.image));
    Send(channels_.perception_camera_pose, mbslam::EncodeLcmMessage(f.pose));
    Send(channels_.perception_tracks, mbslam::EncodeLcmMessage(f.tracks));
    Send(channels_.perception_objects, mbslam::EncodeLcmMessage(f.objects));
    if (f.map) Send(channels_.perception_map, mbslam::EncodeLcmMessage(*f.map));
    if (f.occupancy) Send(channels_.perception_occupancy, mbslam::EncodeLcmMessage(*f.occupancy));
  }
  EXPECT_EQ(adapter_->bad_total(), 0);
  EXPECT_EQ(adapter_->counts().at(channels_.camera_image).received, 6);
  EXPECT_EQ(scene_.camera_trajectory().size(), 4u);  // frames 0 and 1 are initialising
  EXPECT_FALSE(scene_.map().points.empty());
  EXPECT_FALSE(scene_.occupancy().voxels.empty());
  EXPECT_EQ(scene_.objects().objects.size(), 2u);
  const ImageFrame frame = scene_.LatestImageFrame();
  ASSERT_NE(frame.tracks, nullptr);
  ASSERT_NE(frame.image, nullptr);
  EXPECT_EQ(frame.utime, outputs.Frame(5).utime);
  EXPECT_EQ(times.size(), 6u * 4 + 2 * 2);
}

TEST_F(AdapterTest, BadMessagesAreCountedPerChannelAndDropped) {
  const testing::SyntheticOutputs outputs;
  const testing::SyntheticFrame f = outputs.Frame(5);
  // Truncated, garbage, wrong type, oversized, NaN pose.
  const std::vector<uint8_t> map = mbslam::EncodeLcmMessage(*f.map);
  Send(channels_.perception_map, std::vector<uint8_t>(map.begin(), map.begin() + 100));
  Send(channels_.perception_objects, std::vector<uint8_t>(50, 0xab));
  Send(channels_.perception_tracks, mbslam::EncodeLcmMessage(f.pose));
  Send(channels_.camera_image, mbslam::EncodeLcmMessage(f.image));  // 921 kB < 1 MiB limit: fine
  mbslam::image_t big = f.image;
  big.data.resize(size_t{2} << 20);
  big.size = static_cast<int32_t>(big.data.size());
  Send(channels_.camera_image, mbslam::EncodeLcmMessage(big));  // over the 1 MiB limit of this adapter
  mbslam::camera_pose_t nan_pose = f.pose;
  nan_pose.position[2] = std::nan("");
  Send(channels_.perception_camera_pose, mbslam::EncodeLcmMessage(nan_pose));
  Send(channels_.snapshot_request, {1, 2, 3});
  EXPECT_EQ(adapter_->counts().at(channels_.perception_map).bad, 1);
  EXPECT_EQ(adapter_->counts().at(channels_.perception_objects).bad, 1);
  EXPECT_EQ(adapter_->counts().at(channels_.perception_tracks).bad, 1);
  EXPECT_EQ(adapter_->counts().at(channels_.camera_image).bad, 1);
  EXPECT_EQ(adapter_->counts().at(channels_.camera_image).received, 2);
  EXPECT_EQ(adapter_->counts().at(channels_.perception_camera_pose).bad, 1);
  EXPECT_EQ(adapter_->counts().at(channels_.snapshot_request).bad, 1);
  EXPECT_EQ(adapter_->bad_total(), 6);
  EXPECT_FALSE(adapter_->counts().at(channels_.perception_map).last_error.empty());
  EXPECT_TRUE(scene_.map().points.empty());
  EXPECT_FALSE(scene_.current_camera().has_value());
  // The scene has the one good image.
  EXPECT_NE(scene_.LatestImageFrame().image, nullptr);
}

// ---------------------------------------------------------------- ViewerApp on memq://

ViewerOptions AppOptions(const std::string& out) {
  ViewerOptions o;
  o.viewer.output_dir = out;
  o.viewer.log_level = "warning";
  o.view3d.width = 320;
  o.view3d.height = 240;
  o.view3d.antialias_samples = 1;
  return o;
}

TEST(ViewerApp, PeriodicSnapshotsRunOnMessageTime) {
  const std::string out = TempDir("periodic");
  ViewerOptions options = AppOptions(out);
  options.viewer.snapshot_period_s = 1.0;
  Status s;
  auto bus = LcmBus::Create("memq://", &s);
  ASSERT_TRUE(bus) << s.message();
  auto app = ViewerApp::Create(options, &s, bus.get());
  ASSERT_TRUE(app) << s.message();
  testing::SyntheticOptions synthetic;
  synthetic.width = 160;
  synthetic.height = 120;
  const testing::SyntheticOutputs outputs(synthetic);
  // 2.5 s of frames at 10 Hz, delivered as fast as possible: two periodic snapshots
  // (at 1.0 s and 2.0 s after the first message), however fast the messages come.
  for (int k = 0; k < 25; ++k) {
    const testing::SyntheticFrame f = outputs.Frame(k);
    bus->Publish(options.channels.camera_image, f.image);
    bus->Publish(options.channels.perception_camera_pose, f.pose);
    bus->Publish(options.channels.perception_tracks, f.tracks);
    bus->Publish(options.channels.perception_objects, f.objects);
    if (f.map) bus->Publish(options.channels.perception_map, *f.map);
    while (app->RunOnce(0) && bus->HandleTimeout(0) > 0) {
    }
  }
  EXPECT_EQ(app->snapshots_3d(), 2);
  EXPECT_EQ(app->snapshots_image(), 2);
  const int64_t t0 = synthetic.start_utime;
  // Each snapshot shows the last complete frame before the due time.
  EXPECT_TRUE(std::filesystem::exists(out + "/view3d_" + std::string(16 - 7, '0') +
                                      std::to_string(t0 + 900000) + ".png"));
  EXPECT_TRUE(std::filesystem::exists(out + "/image_latest.png"));
  ASSERT_TRUE(app->Finish().ok());
  EXPECT_EQ(app->snapshots_3d(), 3);  // the final one
  std::string stats;
  ASSERT_TRUE(ReadFileToString(out + "/viewer_stats.json", &stats).ok());
  EXPECT_NE(stats.find("\"snapshots_3d\": 3"), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"bad_messages_total\": 0"), std::string::npos) << stats;
  const cv::Mat img = cv::imread(out + "/view3d_latest.png");
  EXPECT_EQ(img.size(), cv::Size(320, 240));
  std::filesystem::remove_all(out);
}

TEST(ViewerApp, SnapshotRequestsWriteTheAskedViews) {
  const std::string out = TempDir("request");
  ViewerOptions options = AppOptions(out);
  options.viewer.snapshot_period_s = 0.0;  // only on request
  options.viewer.snapshot_at_exit = false;
  Status s;
  auto bus = LcmBus::Create("memq://", &s);
  ASSERT_TRUE(bus);
  auto app = ViewerApp::Create(options, &s, bus.get());
  ASSERT_TRUE(app) << s.message();
  const testing::SyntheticOutputs outputs;
  const testing::SyntheticFrame f = outputs.Frame(5);
  bus->Publish(options.channels.perception_camera_pose, f.pose);
  bus->Publish(options.channels.perception_map, *f.map);
  auto request = [&](int8_t what, const std::string& prefix) {
    mbslam::snapshot_request_t r{};
    r.utime = 1;
    r.what = what;
    r.path_prefix = prefix;
    bus->Publish(options.channels.snapshot_request, r);
    while (bus->HandleTimeout(0) > 0) {
    }
  };
  while (bus->HandleTimeout(0) > 0) {
  }
  request(mbslam::snapshot_request_t::WHAT_VIEW_3D, "");
  EXPECT_EQ(CountFiles(out, "view3d_"), 2);  // history + latest
  EXPECT_EQ(CountFiles(out, "image_"), 0);
  request(mbslam::snapshot_request_t::WHAT_OUTPUTS, "");  // not the viewer's
  EXPECT_EQ(app->snapshots_3d(), 1);
  request(mbslam::snapshot_request_t::WHAT_VIEW_IMAGE, "req/run1_");
  EXPECT_EQ(CountFiles(out + "/req", "run1_image_"), 1);  // no "latest" for a named request
  request(mbslam::snapshot_request_t::WHAT_VIEW_3D | mbslam::snapshot_request_t::WHAT_VIEW_IMAGE,
          "/tmp/../etc/evil_");  // refused: goes to the output directory
  EXPECT_FALSE(std::filesystem::exists("/etc/evil_view3d_latest.png"));
  EXPECT_EQ(app->snapshots_3d(), 2);
  ASSERT_TRUE(app->Finish().ok());
  std::string stats;
  ASSERT_TRUE(ReadFileToString(out + "/viewer_stats.json", &stats).ok());
  EXPECT_NE(stats.find("\"refused_request_paths\": 1"), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"snapshot_requests\": 3"), std::string::npos) << stats;
  std::filesystem::remove_all(out);
}

TEST(ViewerOptions, ConfigFileListsEveryOptionWithItsDefault) {
  const std::string path = "config/viewer.yaml";
  std::string text;
  ASSERT_TRUE(ReadFileToString(path, &text).ok()) << "run from the repository root";
  ViewerOptions loaded;
  const Status s = LoadOptionsFromFile(path, &loaded);
  ASSERT_TRUE(s.ok()) << s.message();
  const std::string defaults = OptionsToYaml(ViewerOptions());
  EXPECT_EQ(OptionsToYaml(loaded), defaults);
  size_t pos = 0;
  while (pos < defaults.size()) {
    const size_t end = defaults.find('\n', pos);
    const std::string line = defaults.substr(pos, end - pos);
    EXPECT_NE(text.find(line), std::string::npos) << "config/viewer.yaml lacks: " << line;
    pos = end + 1;
  }
  EXPECT_TRUE(ViewerOptions().Check());
  ViewerOptions bad;
  bad.viewer.output_dir = "";
  EXPECT_FALSE(bad.Check());
  bad = ViewerOptions();
  bad.viewer.stats_file = "../x.json";
  EXPECT_FALSE(bad.Check());
}

}  // namespace
}  // namespace viewer
}  // namespace mbslam
