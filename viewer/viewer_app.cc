#include "viewer/viewer_app.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "common/util/atomic_file.h"
#include "common/util/logging.h"
#include "common/util/shutdown.h"
#include "common/util/time.h"
#include "viewer/snapshot_files.h"

namespace mbslam {
namespace viewer {
namespace {

std::string JsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", static_cast<unsigned char>(c));
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string JsonTiming(const TimingSummary& t, double first_ms) {
  char buf[256];
  std::snprintf(buf, sizeof(buf),
                "{\"count\": %lld, \"first_ms\": %.3f, \"mean_ms\": %.3f, \"p50_ms\": %.3f, "
                "\"p99_ms\": %.3f, \"max_ms\": %.3f}",
                static_cast<long long>(t.count), first_ms, t.mean_ms, t.p50_ms, t.p99_ms, t.max_ms);
  return buf;
}

}  // namespace

ViewerApp::ViewerApp(const ViewerOptions& options) : options_(options), scene_(options.scene) {}

ViewerApp::~ViewerApp() = default;

std::unique_ptr<ViewerApp> ViewerApp::Create(const ViewerOptions& options, Status* status,
                                             LcmBus* bus) {
  if (!options.Check()) {
    *status = Status::Error("viewer options: " + LastOptionError());
    return nullptr;
  }
  std::unique_ptr<ViewerApp> app(new ViewerApp(options));
  std::error_code ec;
  std::filesystem::create_directories(options.viewer.output_dir, ec);
  if (ec) {
    *status = Status::Error("cannot create the output directory " + options.viewer.output_dir +
                            ": " + ec.message());
    return nullptr;
  }
  // Created even when periodic snapshots have no 3D view: requests may ask for it.
  app->renderer_3d_ = View3dRenderer::Create(options.view3d, status);
  if (!app->renderer_3d_) return nullptr;
  if (bus) {
    app->bus_ = bus;
  } else {
    app->own_bus_ = LcmBus::Create(options.viewer.lcm_url, status);
    if (!app->own_bus_) return nullptr;
    app->bus_ = app->own_bus_.get();
  }
  app->from_log_ = app->bus_->url().rfind("file://", 0) == 0;
  app->adapter_ = std::make_unique<ViewerLcmAdapter>(
      app->bus_, options.channels, options.viewer.queue_capacity,
      static_cast<size_t>(options.viewer.max_message_mb) << 20, &app->scene_);
  ViewerApp* self = app.get();
  app->adapter_->SetMessageTimeHook([self](int64_t utime) { self->OnMessageTime(utime); });
  app->adapter_->SetSnapshotHook(
      [self](int what, const std::string& prefix) { self->OnSnapshotRequest(what, prefix); });
  *status = Status::Ok();
  return app;
}

int ViewerApp::DefaultWhat() const {
  return (options_.viewer.view_3d ? kWhatView3d : 0) |
         (options_.viewer.view_image ? kWhatViewImage : 0);
}

// Runs before a message is applied: a snapshot due at or before its time shows the
// state of everything older, i.e. complete frames.
void ViewerApp::OnMessageTime(int64_t utime) {
  if (scene_.resets() != scene_resets_seen_) {  // time went backwards: a new schedule
    scene_resets_seen_ = scene_.resets();
    next_snapshot_utime_ = 0;
  }
  const double period_s = options_.viewer.snapshot_period_s;
  if (period_s <= 0.0) return;
  const int64_t period = std::max<int64_t>(1, SecondsToUtime(period_s));
  if (next_snapshot_utime_ == 0 || utime < next_snapshot_utime_ - 2 * period) {
    next_snapshot_utime_ = utime + period;
    return;
  }
  if (utime < next_snapshot_utime_ || scene_.empty()) return;
  const Status s = Snapshot(DefaultWhat(), "", options_.viewer.write_latest);
  if (!s.ok()) MBSLAM_LOG(WARNING) << "viewer: snapshot failed: " << s.message();
  // Next slot on the grid after this message (one snapshot even if time jumped far).
  while (next_snapshot_utime_ <= utime) next_snapshot_utime_ += period;
}

void ViewerApp::OnSnapshotRequest(int what, const std::string& request_prefix) {
  const int views = what & (kWhatView3d | kWhatViewImage);
  if (views == 0) return;  // e.g. WHAT_OUTPUTS only: the service's business
  ++snapshot_requests_;
  std::string prefix;
  const Status resolved = ResolveRequestPrefix(options_.viewer.output_dir, request_prefix,
                                               options_.viewer.allow_request_paths, &prefix);
  if (!resolved.ok()) {
    ++refused_request_paths_;
    MBSLAM_LOG(WARNING) << "viewer: " << resolved.message();
  }
  const bool default_place = request_prefix.empty() || !resolved.ok();
  const Status s = Snapshot(views, prefix, default_place && options_.viewer.write_latest);
  if (!s.ok()) MBSLAM_LOG(WARNING) << "viewer: requested snapshot failed: " << s.message();
}

Status ViewerApp::Snapshot(int what, const std::string& prefix_in, bool write_latest) {
  const std::string prefix = prefix_in.empty() ? options_.viewer.output_dir + "/" : prefix_in;
  const int64_t utime = scene_.latest_utime();
  Status result;
  auto write = [&](const std::string& view, const cv::Mat& image) {
    const int64_t t0 = MonotonicUtime();
    std::string png;
    Status s = EncodePng(image, &png);
    std::vector<std::string> paths;
    if (options_.viewer.write_history || !write_latest)
      paths.push_back(SnapshotPath(prefix, view, utime));
    if (write_latest) paths.push_back(SnapshotPath(prefix, view, -1));
    for (size_t i = 0; i < paths.size() && s.ok(); ++i) {
      // The "latest" file is a second name of the history file when there is one.
      const bool linked = i > 0 && LinkAtomically(paths[0], paths[i]).ok();
      if (!linked) s = WriteBytesAtomically(paths[i], png);
    }
    if (!s.ok()) {
      ++write_errors_;
      result = s;
    }
    write_png_ms_.Add(UtimeToMs(MonotonicUtime() - t0));
  };
  if (what & kWhatView3d) {
    cv::Mat image;
    const int64_t t0 = MonotonicUtime();
    const Status s = renderer_3d_->Render(scene_, &image);
    const double ms = UtimeToMs(MonotonicUtime() - t0);
    if (s.ok()) {
      if (snapshots_3d_ == 0) {
        first_render_3d_ms_ = ms;  // shader compilation and JIT: reported on its own
      } else {
        render_3d_ms_.Add(ms);
      }
      ++snapshots_3d_;
      write("view3d", image);
    } else {
      ++render_errors_;
      result = s;
    }
  }
  if (what & kWhatViewImage) {
    const int64_t t0 = MonotonicUtime();
    ImageViewInput input;
    const Status decoded = MakeImageViewInput(scene_, options_.scene.max_image_dimension, &input);
    if (!decoded.ok()) {
      ++image_decode_errors_;
      MBSLAM_LOG(WARNING) << "viewer: camera image at " << input.utime
                          << " µs: " << decoded.message();
    }
    cv::Mat image;
    RenderImageView(options_.image_view, input, &image);
    const double ms = UtimeToMs(MonotonicUtime() - t0);
    if (snapshots_image_ == 0) {
      first_render_image_ms_ = ms;
    } else {
      render_image_ms_.Add(ms);
    }
    ++snapshots_image_;
    write("image", image);
  }
  MBSLAM_LOG(DEBUG) << "viewer: snapshot at " << utime << " µs under " << prefix;
  return result;
}

bool ViewerApp::RunOnce(int timeout_ms) {
  const int handled = bus_->HandleTimeout(timeout_ms);
  if (handled >= 0) return true;
  if (from_log_) {
    at_end_of_log_ = true;
    return false;
  }
  MBSLAM_LOG(ERROR) << "viewer: LCM handle failed";
  usleep(100000);  // do not spin on a broken bus
  return true;
}

Status ViewerApp::Run() {
  MBSLAM_LOG(INFO) << "viewer: listening on "
                   << (bus_->url().empty() ? std::string("the LCM default URL") : bus_->url())
                   << ", snapshots in " << options_.viewer.output_dir;
  while (!ShutdownRequested()) {
    if (at_end_of_log_) {
      if (options_.viewer.exit_at_end_of_log) break;
      usleep(100000);  // the log's fd stays readable at its end: wait for a signal
      continue;
    }
    if (!RunOnce(100) && at_end_of_log_) {
      MBSLAM_LOG(INFO) << "viewer: end of the log";
    }
  }
  MBSLAM_LOG(INFO) << "viewer: stopping" << (ShutdownSignal() ? " on signal" : "");
  return Finish();
}

Status ViewerApp::Finish() {
  if (finished_) return Status::Ok();
  finished_ = true;
  Status result;
  if (options_.viewer.snapshot_at_exit && !scene_.empty()) {
    result = Snapshot(DefaultWhat(), "", options_.viewer.write_latest);
  }
  if (!options_.viewer.stats_file.empty()) {
    const std::string path = options_.viewer.output_dir + "/" + options_.viewer.stats_file;
    const Status s = WriteStringAtomically(path, StatsJson());
    if (!s.ok() && result.ok()) result = s;
  }
  MBSLAM_LOG(INFO) << "viewer: " << adapter_->received_total() << " messages, "
                   << adapter_->bad_total() << " bad; " << snapshots_3d_ << " 3D and "
                   << snapshots_image_ << " image snapshots";
  for (const auto& [channel, c] : adapter_->counts()) {
    if (c.bad > 0) {
      MBSLAM_LOG(INFO) << "  " << channel << ": " << c.bad << " bad of " << c.received
                       << " (last: " << c.last_error << ")";
    }
  }
  const TimingSummary t3 = render_3d_ms_.Cumulative(), ti = render_image_ms_.Cumulative();
  if (snapshots_3d_ > 0) {
    MBSLAM_LOG(INFO) << "  3D view render: first " << first_render_3d_ms_ << " ms, then p50 "
                     << t3.p50_ms << " ms, max " << t3.max_ms << " ms (" << t3.count << ")";
  }
  if (snapshots_image_ > 0) {
    MBSLAM_LOG(INFO) << "  image view render: first " << first_render_image_ms_ << " ms, then p50 "
                     << ti.p50_ms << " ms (" << ti.count << ")";
  }
  return result;
}

std::string ViewerApp::StatsJson() const {
  std::ostringstream os;
  os << "{\n  \"messages\": {";
  bool first = true;
  for (const auto& [channel, c] : adapter_->counts()) {
    os << (first ? "" : ", ") << JsonString(channel) << ": " << c.received;
    first = false;
  }
  os << "},\n  \"bad_messages\": {";
  first = true;
  for (const auto& [channel, c] : adapter_->counts()) {
    os << (first ? "" : ", ") << JsonString(channel) << ": " << c.bad;
    first = false;
  }
  os << "},\n  \"bad_messages_total\": " << adapter_->bad_total() << ",\n";
  os << "  \"image_decode_errors\": " << image_decode_errors_ << ",\n";
  os << "  \"occupancy_decode_errors\": " << scene_.occupancy_decode_errors() << ",\n";
  os << "  \"scene_resets\": " << scene_.resets() << ",\n";
  os << "  \"snapshots_3d\": " << snapshots_3d_ << ",\n";
  os << "  \"snapshots_image\": " << snapshots_image_ << ",\n";
  os << "  \"snapshot_requests\": " << snapshot_requests_ << ",\n";
  os << "  \"refused_request_paths\": " << refused_request_paths_ << ",\n";
  os << "  \"render_errors\": " << render_errors_ << ",\n";
  os << "  \"write_errors\": " << write_errors_ << ",\n";
  os << "  \"last_utime\": " << scene_.latest_utime() << ",\n";
  os << "  \"view3d_size\": [" << options_.view3d.width << ", " << options_.view3d.height << "],\n";
  // "first_ms" is the first render (shader compilation); the rest summarise the others.
  os << "  \"render_3d\": " << JsonTiming(render_3d_ms_.Cumulative(), first_render_3d_ms_) << ",\n";
  os << "  \"render_image\": " << JsonTiming(render_image_ms_.Cumulative(), first_render_image_ms_)
     << ",\n";
  os << "  \"write_png\": " << JsonTiming(write_png_ms_.Cumulative(), 0.0) << "\n}\n";
  return os.str();
}

}  // namespace viewer
}  // namespace mbslam
