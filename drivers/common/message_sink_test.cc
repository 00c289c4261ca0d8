#include "drivers/common/message_sink.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include "common/lcm/wire_check.h"
#include "common/testing/temp_dir.h"
#include "mbslam/pose_t.hpp"

namespace mbslam {
namespace {

mbslam::pose_t MakePose(int64_t utime) {
  mbslam::pose_t pose{};
  pose.utime = utime;
  pose.target_frame = "world";
  pose.source_frame = "cam";
  pose.position[0] = static_cast<double>(utime) * 1e-6;
  pose.orientation[0] = 1.0;
  return pose;
}

TEST(MessageSink, LogSinkStampsEventsWithMessageTime) {
  const std::string path = testing_util::MakeTestTempDir("sink") + "/out.lcmlog";
  Status status;
  {
    std::unique_ptr<MessageSink> sink = CreateMessageSink(path, "", &status);
    ASSERT_TRUE(sink) << status.message();
    EXPECT_TRUE(sink->is_file());
    for (int64_t t : {1000, 2500, 9000}) ASSERT_TRUE(sink->Publish("POSE", t, MakePose(t)).ok());
    EXPECT_EQ(sink->messages(), 3);
  }
  std::vector<LcmLogEvent> events;
  ASSERT_TRUE(ReadLcmLog(path, &events).ok());
  ASSERT_EQ(events.size(), 3u);
  EXPECT_EQ(events[1].timestamp, 2500);
  EXPECT_EQ(events[1].channel, "POSE");
  mbslam::pose_t decoded{};
  ASSERT_TRUE(DecodeLcmMessage(events[1].data.data(), events[1].data.size(), &decoded).ok());
  EXPECT_EQ(decoded.position[0], 0.0025);
}

TEST(MessageSink, BusSinkPublishesOnTheBus) {
  Status status;
  std::unique_ptr<LcmBus> bus = LcmBus::Create("memq://", &status);
  ASSERT_TRUE(bus) << status.message();
  int received = 0;
  bus->Subscribe("POSE", [&](const std::string&, const uint8_t* data, size_t size, int64_t) {
    mbslam::pose_t pose{};
    if (DecodeLcmMessage(data, size, &pose).ok() && pose.utime == 42) ++received;
  });
  LcmBusSink sink(bus.get());
  EXPECT_FALSE(sink.is_file());
  ASSERT_TRUE(sink.Publish("POSE", 42, MakePose(42)).ok());
  EXPECT_GT(bus->HandleTimeout(100), 0);
  EXPECT_EQ(received, 1);
}

TEST(MessageSink, UnwritableLogIsAnError) {
  Status status;
  EXPECT_FALSE(CreateMessageSink("/nonexistent_dir/x.lcmlog", "", &status));
  EXPECT_FALSE(status.ok());
}

}  // namespace
}  // namespace mbslam
