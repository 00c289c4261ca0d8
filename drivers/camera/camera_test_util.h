#ifndef MBSLAM_DRIVERS_CAMERA_CAMERA_TEST_UTIL_H_
#define MBSLAM_DRIVERS_CAMERA_CAMERA_TEST_UTIL_H_

// Fixtures for the camera driver's tests: temporary folders, deterministic images and
// small datasets in each supported layout, written by the tests themselves.

#include <stdlib.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "drivers/common/pose_files.h"
#include "drivers/common/test_util.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {
namespace testing_util {

// Noise plus a gradient, different for every seed: compression and off-by-one
// errors cannot hide in it.
inline cv::Mat MakeTestImage(int width, int height, int channels, int seed) {
  cv::Mat image(height, width, channels == 1 ? CV_8UC1 : CV_8UC3);
  cv::RNG rng(static_cast<uint64_t>(seed) * 7919 + 17);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  for (int r = 0; r < height; ++r) {
    uint8_t* row = image.ptr<uint8_t>(r);
    for (int c = 0; c < width * channels; ++c) {
      row[c] = static_cast<uint8_t>((row[c] / 4) + ((r + c + 3 * seed) % 192));
    }
  }
  return image;
}

inline std::string FrameName(int index, const char* ext) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d%s", index, ext);
  return name;
}

// The simulator's sequence layout (tools/sim/SEQUENCE_FORMAT.md) with `n` gray PNG
// frames at 20 Hz from utime 1 s, a camera moving along +x at 1 m/s, and one object
// (id 1, "car") moving along +y at 2 m/s, visible (in the mask) in even frames only.
inline void WriteSimSequence(const std::string& dir, int n, int width = 64, int height = 48) {
  namespace fs = std::filesystem;
  fs::create_directories(dir + "/images");
  fs::create_directories(dir + "/masks");
  fs::create_directories(dir + "/objects");
  WriteTextFile(dir + "/scenario.yaml", "scenario: unit_test_street\nseed: 7\n");
  WriteTextFile(dir + "/calibration.yaml",
                "camera_name: sim_cam\nimage_width: " + std::to_string(width) +
                    "\nimage_height: " + std::to_string(height) +
                    "\ncamera_matrix: {rows: 3, cols: 3, data: [50, 0, 31.5, 0, 50, 23.5, 0, 0, 1]}\n"
                    "distortion_model: none\n");
  WriteTextFile(dir + "/objects.yaml",
                "objects:\n  - {id: 1, class: car, extent: [4.0, 1.8, 1.5], first_frame: 0, "
                "last_frame: " + std::to_string(n - 1) + "}\n");
  std::string stamps;
  std::vector<TimedPose> cam, car;
  for (int i = 0; i < n; ++i) {
    const int64_t utime = 1000000 + 50000 * int64_t{i};
    stamps += std::to_string(i) + " " + std::to_string(utime) + "\n";
    cv::imwrite(dir + "/images/" + FrameName(i, ".png"), MakeTestImage(width, height, 1, i));
    cv::Mat mask(height, width, CV_16UC1, cv::Scalar(0));
    if (i % 2 == 0) mask(cv::Rect(10, 10, 5, 5)).setTo(1);
    cv::imwrite(dir + "/masks/" + FrameName(i, ".png"), mask);
    TimedPose c;
    c.utime = utime;
    c.pose = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.05 * i, 0, 1.5));
    cam.push_back(c);
    TimedPose o;
    o.utime = utime;
    o.pose = Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d::UnitZ())),
                     Eigen::Vector3d(10, 0.1 * i, 0));
    car.push_back(o);
  }
  WriteTextFile(dir + "/timestamps.txt", stamps);
  WriteTumTrajectory(dir + "/cam_trajectory.tum", cam);
  WriteTumTrajectory(dir + "/objects/1.tum", car);
}

}  // namespace testing_util
}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_CAMERA_CAMERA_TEST_UTIL_H_
