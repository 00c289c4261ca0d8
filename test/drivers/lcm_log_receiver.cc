// lcm_log_receiver: subscribes to one channel of an LCM URL and checks that every
// message of that channel in a reference log arrives, in order and byte for byte.
//
//   lcm_log_receiver --url URL --log REF.lcmlog --channel CAMERA_IMAGE
//                    [--ready FILE] [--timeout S]
//
// Touches FILE once subscribed (so a script can start the player), exits 0 when all
// messages arrived identical, 1 on a mismatch or a timeout, 2 on bad arguments.

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "common/lcm/lcm_bus.h"
#include "common/lcm/lcm_log.h"
#include "common/lcm/wire_check.h"
#include "common/util/time.h"
#include "drivers/common/command_line.h"
#include "mbslam/image_t.hpp"

int main(int argc, char** argv) {
  using namespace mbslam;
  CommandLine cl;
  Status st = CommandLine::Parse(argc, argv, {}, {"url", "log", "channel", "ready", "timeout"}, &cl);
  if (!st.ok() || !cl.Has("url") || !cl.Has("log")) {
    std::fprintf(stderr, "lcm_log_receiver: %s\n", st.ok() ? "--url and --log needed" : st.message().c_str());
    return 2;
  }
  const std::string channel = cl.Get("channel", "CAMERA_IMAGE");
  double timeout_s = 30.0;
  if (cl.Has("timeout") && !ParseDouble(cl.Get("timeout"), "--timeout", &timeout_s).ok()) return 2;
  std::vector<LcmLogEvent> expected;
  st = ReadLcmLog(cl.Get("log"), &expected, channel);
  if (!st.ok() || expected.empty()) {
    std::fprintf(stderr, "lcm_log_receiver: no %s messages in %s\n", channel.c_str(), cl.Get("log").c_str());
    return 2;
  }
  std::unique_ptr<LcmBus> bus = LcmBus::Create(cl.Get("url"), &st);
  if (!bus) {
    std::fprintf(stderr, "lcm_log_receiver: %s\n", st.message().c_str());
    return 1;
  }
  size_t received = 0, identical = 0, unexpected = 0;
  int64_t last_seq = -1;
  bool seq_ok = true;
  bus->Subscribe(
      channel,
      [&](const std::string&, const uint8_t* data, size_t size, int64_t) {
        if (received >= expected.size()) {
          ++unexpected;
          return;
        }
        const std::vector<uint8_t>& want = expected[received].data;
        if (size == want.size() && std::equal(data, data + size, want.begin())) ++identical;
        mbslam::image_t image{};
        if (DecodeLcmMessage(data, size, &image).ok()) {
          if (image.seq != last_seq + 1) seq_ok = false;
          last_seq = image.seq;
        }
        ++received;
      },
      static_cast<int>(expected.size()) + 16);
  if (cl.Has("ready")) std::ofstream(cl.Get("ready")) << "subscribed\n";
  const int64_t deadline = MonotonicUtime() + SecondsToUtime(timeout_s);
  while (received < expected.size() && MonotonicUtime() < deadline) bus->HandleTimeout(100);
  // Anything extra that arrives shortly after is an error too.
  const int64_t linger = MonotonicUtime() + 200000;
  while (MonotonicUtime() < linger) bus->HandleTimeout(50);
  std::printf("lcm_log_receiver: %zu/%zu messages on %s, %zu byte-identical, %zu unexpected, seq %s\n",
              received, expected.size(), channel.c_str(), identical, unexpected,
              seq_ok ? "contiguous" : "with gaps");
  return received == expected.size() && identical == expected.size() && unexpected == 0 && seq_ok ? 0 : 1;
}
