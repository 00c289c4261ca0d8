#include "common/lcm/lcm_bus.h"

#include <cstdio>
#include <cstdlib>

#include "common/lcm/channels.h"
#include "common/util/logging.h"

namespace mbslam {

bool ChannelOptions::Check() const {
  for (const std::string* name :
       {&camera_image, &camera_calibration, &odometry, &ground_truth, &perception_camera_pose,
        &perception_objects, &perception_map, &perception_occupancy, &perception_tracks,
        &perception_status, &snapshot_request}) {
    MBSLAM_CHECK_OPTION(IsValidChannelName(*name));
  }
  return true;
}

bool IsValidChannelName(const std::string& name) {
  if (name.empty() || name.size() > 63) return false;
  for (char c : name) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '/';
    if (!ok) return false;
  }
  return true;
}

bool LcmBus::UrlLeavesHost(const std::string& url) {
  std::string effective = url;
  if (effective.empty()) {
    const char* env = std::getenv("LCM_DEFAULT_URL");
    effective = env ? env : "";
  }
  if (effective.empty()) return false;  // LCM's default udpm URL uses ttl=0
  if (effective.rfind("udpm://", 0) != 0) return false;
  // Every "ttl=<value>" option (after '?' or '&'): LCM applies them in order, so any
  // one above zero is reported. Parsed with strtol (atoi was undefined on overflow).
  bool leaves = false;
  for (size_t pos = effective.find("ttl="); pos != std::string::npos; pos = effective.find("ttl=", pos + 1)) {
    if (pos == 0 || (effective[pos - 1] != '?' && effective[pos - 1] != '&')) continue;
    const long ttl = std::strtol(effective.c_str() + pos + 4, nullptr, 10);
    leaves = leaves || ttl > 0;
  }
  return leaves;
}

std::string LcmBus::ExposureWarning(const std::string& url) {
  if (!UrlLeavesHost(url)) return "";
  const std::string shown = url.empty() ? "LCM_DEFAULT_URL=" + std::string(std::getenv("LCM_DEFAULT_URL")) : url;
  return "WARNING: LCM URL '" + shown +
         "' has ttl > 0: messages leave this host, and LCM has no authentication (anyone on "
         "the network can read them and inject inputs); use ttl=0 unless the network is trusted";
}

std::unique_ptr<LcmBus> LcmBus::Create(const std::string& url, Status* status) {
  // Printed before opening, whatever the log level: it is about who else can read and
  // send messages, and it is the configuration that is exposed even if opening fails.
  const std::string warning = ExposureWarning(url);
  if (!warning.empty()) std::fputs((warning + "\n").c_str(), stderr);
  auto lcm = std::make_unique<lcm::LCM>(url);
  if (!lcm->good()) {
    *status = Status::Error("cannot open LCM with URL '" + url +
                            "' (for udpm:// check that a multicast route exists; "
                            "for file:// that the log exists)");
    return nullptr;
  }
  *status = Status::Ok();
  return std::unique_ptr<LcmBus>(new LcmBus(std::move(lcm), url));
}

LcmBus::LcmBus(std::unique_ptr<lcm::LCM> lcm, std::string url)
    : lcm_(std::move(lcm)), url_(std::move(url)) {}

LcmBus::~LcmBus() {
  for (lcm_subscription_t* h : handles_) lcm_unsubscribe(lcm_->getUnderlyingLCM(), h);
}

void LcmBus::Dispatch(const lcm_recv_buf_t* rbuf, const char* channel, void* user) {
  auto* sub = static_cast<Subscription*>(user);
  // LCM subscriptions are regular expressions anchored at both ends; an exact name
  // never matches another channel, but check anyway.
  if (sub->channel != channel) return;
  try {
    sub->handler(sub->channel, static_cast<const uint8_t*>(rbuf->data), rbuf->data_size,
                 rbuf->recv_utime);
  } catch (const std::exception& e) {
    // Handlers must not throw; one that does must not take the process down.
    MBSLAM_LOG(ERROR) << "handler for " << sub->channel << " threw: " << e.what();
  }
}

void LcmBus::Subscribe(const std::string& channel, RawHandler handler, int queue_capacity) {
  subscriptions_.push_back(Subscription{channel, std::move(handler)});
  lcm_subscription_t* h = lcm_subscribe(lcm_->getUnderlyingLCM(), channel.c_str(),
                                        &LcmBus::Dispatch, &subscriptions_.back());
  if (h != nullptr) {
    lcm_subscription_set_queue_capacity(h, queue_capacity);
    handles_.push_back(h);
  } else {
    MBSLAM_LOG(ERROR) << "cannot subscribe to " << channel;
  }
}

int LcmBus::HandleTimeout(int timeout_ms) { return lcm_->handleTimeout(timeout_ms); }

}  // namespace mbslam
