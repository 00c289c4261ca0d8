#ifndef MBSLAM_VIEWER_VIEWER_APP_H_
#define MBSLAM_VIEWER_VIEWER_APP_H_

// The viewer process: LCM bus + adapter + scene + renderers + snapshot schedule.
// Snapshots are rendered every viewer.snapshot_period_s of MESSAGE time (so a file://
// replay at any speed gives the same pictures), on SNAPSHOT_REQUEST, and at the end
// (end of a file:// log, SIGINT / SIGTERM).

#include <cstdint>
#include <memory>
#include <string>

#include "common/lcm/lcm_bus.h"
#include "common/util/status.h"
#include "common/util/timing_stats.h"
#include "viewer/image_view.h"
#include "viewer/lcm_adapter.h"
#include "viewer/scene.h"
#include "viewer/view3d_renderer.h"
#include "viewer/viewer_options.h"

namespace mbslam {
namespace viewer {

// Bits of snapshot_request_t.what that concern the viewer.
constexpr int kWhatView3d = 1;
constexpr int kWhatViewImage = 2;

class ViewerApp {
 public:
  // `bus` may be given (tests, memq://); otherwise one is opened on viewer.lcm_url.
  static std::unique_ptr<ViewerApp> Create(const ViewerOptions& options, Status* status,
                                           LcmBus* bus = nullptr);
  ~ViewerApp();
  ViewerApp(const ViewerApp&) = delete;
  ViewerApp& operator=(const ViewerApp&) = delete;

  // Handles messages until SIGINT / SIGTERM or the end of a file:// log, then Finish().
  Status Run();
  // Handles at most one message; false at the end of a file:// log.
  bool RunOnce(int timeout_ms);
  bool at_end_of_log() const { return at_end_of_log_; }
  // Final snapshots (viewer.snapshot_at_exit) and the stats file. Idempotent.
  Status Finish();

  // Renders and writes the views in `what` now, under `prefix` ("" = output_dir/).
  Status Snapshot(int what, const std::string& prefix, bool write_latest);

  const SceneState& scene() const { return scene_; }
  const ViewerLcmAdapter& adapter() const { return *adapter_; }
  int64_t snapshots_3d() const { return snapshots_3d_; }
  int64_t snapshots_image() const { return snapshots_image_; }
  // Render times (ms): the first of each view (shader compilation, JIT) and a summary of
  // the later ones.
  double first_render_3d_ms() const { return first_render_3d_ms_; }
  TimingSummary render_3d_timing() const { return render_3d_ms_.Cumulative(); }
  TimingSummary render_image_timing() const { return render_image_ms_.Cumulative(); }
  // The stats file's content (JSON).
  std::string StatsJson() const;

 private:
  explicit ViewerApp(const ViewerOptions& options);
  void OnMessageTime(int64_t utime);
  void OnSnapshotRequest(int what, const std::string& prefix);
  int DefaultWhat() const;

  ViewerOptions options_;
  std::unique_ptr<LcmBus> own_bus_;
  LcmBus* bus_ = nullptr;
  bool from_log_ = false;
  bool at_end_of_log_ = false;
  SceneState scene_;
  std::unique_ptr<ViewerLcmAdapter> adapter_;
  std::unique_ptr<View3dRenderer> renderer_3d_;
  int64_t next_snapshot_utime_ = 0;  // µs; 0 = not scheduled yet
  int64_t scene_resets_seen_ = 0;
  bool finished_ = false;
  int64_t snapshots_3d_ = 0, snapshots_image_ = 0, snapshot_requests_ = 0;
  int64_t refused_request_paths_ = 0, write_errors_ = 0, render_errors_ = 0;
  int64_t image_decode_errors_ = 0;
  double first_render_3d_ms_ = 0.0, first_render_image_ms_ = 0.0;
  TimingStats render_3d_ms_{"render_3d"};
  TimingStats render_image_ms_{"render_image"};
  TimingStats write_png_ms_{"write_png"};
};

}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_VIEWER_APP_H_
