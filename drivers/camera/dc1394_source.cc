#include "drivers/camera/dc1394_source.h"

#include <dc1394/dc1394.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <mutex>
#include <sstream>
#include <vector>

#include "common/util/logging.h"
#include "common/util/shutdown.h"
#include "common/util/time.h"
#include "drivers/camera/dc1394_modes.h"

namespace mbslam {
namespace {

// libdc1394 prints its errors to stderr; route them to our log at debug level so the
// driver's own one-line message is what the user sees.
void Dc1394LogHandler(dc1394log_t type, const char* message, void* /*user*/) {
  if (type == DC1394_LOG_DEBUG) return;
  MBSLAM_LOG(DEBUG) << "libdc1394: " << (message ? message : "");
}

void QuietLibdc1394() {
  static std::once_flag once;
  std::call_once(once, [] {
    dc1394_log_register_handler(DC1394_LOG_ERROR, Dc1394LogHandler, nullptr);
    dc1394_log_register_handler(DC1394_LOG_WARNING, Dc1394LogHandler, nullptr);
  });
}

int CountFirewireNodes() {
  int n = 0;
  std::error_code ec;
  for (std::filesystem::directory_iterator it("/dev", ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().filename().string().rfind("fw", 0) == 0) ++n;
  }
  return n;
}

std::string NoCameraMessage() {
  const int nodes = CountFirewireNodes();
  if (nodes == 0) {
    return "no IEEE 1394 camera: no FireWire bus on this machine (no /dev/fw* device nodes)";
  }
  return "no IEEE 1394 camera on the FireWire bus (" + std::to_string(nodes) +
         " /dev/fw* nodes, none of them an IIDC camera; check cable and power)";
}

std::string ErrorText(dc1394error_t err) {
  const char* s = dc1394_error_get_string(err);
  return s ? s : "error " + std::to_string(static_cast<int>(err));
}

}  // namespace

struct Dc1394Source::Impl {
  dc1394_t* context = nullptr;
  dc1394camera_t* camera = nullptr;
  bool capturing = false;
  bool transmitting = false;
  int fd = -1;
  uint64_t guid = 0;
  int64_t last_frame_mono_us = 0;

  ~Impl() { Release(); }
  void Release() {
    if (camera != nullptr) {
      if (transmitting) dc1394_video_set_transmission(camera, DC1394_OFF);
      if (capturing) dc1394_capture_stop(camera);
      dc1394_camera_free(camera);
    }
    if (context != nullptr) dc1394_free(context);
    camera = nullptr;
    context = nullptr;
    capturing = transmitting = false;
    fd = -1;
  }
};

Dc1394Source::Dc1394Source(Dc1394Options options) : options_(std::move(options)) {}

Dc1394Source::~Dc1394Source() { Close(); }

void Dc1394Source::Close() { impl_.reset(); }

SourceStatus Dc1394Source::Open() {
  Close();
  QuietLibdc1394();
  // Validate the names before touching the bus, so a typo is a config error.
  dc1394video_mode_t mode = DC1394_VIDEO_MODE_640x480_MONO8;
  const bool keep_mode = options_.video_mode.empty();
  if (!keep_mode) {
    const Status st = ParseDc1394VideoMode(options_.video_mode, &mode);
    if (!st.ok()) return SourceStatus::Error(SourceError::kConfig, st.message());
  }
  dc1394framerate_t rate = DC1394_FRAMERATE_30;
  dc1394speed_t speed = DC1394_ISO_SPEED_400;
  dc1394color_coding_t f7_coding = DC1394_COLOR_CODING_MONO8;
  uint64_t wanted_guid = 0;
  for (const Status& st :
       {keep_mode || IsDc1394Format7(mode) ? Status::Ok() : ParseDc1394Framerate(options_.framerate, &rate),
        ParseDc1394IsoSpeed(options_.iso_speed, &speed),
        ParseDc1394ColorCoding(options_.format7_color_coding, &f7_coding),
        options_.guid.empty() ? Status::Ok() : ParseDc1394Guid(options_.guid, &wanted_guid)}) {
    if (!st.ok()) return SourceStatus::Error(SourceError::kConfig, st.message());
  }

  auto impl = std::make_unique<Impl>();
  impl->context = dc1394_new();
  if (impl->context == nullptr) {
    return SourceStatus::Error(SourceError::kNoCamera,
                               "no IEEE 1394 camera: libdc1394 cannot start (no FireWire support)");
  }
  dc1394camera_list_t* list = nullptr;
  const dc1394error_t enum_err = dc1394_camera_enumerate(impl->context, &list);
  if (enum_err != DC1394_SUCCESS || list == nullptr) {
    return SourceStatus::Error(SourceError::kNoCamera,
                               "no IEEE 1394 camera: enumeration failed (" + ErrorText(enum_err) + ")");
  }
  std::vector<uint64_t> guids;
  for (uint32_t i = 0; i < list->num; ++i) guids.push_back(list->ids[i].guid);
  dc1394_camera_free_list(list);
  if (guids.empty()) return SourceStatus::Error(SourceError::kNoCamera, NoCameraMessage());
  if (options_.guid.empty()) {
    impl->guid = guids.front();
  } else if (std::find(guids.begin(), guids.end(), wanted_guid) != guids.end()) {
    impl->guid = wanted_guid;
  } else {
    std::string found;
    for (uint64_t g : guids) found += (found.empty() ? "" : ", ") + FormatDc1394Guid(g);
    return SourceStatus::Error(SourceError::kNoCamera, "no IEEE 1394 camera with GUID " +
                                                           FormatDc1394Guid(wanted_guid) +
                                                           " (found: " + found + ")");
  }
  const std::string name = "IEEE 1394 camera " + FormatDc1394Guid(impl->guid);
  impl->camera = dc1394_camera_new(impl->context, impl->guid);
  if (impl->camera == nullptr) {
    return SourceStatus::Error(SourceError::kAccess,
                               "cannot open " + name + " (permissions on /dev/fw*?)");
  }
  dc1394camera_t* cam = impl->camera;
  if (options_.reset_bus) dc1394_reset_bus(cam);

  if (options_.iso_speed > 400) {
    if (dc1394_video_set_operation_mode(cam, DC1394_OPERATION_MODE_1394B) != DC1394_SUCCESS) {
      return SourceStatus::Error(SourceError::kBadMode,
                                 name + " does not support 1394b, needed for " +
                                     std::to_string(options_.iso_speed) + " Mb/s");
    }
  }
  if (dc1394_video_set_iso_speed(cam, speed) != DC1394_SUCCESS) {
    return SourceStatus::Error(SourceError::kBadMode, name + " refuses ISO speed " +
                                                          std::to_string(options_.iso_speed) + " Mb/s");
  }
  if (keep_mode) {
    if (dc1394_video_get_mode(cam, &mode) != DC1394_SUCCESS) {
      return SourceStatus::Error(SourceError::kIo, "cannot read the video mode of " + name);
    }
  } else {
    dc1394video_modes_t modes;
    if (dc1394_video_get_supported_modes(cam, &modes) != DC1394_SUCCESS) {
      return SourceStatus::Error(SourceError::kIo, "cannot list the video modes of " + name);
    }
    bool supported = false;
    std::string names;
    for (uint32_t i = 0; i < modes.num; ++i) {
      supported |= modes.modes[i] == mode;
      names += (names.empty() ? "" : " ") + Dc1394VideoModeName(modes.modes[i]);
    }
    if (!supported) {
      return SourceStatus::Error(SourceError::kBadMode, name + " does not support video mode " +
                                                            options_.video_mode +
                                                            " (supported: " + names + ")");
    }
    if (dc1394_video_set_mode(cam, mode) != DC1394_SUCCESS) {
      return SourceStatus::Error(SourceError::kBadMode,
                                 name + " refused video mode " + options_.video_mode);
    }
  }
  if (IsDc1394Format7(mode)) {
    dc1394color_codings_t codings;
    uint32_t max_w = 0, max_h = 0;
    bool coding_ok = false;
    if (dc1394_format7_get_color_codings(cam, mode, &codings) == DC1394_SUCCESS) {
      for (uint32_t i = 0; i < codings.num; ++i) coding_ok |= codings.codings[i] == f7_coding;
    }
    if (!coding_ok) {
      return SourceStatus::Error(SourceError::kBadMode,
                                 name + " does not offer colour coding " +
                                     options_.format7_color_coding + " in " +
                                     Dc1394VideoModeName(mode));
    }
    if (dc1394_format7_get_max_image_size(cam, mode, &max_w, &max_h) != DC1394_SUCCESS ||
        dc1394_format7_set_roi(cam, mode, f7_coding, DC1394_USE_RECOMMENDED, 0, 0,
                               static_cast<int32_t>(max_w), static_cast<int32_t>(max_h)) !=
            DC1394_SUCCESS) {
      return SourceStatus::Error(SourceError::kBadMode,
                                 name + " refused the full-size ROI of " + Dc1394VideoModeName(mode));
    }
  } else if (!keep_mode) {
    dc1394framerates_t rates;
    if (dc1394_video_get_supported_framerates(cam, mode, &rates) != DC1394_SUCCESS) {
      return SourceStatus::Error(SourceError::kIo, "cannot list the frame rates of " + name);
    }
    bool supported = false;
    std::ostringstream names;
    for (uint32_t i = 0; i < rates.num; ++i) {
      supported |= rates.framerates[i] == rate;
      names << (i ? " " : "") << Dc1394FramerateHz(rates.framerates[i]);
    }
    if (!supported) {
      std::ostringstream msg;
      msg << name << " does not support " << options_.framerate << " Hz in "
          << Dc1394VideoModeName(mode) << " (supported: " << names.str() << " Hz)";
      return SourceStatus::Error(SourceError::kBadMode, msg.str());
    }
    if (dc1394_video_set_framerate(cam, rate) != DC1394_SUCCESS) {
      return SourceStatus::Error(SourceError::kBadMode, name + " refused the frame rate");
    }
  }
  const dc1394error_t setup =
      dc1394_capture_setup(cam, static_cast<uint32_t>(options_.dma_buffers), DC1394_CAPTURE_FLAGS_DEFAULT);
  if (setup != DC1394_SUCCESS) {
    return SourceStatus::Error(SourceError::kAccess,
                               "cannot start capture on " + name + " (" + ErrorText(setup) +
                                   "; bandwidth or ISO channel taken? try dc1394.reset_bus)");
  }
  impl->capturing = true;
  if (dc1394_video_set_transmission(cam, DC1394_ON) != DC1394_SUCCESS) {
    return SourceStatus::Error(SourceError::kIo, "cannot start transmission on " + name);
  }
  impl->transmitting = true;
  impl->fd = dc1394_capture_get_fileno(cam);
  impl->last_frame_mono_us = MonotonicUtime();
  std::ostringstream desc;
  desc << name << " (" << (cam->vendor ? cam->vendor : "") << " " << (cam->model ? cam->model : "")
       << ", " << Dc1394VideoModeName(mode);
  if (!IsDc1394Format7(mode) && !keep_mode) desc << " @ " << options_.framerate << " Hz";
  desc << ", " << options_.iso_speed << " Mb/s)";
  description_ = desc.str();
  impl_ = std::move(impl);
  return SourceStatus::Ok();
}

FrameSource::ReadResult Dc1394Source::Next(Frame* frame, SourceStatus* status) {
  if (!impl_) {
    *status = SourceStatus::Error(SourceError::kDisconnected, "IEEE 1394 camera not open");
    return ReadResult::kError;
  }
  const int64_t timeout_us = SecondsToUtime(options_.frame_timeout_s);
  dc1394video_frame_t* captured = nullptr;
  while (captured == nullptr) {
    if (ShutdownRequested()) return ReadResult::kEnd;
    const int64_t waited = MonotonicUtime() - impl_->last_frame_mono_us;
    if (waited > timeout_us) {
      std::ostringstream msg;
      msg << description_ << ": no frame for " << options_.frame_timeout_s
          << " s (unplugged or stalled)";
      *status = SourceStatus::Error(SourceError::kDisconnected, msg.str());
      return ReadResult::kError;
    }
    if (impl_->fd >= 0) {
      pollfd pfd{impl_->fd, POLLIN, 0};
      const int ready = poll(&pfd, 1, 100);
      if (ready < 0 && errno != EINTR) {
        *status = SourceStatus::Error(SourceError::kDisconnected, description_ + ": poll failed");
        return ReadResult::kError;
      }
      if (ready > 0 && (pfd.revents & (POLLERR | POLLHUP | POLLNVAL))) {
        *status = SourceStatus::Error(SourceError::kDisconnected,
                                      description_ + ": device gone (unplugged)");
        return ReadResult::kError;
      }
      if (ready <= 0) continue;
    } else {
      usleep(2000);
    }
    const dc1394error_t err =
        dc1394_capture_dequeue(impl_->camera, DC1394_CAPTURE_POLICY_POLL, &captured);
    if (err != DC1394_SUCCESS) {
      *status = SourceStatus::Error(SourceError::kDisconnected,
                                    description_ + ": capture failed (" + ErrorText(err) + ")");
      return ReadResult::kError;
    }
  }
  impl_->last_frame_mono_us = MonotonicUtime();
  *frame = Frame();
  frame->index = next_index_++;
  frame->origin = "frame " + std::to_string(frame->index);
  frame->utime = options_.hardware_timestamps && captured->timestamp > 0
                     ? static_cast<int64_t>(captured->timestamp)
                     : WallUtime();
  Status converted = Status::Ok();
  if (dc1394_capture_is_frame_corrupt(impl_->camera, captured) == DC1394_TRUE) {
    converted = Status::Error("corrupt frame (lost packets)");
  } else {
    converted = ConvertDc1394Frame(*captured, options_.bayer_pattern, &frame->image);
  }
  if (captured->frames_behind > static_cast<uint32_t>(options_.dma_buffers) / 2) {
    MBSLAM_LOG(WARNING) << description_ << ": " << captured->frames_behind
                        << " frames waiting in the DMA ring (falling behind)";
  }
  dc1394_capture_enqueue(impl_->camera, captured);
  if (!converted.ok()) {
    *status = SourceStatus::Error(SourceError::kIo, description_ + " " + frame->origin + ": " +
                                                        converted.message());
    return ReadResult::kBadFrame;
  }
  *status = SourceStatus::Ok();
  return ReadResult::kFrame;
}

int ListDc1394Cameras(std::string* report) {
  QuietLibdc1394();
  std::ostringstream out;
  dc1394_t* context = dc1394_new();
  if (context == nullptr) {
    *report = "libdc1394 cannot start (no FireWire support)\n";
    return -1;
  }
  dc1394camera_list_t* list = nullptr;
  if (dc1394_camera_enumerate(context, &list) != DC1394_SUCCESS || list == nullptr) {
    dc1394_free(context);
    *report = "IEEE 1394 enumeration failed\n";
    return -1;
  }
  const int num = static_cast<int>(list->num);
  if (num == 0) out << NoCameraMessage() << "\n";
  for (uint32_t i = 0; i < list->num; ++i) {
    const uint64_t guid = list->ids[i].guid;
    out << FormatDc1394Guid(guid);
    dc1394camera_t* cam = dc1394_camera_new(context, guid);
    if (cam == nullptr) {
      out << "  (cannot open)\n";
      continue;
    }
    out << "  " << (cam->vendor ? cam->vendor : "") << " " << (cam->model ? cam->model : "")
        << "\n";
    dc1394video_modes_t modes;
    if (dc1394_video_get_supported_modes(cam, &modes) == DC1394_SUCCESS) {
      for (uint32_t m = 0; m < modes.num; ++m) {
        out << "    " << Dc1394VideoModeName(modes.modes[m]);
        dc1394framerates_t rates;
        if (!IsDc1394Format7(modes.modes[m]) &&
            dc1394_video_get_supported_framerates(cam, modes.modes[m], &rates) == DC1394_SUCCESS) {
          out << " @";
          for (uint32_t r = 0; r < rates.num; ++r) out << " " << Dc1394FramerateHz(rates.framerates[r]);
          out << " Hz";
        }
        out << "\n";
      }
    }
    dc1394_camera_free(cam);
  }
  dc1394_camera_free_list(list);
  dc1394_free(context);
  *report = out.str();
  return num;
}

}  // namespace mbslam
