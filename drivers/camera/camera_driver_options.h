#ifndef MBSLAM_DRIVERS_CAMERA_CAMERA_DRIVER_OPTIONS_H_
#define MBSLAM_DRIVERS_CAMERA_CAMERA_DRIVER_OPTIONS_H_

// Options of camera_driver (config/camera_driver.yaml). One struct per concern,
// nested as YAML sections.

#include <cstdint>
#include <string>
#include <vector>

#include "common/config/options.h"
#include "common/lcm/channels.h"

namespace mbslam {

struct ImageOutputOptions {
  std::string encoding = "raw";  // raw | jpeg | png | source (the JPEG/PNG file bytes when no conversion is needed, else raw)
  std::string color = "keep";    // keep | gray | bgr
  int jpeg_quality = 95;         // JPEG quality (0-100)
  int png_compression = 3;       // PNG compression level (0-9)

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("encoding", &encoding, "raw | jpeg | png | source (file bytes of JPEG/PNG inputs when unchanged)");
    v("color", &color, "keep | gray | bgr");
    v("jpeg_quality", &jpeg_quality, "JPEG quality (0-100)");
    v("png_compression", &png_compression, "PNG compression level (0-9)");
  }
};

struct PlaybackOptions {
  double speed = 1.0;        // file sources: 1 = recorded rate, N = N times faster, 0 = as fast as possible (ignored with --log)
  int64_t start_frame = 0;   // index of the first frame to publish (0-based)
  int64_t end_frame = -1;    // index after the last frame to publish (-1 = to the end)
  double start_s = 0.0;      // skip frames earlier than this after the first frame (s)
  double end_s = -1.0;       // stop at this time after the first frame (s, < 0 = to the end)
  int loops = 1;             // times to play a file source (0 = forever, not with --log)
  bool progress = true;      // progress bar on stderr when it is a terminal

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("speed", &speed, "1 = recorded rate, N = N x, 0 = as fast as possible (ignored with --log)");
    v("start_frame", &start_frame, "index of the first frame to publish (0-based)");
    v("end_frame", &end_frame, "index after the last frame to publish (-1 = to the end)");
    v("start_s", &start_s, "skip frames earlier than this after the first frame (s)");
    v("end_s", &end_s, "stop at this time after the first frame (s, < 0 = to the end)");
    v("loops", &loops, "times to play a file source (0 = forever, not with --log)");
    v("progress", &progress, "progress bar on stderr when it is a terminal");
  }
};

struct FolderOptions {
  double rate_hz = 10.0;              // frame rate of sources without timestamps (Hz)
  double time_origin_s = 0.0;         // time of frame 0 of sources without timestamps (s)
  std::string timestamps_file = "";   // per frame "<t>" or "<index|file name> <t>" ('#' comments); empty = rate_hz
  std::string timestamps_unit = "s";  // unit of timestamps_file: s | ms | us | ns
  std::vector<std::string> extensions = {".png", ".jpg", ".jpeg", ".bmp", ".pgm", ".ppm", ".tif", ".tiff"};  // image file endings (case-insensitive)
  int kitti_camera = 2;               // KITTI camera index (0, 1 gray; 2, 3 colour)

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("rate_hz", &rate_hz, "frame rate of sources without timestamps (Hz)");
    v("time_origin_s", &time_origin_s, "time of frame 0 of sources without timestamps (s)");
    v("timestamps_file", &timestamps_file, "per frame '<t>' or '<index|name> <t>'; empty = rate_hz");
    v("timestamps_unit", &timestamps_unit, "unit of timestamps_file: s | ms | us | ns");
    v("extensions", &extensions, "image file endings (case-insensitive)");
    v("kitti_camera", &kitti_camera, "KITTI camera index (0, 1 gray; 2, 3 colour)");
  }
};

struct GroundTruthOptions {
  bool publish = true;         // publish the dataset's truth on the ground_truth channel
  std::string file = "";       // truth file replacing the dataset's own (empty = the dataset's)
  std::string format = "tum";  // format of `file`: tum (timed, interpolated) | kitti | tartanair (one per frame)
  double max_gap_s = 0.1;      // largest gap of timed truth samples to interpolate across (s)

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("publish", &publish, "publish the dataset's truth on the ground_truth channel");
    v("file", &file, "truth file replacing the dataset's own (empty = the dataset's)");
    v("format", &format, "format of file: tum | kitti | tartanair");
    v("max_gap_s", &max_gap_s, "largest gap of timed truth samples to interpolate across (s)");
  }
};

struct Dc1394Options {
  std::string guid = "";                       // camera GUID in hex (e.g. 0x00b09d0100a1b2c3); empty = the first camera
  std::string video_mode = "640x480_MONO8";    // WxH_CODING (e.g. 640x480_YUV422, 1024x768_RGB8) or FORMAT7_0..7; empty = keep the camera's
  double framerate = 30.0;                     // Hz: 1.875 3.75 7.5 15 30 60 120 240 (not used by FORMAT7)
  std::string format7_color_coding = "MONO8";  // FORMAT7 only: MONO8 | MONO16 | RAW8 | RGB8 | YUV411 | YUV422 | YUV444
  int iso_speed = 400;                         // isochronous speed (Mb/s): 100 200 400 800 (800 switches to 1394b)
  int dma_buffers = 8;                         // capture ring buffer (frames)
  bool hardware_timestamps = true;             // stamp frames with libdc1394's capture time, else the dequeue time
  std::string bayer_pattern = "none";          // colour filter of RAW8 / MONO8 sensors: none | RGGB | GBRG | GRBG | BGGR
  double frame_timeout_s = 2.0;                // no frame for this long = camera lost (s)
  bool reset_bus = false;                      // reset the bus before opening (frees stale isochronous resources)

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("guid", &guid, "camera GUID in hex; empty = the first camera");
    v("video_mode", &video_mode, "WxH_CODING (640x480_MONO8, 1024x768_RGB8, ...) or FORMAT7_n; empty = keep");
    v("framerate", &framerate, "Hz: 1.875 3.75 7.5 15 30 60 120 240 (not FORMAT7)");
    v("format7_color_coding", &format7_color_coding, "FORMAT7 only: MONO8 | MONO16 | RAW8 | RGB8 | YUV4xx");
    v("iso_speed", &iso_speed, "isochronous speed (Mb/s): 100 200 400 800");
    v("dma_buffers", &dma_buffers, "capture ring buffer (frames)");
    v("hardware_timestamps", &hardware_timestamps, "use libdc1394's capture time, else the dequeue time");
    v("bayer_pattern", &bayer_pattern, "none | RGGB | GBRG | GRBG | BGGR");
    v("frame_timeout_s", &frame_timeout_s, "no frame for this long = camera lost (s)");
    v("reset_bus", &reset_bus, "reset the bus before opening");
  }
};

struct V4l2Options {
  std::string device = "/dev/video0";  // device node (or a number N for /dev/videoN)
  int width = 640;                     // requested width (px, 0 = keep the device's)
  int height = 480;                    // requested height (px, 0 = keep the device's)
  double fps = 30.0;                   // requested frame rate (Hz, 0 = keep the device's)
  std::string fourcc = "";             // pixel format: MJPG | YUYV | GREY | ...; empty = the device's
  double frame_timeout_s = 2.0;        // no frame for this long = camera lost (s)

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("device", &device, "device node, or N for /dev/videoN");
    v("width", &width, "requested width (px, 0 = keep)");
    v("height", &height, "requested height (px, 0 = keep)");
    v("fps", &fps, "requested frame rate (Hz, 0 = keep)");
    v("fourcc", &fourcc, "pixel format MJPG | YUYV | GREY ...; empty = keep");
    v("frame_timeout_s", &frame_timeout_s, "no frame for this long = camera lost (s)");
  }
};

struct LiveOptions {
  bool reconnect = false;            // on a missing or lost camera, retry instead of exiting
  double reconnect_interval_s = 1.0; // wait between attempts (s)
  int max_reconnect_attempts = 0;    // attempts before giving up (0 = forever)

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("reconnect", &reconnect, "on a missing or lost camera, retry instead of exiting");
    v("reconnect_interval_s", &reconnect_interval_s, "wait between attempts (s)");
    v("max_reconnect_attempts", &max_reconnect_attempts, "attempts before giving up (0 = forever)");
  }
};

struct CameraDriverOptions {
  std::string source = "folder";     // dc1394 | v4l2 | video | folder | tum | kitti | tartanair | sequence
  std::string input = "";            // file / folder of a file source
  std::string camera_name = "";      // image_t.camera_name (empty = the calibration's camera_name)
  std::string calibration_file = ""; // intrinsics YAML (config/camera/*.yaml); empty = the dataset's, else approximate
  double calibration_period_s = 1.0; // resend the calibration this often in message time (s; also with the first frame)
  std::string lcm_url = "";          // LCM URL to publish on (empty = LCM default); not used with --log
  ImageOutputOptions image;
  PlaybackOptions playback;
  FolderOptions folder;
  GroundTruthOptions ground_truth;
  Dc1394Options dc1394;
  V4l2Options v4l2;
  LiveOptions live;
  ChannelOptions channels;

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("source", &source, "dc1394 | v4l2 | video | folder | tum | kitti | tartanair | sequence");
    v("input", &input, "file / folder of a file source");
    v("camera_name", &camera_name, "image_t.camera_name (empty = the calibration's)");
    v("calibration_file", &calibration_file, "intrinsics YAML; empty = the dataset's, else approximate");
    v("calibration_period_s", &calibration_period_s, "resend the calibration this often (s, message time)");
    v("lcm_url", &lcm_url, "LCM URL (empty = LCM default); not used with --log");
    v("image", &image, "published image format");
    v("playback", &playback, "file sources: rate, range, loops");
    v("folder", &folder, "image folders and datasets without timestamps");
    v("ground_truth", &ground_truth, "dataset truth on the ground_truth channel");
    v("dc1394", &dc1394, "IEEE 1394 cameras (libdc1394)");
    v("v4l2", &v4l2, "V4L2 / USB cameras");
    v("live", &live, "live cameras: reconnect policy");
    v("channels", &channels, "LCM channel names");
  }
};

bool IsKnownCameraSource(const std::string& source);
bool IsLiveCameraSource(const std::string& source);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_CAMERA_CAMERA_DRIVER_OPTIONS_H_
