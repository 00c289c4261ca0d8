// mbslam-request end to end (file:// only): the request it publishes, read back from the
// log it writes, and its refusals.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "common/lcm/lcm_log.h"
#include "common/lcm/wire_check.h"
#include "mbslam/snapshot_request_t.hpp"
#include "test/tools/run_command.h"

namespace mbslam {
namespace {

namespace fs = std::filesystem;

// Runs the tool with `args`, writing into a fresh log; the requests in it.
int Request(const std::string& args, std::vector<mbslam::snapshot_request_t>* sent,
            std::vector<std::string>* channels = nullptr) {
  static int n = 0;
  const std::string log = ::testing::TempDir() + "/mbslam_request_" + std::to_string(::getpid()) +
                          "_" + std::to_string(n++) + ".lcmlog";
  fs::remove(log);
  std::string out;
  const int status =
      testing_util::RunCommand(testing_util::ToolPath("mbslam-request") + " --lcm-url 'file://" +
                                   log + "?mode=w' " + args + " 2>/dev/null",
                               &out);
  sent->clear();
  if (channels) channels->clear();
  std::vector<LcmLogEvent> events;
  if (fs::exists(log) && ReadLcmLog(log, &events).ok()) {
    for (const LcmLogEvent& e : events) {
      mbslam::snapshot_request_t m{};
      EXPECT_TRUE(DecodeLcmMessage(e.data.data(), e.data.size(), &m).ok());
      sent->push_back(m);
      if (channels) channels->push_back(e.channel);
    }
  }
  fs::remove(log);
  return status;
}

TEST(RequestCli, SendsWhatIsAskedFor) {
  std::vector<mbslam::snapshot_request_t> sent;
  std::vector<std::string> channels;
  ASSERT_EQ(Request("--global-ba", &sent, &channels), 0);
  ASSERT_EQ(sent.size(), 1u);
  EXPECT_EQ(channels[0], "SNAPSHOT_REQUEST");
  EXPECT_EQ(sent[0].what, mbslam::snapshot_request_t::WHAT_GLOBAL_BA);
  EXPECT_EQ(sent[0].path_prefix, "");
  EXPECT_GT(sent[0].utime, 0);
  ASSERT_EQ(Request("--outputs --views --prefix run1 --channel OTHER", &sent, &channels), 0);
  ASSERT_EQ(sent.size(), 1u);
  EXPECT_EQ(channels[0], "OTHER");
  EXPECT_EQ(sent[0].what, mbslam::snapshot_request_t::WHAT_OUTPUTS |
                              mbslam::snapshot_request_t::WHAT_VIEW_3D |
                              mbslam::snapshot_request_t::WHAT_VIEW_IMAGE);
  EXPECT_EQ(sent[0].path_prefix, "run1");
  ASSERT_EQ(Request("--view-image", &sent), 0);
  ASSERT_EQ(sent.size(), 1u);
  EXPECT_EQ(sent[0].what, mbslam::snapshot_request_t::WHAT_VIEW_IMAGE);
  ASSERT_EQ(Request("--view-3d", &sent), 0);
  ASSERT_EQ(sent.size(), 1u);
  EXPECT_EQ(sent[0].what, mbslam::snapshot_request_t::WHAT_VIEW_3D);
  std::string out;
  EXPECT_EQ(testing_util::RunCommand(testing_util::ToolPath("mbslam-request") + " --help", &out),
            0);
  EXPECT_NE(out.find("--global-ba"), std::string::npos);
}

TEST(RequestCli, RefusesAnEmptyOrUnknownRequest) {
  std::vector<mbslam::snapshot_request_t> sent;
  EXPECT_EQ(Request("", &sent), 2);
  EXPECT_TRUE(sent.empty());
  EXPECT_EQ(Request("--global-ba --global-bundle", &sent), 2);
  EXPECT_TRUE(sent.empty());
  EXPECT_EQ(Request("--outputs run1", &sent), 2) << "a flag with a value";
  EXPECT_TRUE(sent.empty());
  EXPECT_EQ(Request("--global-ba x", &sent), 2);
  EXPECT_TRUE(sent.empty());
  EXPECT_EQ(Request("--outputs run1 --outputs", &sent), 2) << "a value on either";
  EXPECT_TRUE(sent.empty());
  EXPECT_EQ(Request("--global-ba --channel ''", &sent), 2);
  EXPECT_TRUE(sent.empty());
  EXPECT_EQ(Request("--outputs --prefix", &sent), 2) << "an option without its value";
  EXPECT_TRUE(sent.empty());
  std::string out;
  EXPECT_EQ(testing_util::RunCommand(testing_util::ToolPath("mbslam-request") +
                                         " --lcm-url 'bogus://x' --global-ba 2>/dev/null",
                                     &out),
            2);
}

}  // namespace
}  // namespace mbslam
