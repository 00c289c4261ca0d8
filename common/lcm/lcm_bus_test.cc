#include "common/lcm/lcm_bus.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <map>

#include "common/lcm/all_types.h"
#include "common/lcm/lcm_log.h"
#include "common/lcm/wire_check.h"

namespace mbslam {
namespace {

std::string TempPath(const std::string& name) {
  char pattern[] = "/tmp/mbslam_lcm_XXXXXX";
  return std::string(mkdtemp(pattern)) + "/" + name;
}

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
  const std::string log = TempPath("roundtrip.lcmlog");
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
}

}  // namespace
}  // namespace mbslam
