#ifndef MBSLAM_DRIVERS_CAMERA_FRAME_SOURCE_H_
#define MBSLAM_DRIVERS_CAMERA_FRAME_SOURCE_H_

// The interface every image source of camera_driver implements (cameras, video
// files, image folders, datasets), and the frame it produces.

#include <opencv2/core.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "services/perception/geometry/rigid3.h"

namespace mbslam {

// Why a source failed. Maps one-to-one onto the process exit codes (exit_codes.h).
enum class SourceError {
  kNone,
  kConfig,        // bad options (unknown mode string, missing path option, ...)
  kNotFound,      // input file / folder missing, or a dataset without frames
  kNoCamera,      // no bus / device node / camera with the requested id
  kBadMode,       // the camera refuses the requested mode, rate or size
  kDisconnected,  // a live camera stopped delivering
  kAccess,        // permission denied or device busy
  kIo,            // read or decode failure that is not one of the above
  kOutput,        // publishing or writing the log failed
};

const char* SourceErrorName(SourceError error);
// The process exit code for an error kind.
int ExitCodeFor(SourceError error);

class SourceStatus {
 public:
  SourceStatus() = default;
  static SourceStatus Ok() { return SourceStatus(); }
  static SourceStatus Error(SourceError kind, std::string message) {
    SourceStatus s;
    s.kind_ = kind == SourceError::kNone ? SourceError::kIo : kind;
    s.message_ = std::move(message);
    return s;
  }
  bool ok() const { return kind_ == SourceError::kNone; }
  SourceError kind() const { return kind_; }
  const std::string& message() const { return message_; }

 private:
  SourceError kind_ = SourceError::kNone;
  std::string message_;
};

// Ground truth of one rigid body in the frame's scene (simulator).
struct BodyTruth {
  int id = 0;                   // body id (0 = static world)
  std::string name;             // class / name
  Rigid3d world_from_body;
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   // body origin, world frame (m/s)
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // world frame (rad/s)
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();            // box size along body x y z (m)
  bool visible = false;         // any pixel of the body in the image
};

struct Frame {
  int64_t index = 0;       // position of the frame in the source (0-based)
  int64_t utime = 0;       // sensor time (µs)
  cv::Mat image;           // 8-bit, 1 channel (gray) or 3 channels (BGR)
  // The file bytes the image was decoded from when they are a JPEG or PNG of exactly
  // `image` (8-bit gray or BGR), for the "source" encoding; else empty.
  std::string file_bytes;
  int8_t file_encoding = -1;  // image_t::ENCODING_JPEG / ENCODING_PNG for file_bytes
  std::string origin;         // file name or "frame N", for messages

  // Ground truth, if the source has any.
  bool has_truth_source = false;             // the source carries truth (publish has_camera=0 if missing)
  std::optional<Rigid3d> world_from_cam;     // camera pose (axes x right, y down, z forward)
  std::vector<BodyTruth> bodies;             // moving bodies (simulator)
  std::string truth_source;                  // "tum", "kitti", "tartanair", "sim:<scenario>"
};

class FrameSource {
 public:
  enum class ReadResult {
    kFrame,     // *frame holds the next frame
    kBadFrame,  // an unreadable frame was skipped; *status says which and why
    kEnd,       // no more frames (file sources)
    kError,     // fatal; *status has the kind (kDisconnected for a lost camera)
  };

  virtual ~FrameSource() = default;

  // Opens the device or indexes the files. Called again after Close() to reconnect.
  virtual SourceStatus Open() = 0;
  virtual void Close() = 0;
  virtual ReadResult Next(Frame* frame, SourceStatus* status) = 0;

  // Cameras are live: no pacing, no loop, reconnect on loss.
  virtual bool is_live() const = 0;
  // Frames in a file source, -1 when unknown.
  virtual int64_t num_frames() const { return -1; }
  // Back to the first frame (file sources, for looping).
  virtual SourceStatus Rewind() {
    return SourceStatus::Error(SourceError::kConfig, "this source cannot loop");
  }
  // Moves so that the next frame is `index`; false if the source cannot seek (the
  // caller then reads and drops frames).
  virtual bool SeekToIndex(int64_t /*index*/) { return false; }
  // A calibration file that comes with the data (e.g. a sequence's calibration.yaml).
  virtual std::string dataset_calibration_file() const { return ""; }
  virtual std::string description() const = 0;
};

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_CAMERA_FRAME_SOURCE_H_
