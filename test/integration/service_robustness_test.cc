// The service keeps running on truncated, corrupted and oversized messages on every
// input channel, and PERCEPTION_STATUS counts them.

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <map>

#include "common/lcm/wire_check.h"
#include "mbslam/camera_calibration_t.hpp"
#include "mbslam/image_t.hpp"
#include "mbslam/odometry_t.hpp"
#include "mbslam/snapshot_request_t.hpp"
#include "mbslam/status_t.hpp"
#include "services/perception/perception_service.h"

namespace mbslam {
namespace {

mbslam::image_t Image(int64_t utime, int64_t seq) {
  mbslam::image_t m{};
  m.utime = utime;
  m.seq = seq;
  m.camera_name = "cam";
  m.width = 64;
  m.height = 48;
  m.row_stride = 64;
  m.encoding = mbslam::image_t::ENCODING_GRAY8;
  m.data.resize(64 * 48);
  for (size_t i = 0; i < m.data.size(); ++i) m.data[i] = static_cast<uint8_t>((i * 37 + seq) & 255);
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}

class ServiceRobustness : public ::testing::Test {
 protected:
  void SetUp() override {
    Status s;
    bus_ = LcmBus::Create("memq://", &s);
    ASSERT_TRUE(bus_) << s.message();
    PerceptionOptions options;
    options.pipeline.mode = "lockstep";
    service_ = PerceptionService::Create(options, &s, bus_.get());
    ASSERT_TRUE(service_) << s.message();
    bus_->Subscribe(options.channels.perception_status,
                    [this](const std::string&, const uint8_t* d, size_t n, int64_t) {
                      mbslam::status_t st{};
                      ASSERT_TRUE(DecodeLcmMessage(d, n, &st).ok());
                      statuses_.push_back(st);
                    });
    bus_->Subscribe(options.channels.perception_camera_pose,
                    [this](const std::string&, const uint8_t*, size_t, int64_t) { ++poses_; });
  }
  void Send(const std::string& channel, const std::vector<uint8_t>& bytes, size_t size = 0) {
    bus_->PublishRaw(channel, bytes.data(), static_cast<unsigned>(size ? size : bytes.size()));
    while (bus_->HandleTimeout(0) > 0) {
    }
  }
  std::map<std::string, int64_t> FinalCounters() {
    EXPECT_TRUE(service_->Finish().ok());
    while (bus_->HandleTimeout(0) > 0) {
    }
    std::map<std::string, int64_t> out;
    if (statuses_.empty()) return out;
    for (const auto& c : statuses_.back().counters) out[c.name] = c.value;
    return out;
  }

  std::unique_ptr<LcmBus> bus_;
  std::unique_ptr<PerceptionService> service_;
  std::vector<mbslam::status_t> statuses_;
  int poses_ = 0;
};

TEST_F(ServiceRobustness, BadInputOnEveryChannelIsCountedAndServiceKeepsRunning) {
  const ChannelOptions ch;
  mbslam::camera_calibration_t calib{};
  calib.camera_name = "cam";
  calib.width = 64;
  calib.height = 48;
  calib.fx = calib.fy = 50;
  calib.cx = 31.5;
  calib.cy = 23.5;
  Send(ch.camera_calibration, mbslam::EncodeLcmMessage(calib));
  int64_t t = 1000000;
  for (int i = 0; i < 5; ++i, t += 33333) Send(ch.camera_image, mbslam::EncodeLcmMessage(Image(t, i)));

  // CAMERA_IMAGE: truncated, corrupted, oversized claim, wrong size, unknown encoding,
  // time backwards.
  std::vector<uint8_t> img = mbslam::EncodeLcmMessage(Image(t, 5));
  Send(ch.camera_image, img, img.size() / 2);
  std::vector<uint8_t> corrupt = img;
  corrupt[0] ^= 0xFF;
  Send(ch.camera_image, corrupt);
  std::vector<uint8_t> huge = img;
  const size_t size_pos = huge.size() - 64 * 48 - 4;
  huge[size_pos] = 0x7F;  // claims ~2 GB of pixel data
  huge[size_pos + 1] = 0xFF;
  Send(ch.camera_image, huge);
  mbslam::image_t wrong = Image(t, 5);
  wrong.height = 4800;
  Send(ch.camera_image, mbslam::EncodeLcmMessage(wrong));
  mbslam::image_t enc = Image(t, 5);
  enc.encoding = 99;
  Send(ch.camera_image, mbslam::EncodeLcmMessage(enc));
  Send(ch.camera_image, mbslam::EncodeLcmMessage(Image(t - 500000, 5)));
  // CAMERA_CALIBRATION: truncated, NaN.
  std::vector<uint8_t> cal = mbslam::EncodeLcmMessage(calib);
  Send(ch.camera_calibration, cal, cal.size() - 3);
  mbslam::camera_calibration_t nan_calib = calib;
  nan_calib.cx = NAN;
  Send(ch.camera_calibration, mbslam::EncodeLcmMessage(nan_calib));
  // ODOMETRY: garbage, NaN.
  std::vector<uint8_t> garbage(1000, 0xEE);
  Send(ch.odometry, garbage);
  mbslam::odometry_t odom{};
  odom.utime = t;
  odom.orientation[0] = NAN;
  Send(ch.odometry, mbslam::EncodeLcmMessage(odom));
  // SNAPSHOT_REQUEST: truncated.
  mbslam::snapshot_request_t snap{};
  snap.path_prefix = "/tmp/x";
  std::vector<uint8_t> sb = mbslam::EncodeLcmMessage(snap);
  Send(ch.snapshot_request, sb, 5);

  for (int i = 0; i < 5; ++i, t += 33333) Send(ch.camera_image, mbslam::EncodeLcmMessage(Image(t, 5 + i)));
  std::map<std::string, int64_t> c = FinalCounters();

  EXPECT_EQ(poses_, 10) << "every valid image produced an output";
  EXPECT_EQ(c["image_decode_error"], 3);
  EXPECT_EQ(c["image_size_mismatch"], 1);
  EXPECT_EQ(c["image_unknown_encoding"], 1);
  EXPECT_EQ(c["image_time_backwards"], 1);
  EXPECT_EQ(c["calibration_decode_error"], 1);
  EXPECT_EQ(c["calibration_invalid"], 1);
  EXPECT_EQ(c["odometry_decode_error"], 1);
  EXPECT_EQ(c["odometry_invalid"], 1);
  EXPECT_EQ(c["snapshot_request_decode_error"], 1);
  ASSERT_FALSE(statuses_.empty());
  EXPECT_EQ(statuses_.back().frames_received, 10);
  EXPECT_EQ(statuses_.back().frames_processed, 10);
  EXPECT_EQ(statuses_.back().frames_rejected, 6);
  bool degraded_seen = false;
  for (const auto& st : statuses_) degraded_seen |= st.state == mbslam::status_t::STATE_DEGRADED;
  EXPECT_TRUE(degraded_seen || statuses_.size() == 1);
}

// Issue 9: LCM has no authentication, so SNAPSHOT_REQUEST's path_prefix may only name
// a folder under service.output_dir; absolute paths and ".." are refused and counted.
TEST(ServiceSnapshotRequests, PathsOutsideTheOutputDirAreRefused) {
  const std::string root = ::testing::TempDir() + "/mbslam_snapshot_paths_" + std::to_string(::getpid());
  std::filesystem::remove_all(root);
  std::filesystem::create_directories(root + "/out");
  Status s;
  auto bus = LcmBus::Create("memq://", &s);
  ASSERT_TRUE(bus) << s.message();
  PerceptionOptions options;
  options.pipeline.mode = "lockstep";
  options.service.output_dir = root + "/out";
  auto service = PerceptionService::Create(options, &s, bus.get());
  ASSERT_TRUE(service) << s.message();
  std::vector<mbslam::status_t> statuses;
  bus->Subscribe(options.channels.perception_status,
                 [&statuses](const std::string&, const uint8_t* d, size_t n, int64_t) {
                   mbslam::status_t st{};
                   ASSERT_TRUE(DecodeLcmMessage(d, n, &st).ok());
                   statuses.push_back(st);
                 });
  auto request = [&](const std::string& prefix) {
    mbslam::snapshot_request_t r{};
    r.utime = 1;
    r.path_prefix = prefix;
    r.what = mbslam::snapshot_request_t::WHAT_OUTPUTS;
    const std::vector<uint8_t> b = mbslam::EncodeLcmMessage(r);
    bus->PublishRaw(options.channels.snapshot_request, b.data(), static_cast<unsigned>(b.size()));
    while (bus->HandleTimeout(0) > 0) {
    }
  };
  request(root + "/absolute");
  request("../escaped");
  request("inside");
  ASSERT_TRUE(service->Finish().ok());
  while (bus->HandleTimeout(0) > 0) {
  }
  EXPECT_FALSE(std::filesystem::exists(root + "/absolute"));
  EXPECT_FALSE(std::filesystem::exists(root + "/escaped"));
  EXPECT_TRUE(std::filesystem::exists(root + "/out/inside/camera_trajectory.tum"));
  ASSERT_FALSE(statuses.empty());
  int64_t refused = 0;
  for (const auto& c : statuses.back().counters) {
    if (c.name == "snapshot_request_refused_path") refused = c.value;
  }
  EXPECT_EQ(refused, 2);
  for (const auto& c : statuses.back().counters) {
    EXPECT_NE(c.name, "slam_global_ba_requested") << "WHAT_OUTPUTS asks for no adjustment";
  }
  std::filesystem::remove_all(root);
}

// WHAT_GLOBAL_BA asks the service's SLAM for a bundle adjustment of its whole map: it is
// counted when an image takes it up. The images here make no map, so it does not start
// (SlamGlobalBundleAdjustment tests that it does on a map).
TEST_F(ServiceRobustness, AGlobalBundleAdjustmentRequestIsCounted) {
  const ChannelOptions ch;
  int64_t t = 1000000;
  Send(ch.camera_image, mbslam::EncodeLcmMessage(Image(t, 0)));
  mbslam::snapshot_request_t r{};
  r.utime = t;
  r.path_prefix = "global_ba";
  r.what = mbslam::snapshot_request_t::WHAT_GLOBAL_BA;
  Send(ch.snapshot_request, mbslam::EncodeLcmMessage(r));
  for (int i = 1; i < 4; ++i) Send(ch.camera_image, mbslam::EncodeLcmMessage(Image(t += 33333, i)));
  std::map<std::string, int64_t> c = FinalCounters();
  EXPECT_EQ(c["slam_global_ba_requested"], 1);
  EXPECT_EQ(c["slam_global_ba_started"], 0) << "no map to adjust";
  EXPECT_EQ(poses_, 4);
  EXPECT_EQ(c["snapshot_request_decode_error"], 0);
  ASSERT_FALSE(statuses_.empty());
  EXPECT_NE(statuses_.back().state, mbslam::status_t::STATE_DEGRADED) << "a request is no fault";
}

}  // namespace
}  // namespace mbslam
