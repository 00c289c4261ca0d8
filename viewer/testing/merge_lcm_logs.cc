// Merges LCM logs by event timestamp into one, so that a lockstep replay's output log
// (stamped with message time) and the input log it was made from (camera images) can
// be rendered together by `viewer --lcm-url file://MERGED?speed=0`. Events with equal
// timestamps keep the order of the inputs on the command line.
//
//   merge_lcm_logs OUT.lcmlog IN1.lcmlog IN2.lcmlog ... [--channels REGEX_FREE_LIST]
//
// --channels A,B,C keeps only those channels (exact names).

#include <algorithm>
#include <cstdio>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "common/lcm/lcm_log.h"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: merge_lcm_logs OUT.lcmlog IN.lcmlog... [--channels A,B,...]\n");
    return 2;
  }
  const std::string out = argv[1];
  std::vector<std::string> inputs;
  std::set<std::string> keep;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--channels" && i + 1 < argc) {
      std::stringstream list(argv[++i]);
      std::string name;
      while (std::getline(list, name, ',')) {
        if (!name.empty()) keep.insert(name);
      }
    } else {
      inputs.push_back(a);
    }
  }
  struct Item {
    mbslam::LcmLogEvent event;
    size_t input = 0, index = 0;
  };
  std::vector<Item> items;
  for (size_t k = 0; k < inputs.size(); ++k) {
    std::vector<mbslam::LcmLogEvent> events;
    const mbslam::Status s = mbslam::ReadLcmLog(inputs[k], &events);
    if (!s.ok()) {
      std::fprintf(stderr, "merge_lcm_logs: %s\n", s.message().c_str());
      return 1;
    }
    for (size_t i = 0; i < events.size(); ++i) {
      if (!keep.empty() && !keep.count(events[i].channel)) continue;
      items.push_back({std::move(events[i]), k, i});
    }
  }
  std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    if (a.event.timestamp != b.event.timestamp) return a.event.timestamp < b.event.timestamp;
    return a.input < b.input;
  });
  mbslam::Status s;
  auto writer = mbslam::LcmLogWriter::Open(out, &s);
  if (!writer) {
    std::fprintf(stderr, "merge_lcm_logs: %s\n", s.message().c_str());
    return 1;
  }
  for (const Item& item : items) {
    s = writer->WriteRaw(item.event.channel, item.event.timestamp, item.event.data.data(),
                         item.event.data.size());
    if (!s.ok()) {
      std::fprintf(stderr, "merge_lcm_logs: %s\n", s.message().c_str());
      return 1;
    }
  }
  writer->Flush();
  std::printf("%s: %zu events from %zu logs\n", out.c_str(), items.size(), inputs.size());
  return 0;
}
