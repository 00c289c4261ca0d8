#include "common/lcm/lcm_log.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include "common/testing/temp_dir.h"
#include "common/util/atomic_file.h"
#include "mbslam/pose_t.hpp"

namespace mbslam {
namespace {

void WriteLog(const std::string& path) {
  Status status;
  auto writer = LcmLogWriter::Open(path, &status);
  ASSERT_TRUE(writer) << status.message();
  for (int i = 0; i < 10; ++i) {
    mbslam::pose_t pose{};  // value-initialised: generated types do not zero themselves
    pose.utime = 1000 * i;
    pose.target_frame = "world";
    pose.source_frame = "cam";
    pose.position[0] = i;
    pose.orientation[0] = 1.0;
    ASSERT_TRUE(writer->Write("POSE", pose.utime, pose).ok());
  }
}

TEST(LcmLog, WriterStampsMessageTimeSoLogsAreByteIdentical) {
  const std::string a = testing_util::MakeTestTempPath("log", "a.lcmlog");
  const std::string b = testing_util::MakeTestTempPath("log", "b.lcmlog");
  WriteLog(a);
  usleep(2000);
  WriteLog(b);
  std::string ta, tb;
  ASSERT_TRUE(ReadFileToString(a, &ta).ok());
  ASSERT_TRUE(ReadFileToString(b, &tb).ok());
  EXPECT_EQ(ta, tb);

  std::vector<LcmLogEvent> events;
  ASSERT_TRUE(ReadLcmLog(a, &events, "POSE").ok());
  ASSERT_EQ(events.size(), 10u);
  EXPECT_EQ(events[3].timestamp, 3000);
  mbslam::pose_t pose;
  ASSERT_EQ(pose.decode(events[3].data.data(), 0, static_cast<int>(events[3].data.size())),
            static_cast<int>(events[3].data.size()));
  EXPECT_EQ(pose.position[0], 3.0);
}

TEST(LcmLog, MissingFileIsAnError) {
  std::vector<LcmLogEvent> events;
  EXPECT_FALSE(ReadLcmLog("/nonexistent/x.lcmlog", &events).ok());
}

}  // namespace
}  // namespace mbslam
