#ifndef MBSLAM_SERVICES_PERCEPTION_PIPELINE_COUNTERS_H_
#define MBSLAM_SERVICES_PERCEPTION_PIPELINE_COUNTERS_H_

// Named, cumulative event counters (input errors, drops, recoveries) reported on
// PERCEPTION_STATUS. Thread-safe.

#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace mbslam {

class Counters {
 public:
  void Increment(const std::string& name, int64_t by = 1) {
    std::lock_guard<std::mutex> lock(mutex_);
    values_[name] += by;
    last_event_ = name;
  }
  int64_t Get(const std::string& name) const {
    std::lock_guard<std::mutex> lock(mutex_);
    auto it = values_.find(name);
    return it == values_.end() ? 0 : it->second;
  }
  // Sorted by name.
  std::vector<std::pair<std::string, int64_t>> Snapshot() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return {values_.begin(), values_.end()};
  }
  std::string last_event() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return last_event_;
  }

 private:
  mutable std::mutex mutex_;
  std::map<std::string, int64_t> values_;
  std::string last_event_;
};

// Counter names used across the service, defined once.
namespace counter {
inline constexpr const char* kImageDecodeError = "image_decode_error";          // malformed image_t
inline constexpr const char* kImageBadSize = "image_bad_size";                  // width/height out of range
inline constexpr const char* kImageSizeMismatch = "image_size_mismatch";        // byte count != geometry
inline constexpr const char* kImageUnknownEncoding = "image_unknown_encoding";  // encoding not supported
inline constexpr const char* kImageDecompressError = "image_decompress_error";  // JPEG/PNG broken
inline constexpr const char* kImageTimeBackwards = "image_time_backwards";      // utime <= previous
inline constexpr const char* kImageTimeJump = "image_time_jump";                // gap > max_frame_gap
inline constexpr const char* kImageSeqGap = "image_frames_lost_upstream";       // seq gaps (frames)
inline constexpr const char* kImageCalibrationMismatch = "image_calibration_mismatch";
inline constexpr const char* kImageUncalibrated = "image_uncalibrated";         // used fallback intrinsics
inline constexpr const char* kImageDroppedStale = "image_dropped_stale";        // realtime policy
inline constexpr const char* kOdometryDecodeError = "odometry_decode_error";
inline constexpr const char* kOdometryInvalid = "odometry_invalid";             // NaN / non-unit quaternion
inline constexpr const char* kOdometryTimeBackwards = "odometry_time_backwards";
inline constexpr const char* kCalibrationDecodeError = "calibration_decode_error";
inline constexpr const char* kCalibrationInvalid = "calibration_invalid";
inline constexpr const char* kSnapshotDecodeError = "snapshot_request_decode_error";
inline constexpr const char* kStageOverrun = "stage_overrun";
inline constexpr const char* kImageRejectedGlitch = "image_rejected_glitch";   // nearly every track lost at once: skipped
inline constexpr const char* kImageExposureCorrected = "image_exposure_corrected";  // an exposure step undone before tracking
inline constexpr const char* kImageTimelineReset = "image_timeline_reset";      // time (or size) changed for good: start over
inline constexpr const char* kImageSeqRestart = "image_seq_restart";            // seq went back (driver restarted)
inline constexpr const char* kImageSizeChanged = "image_size_changed";          // size differs from the previous images
inline constexpr const char* kImageWithoutOdometry = "image_without_odometry";  // odometry seen before, but none recent
inline constexpr const char* kOdometryGap = "odometry_gap";                     // odometry resumed after a gap
inline constexpr const char* kTrackingLost = "tracking_lost";                   // camera tracking state left OK
inline constexpr const char* kWorldMotionReplaced = "world_motion_replaced";    // SLAM's motion disagreed with the image: segmentation used its two-view estimate
inline constexpr const char* kPoseEpipolarAssisted = "pose_epipolar_assisted";  // too few map points: pose leaned on the epipolar geometry (slam.hybrid_tracking)
inline constexpr const char* kPoseRelocalized = "pose_relocalized";              // placed by matching ORB descriptors to the map (slam.relocalization)
inline constexpr const char* kMapRejoined = "map_rejoined";                      // a kept lost map placed the image and was taken up again (slam.lost_maps_kept)
inline constexpr const char* kTrackingRecovered = "tracking_recovered";         // back to OK after a loss
inline constexpr const char* kMapPointsCulled = "map_points_culled";            // left with their culled keyframes
inline constexpr const char* kObjectRecordsPruned = "object_records_pruned";    // per-object state of objects gone
inline constexpr const char* kOccupancyCrops = "occupancy_crops";                // memory bound: cropped around the camera
inline constexpr const char* kOccupancyVoxelsDropped = "occupancy_voxels_dropped";  // occupied voxels those crops dropped
inline constexpr const char* kGlobalBaRequested = "slam_global_ba_requested";  // images that took SNAPSHOT_REQUEST WHAT_GLOBAL_BA (requests between two images: once)
inline constexpr const char* kGlobalBaStarted = "slam_global_ba_started";      // ... and its whole-map adjustment started
}  // namespace counter

// Counters that report recoveries or routine housekeeping, not problems: they do not make
// the state DEGRADED.
inline bool IsInformationalCounter(const std::string& name) {
  return name == counter::kTrackingRecovered || name == counter::kMapPointsCulled ||
         name == counter::kObjectRecordsPruned || name == counter::kOccupancyCrops ||
         name == counter::kOccupancyVoxelsDropped || name == counter::kGlobalBaRequested ||
         name == counter::kGlobalBaStarted;
}

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PIPELINE_COUNTERS_H_
