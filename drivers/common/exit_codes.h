#ifndef MBSLAM_DRIVERS_COMMON_EXIT_CODES_H_
#define MBSLAM_DRIVERS_COMMON_EXIT_CODES_H_

// Process exit codes of the drivers (camera_driver, odometry_bridge, handeye_calib).
// Each failure a script may want to react to has its own code; they are stable.

namespace mbslam {

enum DriverExitCode : int {
  kExitOk = 0,              // end of the input, or SIGINT / SIGTERM
  kExitRuntimeError = 1,    // an unexpected failure (message on stderr)
  kExitUsage = 2,           // bad command line, option file or calibration file
  kExitInputNotFound = 3,   // a file, folder or dataset is missing or has no frames
  kExitOutputError = 4,     // the LCM URL or the output log cannot be opened / written
  kExitInputTimeout = 5,    // a live input (DDS, LCM) sent nothing within the timeout
  kExitDegenerateData = 6,  // the data cannot determine the result (hand-eye without turns)
  kExitNoCamera = 10,       // no camera bus, no device node, no camera with that GUID
  kExitBadMode = 11,        // the camera refuses the requested video mode / rate / size
  kExitCameraLost = 12,     // the camera stopped delivering mid-stream (unplugged)
  kExitCameraAccess = 13,   // the device exists but cannot be opened (permissions, busy)
  kExitBadData = 14,        // no frame of a file source could be decoded
};

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_COMMON_EXIT_CODES_H_
