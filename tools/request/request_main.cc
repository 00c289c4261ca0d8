// mbslam-request: sends one SNAPSHOT_REQUEST (snapshot_request_t) to the perception
// service and the viewer, as an operator or a script does during a run:
//
//   mbslam-request --lcm-url 'udpm://239.255.76.67:7667?ttl=0' --global-ba
//   mbslam-request --outputs --prefix run1      # the service writes its outputs now
//   mbslam-request --views --prefix snap        # the viewer renders its PNGs now
//
// Exit status: 0 sent, 2 bad command line or the bus could not be opened or written.

#include <cstdio>
#include <exception>
#include <iostream>
#include <memory>
#include <string>

#include "common/lcm/channels.h"
#include "common/lcm/lcm_bus.h"
#include "common/util/command_line.h"
#include "common/util/time.h"
#include "mbslam/snapshot_request_t.hpp"

namespace {

constexpr char kUsage[] =
    "usage: mbslam-request [--lcm-url URL] [--channel NAME] [--prefix DIR]\n"
    "         (--global-ba | --outputs | --views | --view-3d | --view-image)...\n"
    "  --lcm-url     where to publish (default: LCM_DEFAULT_URL, else LCM's own default);\n"
    "                file://LOG?mode=w writes the request into a log\n"
    "  --channel     the request channel (default SNAPSHOT_REQUEST)\n"
    "  --prefix      a folder under the receiver's output directory (default: that\n"
    "                directory itself); absolute paths and '..' are refused by the receiver\n"
    "  --global-ba   the service adjusts its whole static map (bundle adjustment in its\n"
    "                back end, started at the next image; counted as slam_global_ba_started)\n"
    "  --outputs     the service writes trajectories, map PLY, occupancy .bt and summary now\n"
    "  --views       the viewer renders both PNG views now (--view-3d, --view-image: one)\n"
    "Sent is not received: LCM does not acknowledge. --global-ba with --outputs writes the\n"
    "outputs before the adjustment has run.\n"
    "exit status: 0 sent, 2 bad command line or bus error\n";

int Run(int argc, char** argv) {
  const mbslam::CommandLineArgs args(argc, argv);
  if (args.Has("help")) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  // The flags take no value ('--outputs run1' is a mistake for '--outputs --prefix run1'),
  // the options one.
  std::string flag_with_value;
  for (const char* flag : {"global-ba", "outputs", "views", "view-3d", "view-image"}) {
    for (const std::string& v : args.GetAll(flag)) {
      if (!v.empty() && flag_with_value.empty())
        flag_with_value = std::string("--") + flag + " takes no value";
    }
  }
  for (const char* option : {"lcm-url", "channel", "prefix"}) {
    if (args.Has(option) && args.Get(option).empty() && flag_with_value.empty())
      flag_with_value = std::string("--") + option + " needs a value";
  }
  int what = 0;
  if (args.Has("global-ba")) what |= mbslam::snapshot_request_t::WHAT_GLOBAL_BA;
  if (args.Has("outputs")) what |= mbslam::snapshot_request_t::WHAT_OUTPUTS;
  if (args.Has("views") || args.Has("view-3d")) what |= mbslam::snapshot_request_t::WHAT_VIEW_3D;
  if (args.Has("views") || args.Has("view-image"))
    what |= mbslam::snapshot_request_t::WHAT_VIEW_IMAGE;
  const std::string url = args.Get("lcm-url");
  const std::string channel = args.Get("channel", mbslam::ChannelOptions().snapshot_request);
  const std::string prefix = args.Get("prefix");
  const std::string problems = args.Problems();
  if (!problems.empty() || !flag_with_value.empty() || what == 0) {
    const std::string why = !problems.empty()          ? problems
                            : !flag_with_value.empty() ? flag_with_value
                                                       : "nothing asked for";
    std::fprintf(stderr, "mbslam-request: %s\n%s", why.c_str(), kUsage);
    return 2;
  }
  mbslam::Status status;
  std::unique_ptr<mbslam::LcmBus> bus = mbslam::LcmBus::Create(url, &status);
  if (!bus) {
    std::fprintf(stderr, "mbslam-request: %s\n", status.message().c_str());
    return 2;
  }
  mbslam::snapshot_request_t msg{};
  msg.utime = mbslam::WallUtime();
  msg.path_prefix = prefix;
  msg.what = static_cast<int8_t>(what);
  if (bus->Publish(channel, msg) != 0) {
    std::fprintf(stderr, "mbslam-request: publishing on %s failed\n", channel.c_str());
    return 2;
  }
  std::printf("sent %s: what %d%s%s\n", channel.c_str(), what, prefix.empty() ? "" : ", prefix ",
              prefix.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "mbslam-request: unexpected error: " << e.what() << "\n";
    return 2;
  }
}
