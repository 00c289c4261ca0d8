#ifndef MBSLAM_COMMON_LCM_LCM_BUS_H_
#define MBSLAM_COMMON_LCM_LCM_BUS_H_

// A small interface over LCM. One LcmBus per process (memq:// is one bus per instance).
// URLs: memq:// (in process, tests), file://LOG?speed=0 (replay), file://LOG?mode=w
// (record), udpm://ADDR:PORT?ttl=0 (live; multicast stays on this host with ttl=0).

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "common/util/status.h"

namespace mbslam {

class LcmBus {
 public:
  // Raw message callback: the undecoded bytes and the receive time (µs, wall clock
  // for live transports, the log's timestamp for file://).
  using RawHandler = std::function<void(const std::string& channel, const uint8_t* data,
                                        size_t size, int64_t recv_utime)>;

  // Opens the bus. An empty URL means LCM's default (env LCM_DEFAULT_URL, else udpm).
  // Prints ExposureWarning(url) on stderr, whatever the log level, when there is one.
  static std::unique_ptr<LcmBus> Create(const std::string& url, Status* status);

  ~LcmBus();
  LcmBus(const LcmBus&) = delete;
  LcmBus& operator=(const LcmBus&) = delete;

  // Subscribes to one channel (exact name, not a pattern). queue_capacity bounds the
  // messages LCM buffers for this subscription before it drops (LCM's default is 30).
  void Subscribe(const std::string& channel, RawHandler handler, int queue_capacity = 30);

  // Thread-safe.
  template <typename Msg>
  int Publish(const std::string& channel, const Msg& msg) {
    std::lock_guard<std::mutex> lock(publish_mutex_);
    return lcm_->publish(channel, &msg);
  }
  int PublishRaw(const std::string& channel, const void* data, unsigned size) {
    std::lock_guard<std::mutex> lock(publish_mutex_);
    return lcm_->publish(channel, data, size);
  }

  // Dispatches at most one message. Returns > 0 if one was handled, 0 on timeout,
  // < 0 on error or at the end of a file:// log.
  int HandleTimeout(int timeout_ms);

  const std::string& url() const { return url_; }
  lcm::LCM& lcm() { return *lcm_; }

  // True when the URL ("" = LCM_DEFAULT_URL) is udpm:// with a ttl > 0: multicast
  // leaves this host.
  static bool UrlLeavesHost(const std::string& url);
  // The stderr warning for such a URL (LCM has no authentication: who can reach the
  // network can read every message and inject inputs); "" for a URL that stays local.
  static std::string ExposureWarning(const std::string& url);

 private:
  struct Subscription {
    std::string channel;
    RawHandler handler;
  };
  LcmBus(std::unique_ptr<lcm::LCM> lcm, std::string url);
  static void Dispatch(const lcm_recv_buf_t* rbuf, const char* channel, void* user);

  std::unique_ptr<lcm::LCM> lcm_;
  std::string url_;
  std::mutex publish_mutex_;
  std::list<Subscription> subscriptions_;  // stable addresses for the C callback
  std::vector<lcm_subscription_t*> handles_;
};

}  // namespace mbslam

#endif  // MBSLAM_COMMON_LCM_LCM_BUS_H_
