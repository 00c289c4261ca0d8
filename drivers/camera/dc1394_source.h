#ifndef MBSLAM_DRIVERS_CAMERA_DC1394_SOURCE_H_
#define MBSLAM_DRIVERS_CAMERA_DC1394_SOURCE_H_

// IEEE 1394 (FireWire) IIDC cameras through libdc1394: enumeration, choice by GUID,
// video mode, frame rate (or Format7 ROI), ISO speed, capture with libdc1394's
// timestamps. Waits for frames with poll() on the capture descriptor so an unplugged
// camera is reported after frame_timeout_s instead of blocking forever.

#include <memory>
#include <string>

#include "drivers/camera/camera_driver_options.h"
#include "drivers/camera/frame_source.h"

namespace mbslam {

class Dc1394Source : public FrameSource {
 public:
  explicit Dc1394Source(Dc1394Options options);
  ~Dc1394Source() override;

  SourceStatus Open() override;
  void Close() override;
  ReadResult Next(Frame* frame, SourceStatus* status) override;
  bool is_live() const override { return true; }
  std::string description() const override { return description_; }

 private:
  struct Impl;
  Dc1394Options options_;
  std::unique_ptr<Impl> impl_;
  std::string description_ = "IEEE 1394 camera";
  int64_t next_index_ = 0;
};

// A human-readable list of the cameras libdc1394 sees (GUID, vendor, model, modes),
// or the reason there are none. Returns the number of cameras, -1 when libdc1394
// cannot start.
int ListDc1394Cameras(std::string* report);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_CAMERA_DC1394_SOURCE_H_
