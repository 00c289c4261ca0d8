// Test helper for the message-contract round trips between processes.
//
//   lcm_roundtrip_tool publish   URL SEED REPEATS   one random message of every type, REPEATS times
//   lcm_roundtrip_tool subscribe URL SEED REPEATS TIMEOUT_S
//                                                  waits for all of them; exit 0 iff every message
//                                                  arrived byte-identical
//   lcm_roundtrip_tool write-log FILE SEED REPEATS  the same messages as an LCM log
//
// Message i of type T is RandomLcmEncoding(T, seed + i) on channel RT_<T>.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "common/lcm/all_types.h"
#include "common/lcm/lcm_bus.h"
#include "common/lcm/lcm_log.h"
#include "common/lcm/wire_check.h"
#include "common/util/command_line.h"
#include "common/util/time.h"

namespace {

struct Expected {
  std::string channel;
  std::vector<std::vector<uint8_t>> messages;
};

std::vector<Expected> MakeExpected(uint32_t seed, int repeats) {
  std::vector<Expected> out;
#define MBSLAM_EXPECT(T)                                                                   \
  {                                                                                        \
    Expected e{"RT_" #T, {}};                                                              \
    for (int i = 0; i < repeats; ++i)                                                      \
      e.messages.push_back(mbslam::RandomLcmEncoding(mbslam::T::getTypeName(),             \
                                                     mbslam::T::getHash(), seed + i));     \
    out.push_back(e);                                                                      \
  }
  MBSLAM_FOR_EACH_LCM_TYPE(MBSLAM_EXPECT)
#undef MBSLAM_EXPECT
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: lcm_roundtrip_tool publish|subscribe|write-log URL|FILE SEED REPEATS [TIMEOUT_S]\n");
    return 2;
  }
  const std::string mode = argv[1];
  const std::string target = argv[2];
  int64_t seed_arg = 0, repeats_arg = 0;
  mbslam::Status parsed = mbslam::ParseInt64(argv[3], "SEED", &seed_arg);
  if (parsed.ok()) parsed = mbslam::ParseInt64(argv[4], "REPEATS", &repeats_arg);
  if (!parsed.ok() || seed_arg < 0 || seed_arg > 0xffffffffLL || repeats_arg < 1 || repeats_arg > 100000) {
    std::fprintf(stderr, "lcm_roundtrip_tool: %s\n",
                 parsed.ok() ? "SEED must be 0-4294967295, REPEATS 1-100000" : parsed.message().c_str());
    return 2;
  }
  const uint32_t seed = static_cast<uint32_t>(seed_arg);
  const int repeats = static_cast<int>(repeats_arg);
  const auto expected = MakeExpected(seed, repeats);

  if (mode == "write-log") {
    mbslam::Status status;
    auto log = mbslam::LcmLogWriter::Open(target, &status);
    if (!log) {
      std::fprintf(stderr, "%s\n", status.message().c_str());
      return 1;
    }
    int64_t t = 1000000;
    for (int i = 0; i < repeats; ++i) {
      for (const auto& e : expected) {
        log->WriteRaw(e.channel, t, e.messages[i].data(), e.messages[i].size());
        t += 2000;  // 500 messages per second of log time
      }
    }
    log->Flush();
    return 0;
  }

  mbslam::Status status;
  auto bus = mbslam::LcmBus::Create(target, &status);
  if (!bus) {
    std::fprintf(stderr, "%s\n", status.message().c_str());
    return 1;
  }
  if (mode == "publish") {
    for (int i = 0; i < repeats; ++i) {
      for (const auto& e : expected) {
        bus->PublishRaw(e.channel, e.messages[i].data(), static_cast<unsigned>(e.messages[i].size()));
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
    }
    return 0;
  }
  if (mode != "subscribe" || argc < 6) return 2;
  double timeout_s = 0.0;
  if (const mbslam::Status s = mbslam::ParseDouble(argv[5], "TIMEOUT_S", &timeout_s); !s.ok() || timeout_s <= 0.0) {
    std::fprintf(stderr, "lcm_roundtrip_tool: %s\n", s.ok() ? "TIMEOUT_S must be positive" : s.message().c_str());
    return 2;
  }
  std::map<std::string, std::vector<std::vector<uint8_t>>> received;
  for (const auto& e : expected) {
    bus->Subscribe(e.channel, [&](const std::string& ch, const uint8_t* d, size_t n, int64_t) {
      received[ch].emplace_back(d, d + n);
    }, 1000);
  }
  std::printf("ready\n");
  std::fflush(stdout);
  const int64_t deadline = mbslam::MonotonicUtime() + mbslam::SecondsToUtime(timeout_s);
  const size_t total = expected.size() * static_cast<size_t>(repeats);
  auto count = [&] {
    size_t n = 0;
    for (const auto& kv : received) n += kv.second.size();
    return n;
  };
  while (count() < total && mbslam::MonotonicUtime() < deadline) bus->HandleTimeout(100);
  int bad = 0;
  for (const auto& e : expected) {
    const auto& got = received[e.channel];
    if (got != e.messages) {
      std::fprintf(stderr, "%s: received %zu of %zu messages%s\n", e.channel.c_str(), got.size(),
                   e.messages.size(), got.size() == e.messages.size() ? " (bytes differ)" : "");
      ++bad;
    }
  }
  std::printf("received %zu of %zu messages, %d channels wrong\n", count(), total, bad);
  return bad == 0 ? 0 : 1;
}
