#include "common/lcm/lcm_bus.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <map>

#include "common/lcm/all_types.h"
#include "common/lcm/lcm_log.h"
#include "common/lcm/wire_check.h"
#include "common/testing/temp_dir.h"
#include "common/util/logging.h"

namespace mbslam {
namespace {

struct Sample {
  std::string channel;
  std::vector<uint8_t> bytes;
};

// One random valid message of every type, each on its own channel.
std::vector<Sample> AllSamples(uint32_t seed) {
  std::vector<Sample> samples;
#define MBSLAM_SAMPLE(T)                                                       \
  samples.push_back(Sample{"TEST_" #T, RandomLcmEncoding(mbslam::T::getTypeName(), \
                                                         mbslam::T::getHash(), seed)});
  MBSLAM_FOR_EACH_LCM_TYPE(MBSLAM_SAMPLE)
#undef MBSLAM_SAMPLE
  return samples;
}

TEST(LcmBus, EveryTypeRoundTripsThroughMemq) {
  Status status;
  auto bus = LcmBus::Create("memq://", &status);
  ASSERT_TRUE(bus) << status.message();
  const auto samples = AllSamples(7);
  std::map<std::string, std::vector<uint8_t>> received;
  for (const auto& s : samples) {
    bus->Subscribe(s.channel, [&](const std::string& ch, const uint8_t* d, size_t n, int64_t) {
      received[ch].assign(d, d + n);
    });
  }
  for (const auto& s : samples) {
    ASSERT_EQ(bus->PublishRaw(s.channel, s.bytes.data(), static_cast<unsigned>(s.bytes.size())), 0);
  }
  while (bus->HandleTimeout(0) > 0) {
  }
  ASSERT_EQ(received.size(), samples.size());
  for (const auto& s : samples) EXPECT_EQ(received[s.channel], s.bytes) << s.channel;
}

TEST(LcmBus, EveryTypeRoundTripsThroughFileLog) {
  const std::string log = testing_util::MakeTestTempPath("lcm", "roundtrip.lcmlog");
  const auto samples = AllSamples(11);
  {
    Status status;
    auto writer = LcmBus::Create("file://" + log + "?mode=w", &status);
    ASSERT_TRUE(writer) << status.message();
    for (const auto& s : samples) {
      writer->PublishRaw(s.channel, s.bytes.data(), static_cast<unsigned>(s.bytes.size()));
    }
  }
  Status status;
  auto reader = LcmBus::Create("file://" + log + "?speed=0", &status);
  ASSERT_TRUE(reader) << status.message();
  std::vector<Sample> received;
  for (const auto& s : samples) {
    reader->Subscribe(s.channel, [&](const std::string& ch, const uint8_t* d, size_t n, int64_t) {
      received.push_back(Sample{ch, std::vector<uint8_t>(d, d + n)});
    });
  }
  int guard = 0;
  while (reader->HandleTimeout(100) > 0 && ++guard < 1000) {
  }
  ASSERT_EQ(received.size(), samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    EXPECT_EQ(received[i].channel, samples[i].channel);
    EXPECT_EQ(received[i].bytes, samples[i].bytes);
  }
}

TEST(LcmBus, ThrowingHandlerDoesNotEscape) {
  Status status;
  auto bus = LcmBus::Create("memq://", &status);
  ASSERT_TRUE(bus);
  int calls = 0;
  bus->Subscribe("X", [&](const std::string&, const uint8_t*, size_t, int64_t) {
    ++calls;
    throw std::runtime_error("boom");
  });
  const char payload[] = "abc";
  bus->PublishRaw("X", payload, 3);
  EXPECT_NO_THROW(bus->HandleTimeout(0));
  EXPECT_EQ(calls, 1);
}

TEST(LcmBus, MissingLogIsAClearError) {
  Status status;
  auto bus = LcmBus::Create("file:///nonexistent/dir/x.lcmlog?speed=0", &status);
  EXPECT_FALSE(bus);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("nonexistent"), std::string::npos);
}

TEST(LcmBus, TtlAboveZeroIsDetected) {
  EXPECT_FALSE(LcmBus::UrlLeavesHost("udpm://239.255.76.67:7667?ttl=0"));
  EXPECT_TRUE(LcmBus::UrlLeavesHost("udpm://239.255.76.67:7667?ttl=1"));
  EXPECT_TRUE(LcmBus::UrlLeavesHost("udpm://239.255.76.67:7667?recv_buf_size=100&ttl=3"));
  EXPECT_FALSE(LcmBus::UrlLeavesHost("memq://"));
  EXPECT_FALSE(LcmBus::UrlLeavesHost("udpm://239.255.76.67:7667"));
  // LCM applies every ttl option in turn: any above zero counts.
  EXPECT_TRUE(LcmBus::UrlLeavesHost("udpm://239.255.76.67:7667?ttl=0&ttl=1"));
  EXPECT_FALSE(LcmBus::UrlLeavesHost("udpm://239.255.76.67:7667?ttl=-1"));
  EXPECT_FALSE(LcmBus::UrlLeavesHost("udpm://239.255.76.67:7667?xttl=5"));
  EXPECT_TRUE(LcmBus::UrlLeavesHost("udpm://239.255.76.67:7667?ttl=99999999999999999999"));
  EXPECT_FALSE(LcmBus::UrlLeavesHost("file:///tmp/x.lcmlog?ttl=1"));
}

TEST(LcmBus, ExposureWarningNamesTheUrlAndTheRisk) {
  EXPECT_EQ(LcmBus::ExposureWarning("udpm://239.255.76.67:7667?ttl=0"), "");
  EXPECT_EQ(LcmBus::ExposureWarning("memq://"), "");
  const std::string w = LcmBus::ExposureWarning("udpm://239.255.76.67:7667?ttl=1");
  EXPECT_NE(w.find("WARNING"), std::string::npos);
  EXPECT_NE(w.find("udpm://239.255.76.67:7667?ttl=1"), std::string::npos);
  EXPECT_NE(w.find("no authentication"), std::string::npos);
  EXPECT_NE(w.find("ttl=0"), std::string::npos);

  // An empty URL is LCM_DEFAULT_URL's.
  const char* saved = std::getenv("LCM_DEFAULT_URL");
  const std::string saved_value = saved ? saved : "";
  setenv("LCM_DEFAULT_URL", "udpm://239.255.76.67:7667?ttl=2", 1);
  EXPECT_NE(LcmBus::ExposureWarning("").find("LCM_DEFAULT_URL=udpm://239.255.76.67:7667?ttl=2"),
            std::string::npos);
  unsetenv("LCM_DEFAULT_URL");
  EXPECT_EQ(LcmBus::ExposureWarning(""), "");
  if (saved) setenv("LCM_DEFAULT_URL", saved_value.c_str(), 1);
}

// The warning goes to stderr before the bus opens, even when the log level hides
// warnings. (300.0.0.1 is not an address: LCM refuses the URL before it creates any
// socket, so the test stays off the network.)
TEST(LcmBus, CreateWarnsOnStderrWhateverTheLogLevel) {
  const LogLevel level = GetLogLevel();
  SetLogLevel(LogLevel::kError);
  testing::internal::CaptureStderr();
  Status status;
  auto bus = LcmBus::Create("udpm://300.0.0.1:7667?ttl=1", &status);
  const std::string err = testing::internal::GetCapturedStderr();
  SetLogLevel(level);
  EXPECT_FALSE(bus);
  EXPECT_NE(err.find("WARNING: LCM URL 'udpm://300.0.0.1:7667?ttl=1' has ttl > 0"), std::string::npos)
      << err;
}

TEST(LcmBus, CreatePrintsNoWarningForLocalUrls) {
  const LogLevel level = GetLogLevel();
  SetLogLevel(LogLevel::kError);
  testing::internal::CaptureStderr();
  Status status;
  auto bus = LcmBus::Create("memq://", &status);
  const std::string err = testing::internal::GetCapturedStderr();
  SetLogLevel(level);
  ASSERT_TRUE(bus);
  EXPECT_EQ(err, "");
}

}  // namespace
}  // namespace mbslam
