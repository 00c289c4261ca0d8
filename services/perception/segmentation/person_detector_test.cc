// PersonDetector: HOG people detection restricted to a moving object's box. The
// references are the detections of OpenCV's HOG people detector on the whole frame of
// OpenCV's vtest.avi (pedestrians; ../shared/data/opencv_vtest, skipped when absent):
// the restricted check must find them from their boxes, also when the image is enlarged
// so much that the box is scaled down first (max_box_height_px), and must not fire on
// boxes where the whole-frame detector found nobody.

#include "services/perception/segmentation/person_detector.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

namespace mbslam {
namespace {

std::string VtestPath() {
  const char* env = std::getenv("MBSLAM_DATA");
  const std::string root = env ? env : std::string(MBSLAM_SOURCE_DIR) + "/../shared/data";
  const std::string path = root + "/opencv_vtest/vtest.avi";
  return std::filesystem::exists(path) ? path : std::string();
}

// The person inside a HOG detection window: the window has ~1/4 of margin at each side
// and ~1/8 above and below.
cv::Rect PersonBox(const cv::Rect& window) {
  return cv::Rect(window.x + window.width / 4, window.y + window.height / 8, window.width / 2,
                  window.height * 3 / 4);
}

TEST(PersonDetector, NoPersonInAFlatOrTinyRegion) {
  PersonDetector detector(PersonDetectorOptions{});
  const cv::Mat flat(480, 640, CV_8UC1, cv::Scalar(128));
  EXPECT_FALSE(detector.Detect(flat, cv::Rect(200, 100, 80, 200)));
  EXPECT_FALSE(detector.Detect(flat, cv::Rect(0, 0, 640, 480)));
  EXPECT_FALSE(detector.Detect(flat, cv::Rect(10, 10, 20, 30)));   // below min_box_height_px
  EXPECT_FALSE(detector.Detect(flat, cv::Rect(700, 500, 50, 100)));  // outside the image
}

TEST(PersonDetector, OptionsAreChecked) {
  PersonDetectorOptions o;
  EXPECT_TRUE(o.Check());
  o.scale_step = 1.0;
  EXPECT_FALSE(o.Check());
  o = PersonDetectorOptions{};
  o.max_box_height_px = 100;  // below the 128-px detector window
  EXPECT_FALSE(o.Check());
}

TEST(PersonDetector, FindsThePedestriansOfVtestFromTheirBoxes) {
  const std::string path = VtestPath();
  if (path.empty()) GTEST_SKIP() << "opencv_vtest not found (set MBSLAM_DATA or put ../shared/data next to the repository)";
  cv::VideoCapture video(path);
  ASSERT_TRUE(video.isOpened());
  cv::HOGDescriptor hog;
  hog.setSVMDetector(cv::HOGDescriptor::getDefaultPeopleDetector());
  PersonDetector detector(PersonDetectorOptions{});

  int references = 0, found = 0, found_enlarged = 0, enlarged_scaled_down = 0;
  int negatives = 0, false_alarms = 0;
  cv::Mat frame, gray;
  for (int index = 0; index < 400 && video.read(frame); ++index) {
    if (index % 50 != 0) continue;
    cv::cvtColor(frame, gray, cv::COLOR_BGR2GRAY);
    std::vector<cv::Rect> windows;
    std::vector<double> weights;
    hog.detectMultiScale(gray, windows, weights, 0.3, cv::Size(8, 8), cv::Size(0, 0), 1.05, 2.0);
    cv::Mat enlarged;
    cv::resize(gray, enlarged, cv::Size(), 2.5, 2.5, cv::INTER_LINEAR);
    for (size_t k = 0; k < windows.size(); ++k) {
      if (weights[k] < 0.8) continue;  // confident references only
      const cv::Rect box = PersonBox(windows[k]) & cv::Rect(0, 0, gray.cols, gray.rows);
      if (box.height < 48) continue;
      ++references;
      found += detector.Detect(gray, box);
      const cv::Rect big(static_cast<int>(box.x * 2.5), static_cast<int>(box.y * 2.5),
                         static_cast<int>(box.width * 2.5), static_cast<int>(box.height * 2.5));
      enlarged_scaled_down += big.height > PersonDetectorOptions{}.max_box_height_px;
      found_enlarged += detector.Detect(enlarged, big);
    }
    // Negatives: person-sized boxes that overlap no detection of the whole frame.
    for (int y = 0; y + 160 <= gray.rows; y += 80) {
      for (int x = 0; x + 70 <= gray.cols; x += 70) {
        const cv::Rect box(x, y, 70, 160);
        bool overlaps = false;
        for (const cv::Rect& w : windows) overlaps |= (w & box).area() > 0;
        if (overlaps) continue;
        ++negatives;
        false_alarms += detector.Detect(gray, box);
      }
    }
  }
  ASSERT_GE(references, 5) << "too few confident pedestrians in vtest.avi";
  EXPECT_GT(enlarged_scaled_down, 0);
  EXPECT_GE(found, references * 8 / 10) << found << " of " << references;
  EXPECT_GE(found_enlarged, references * 8 / 10) << found_enlarged << " of " << references;
  ASSERT_GE(negatives, 20);
  EXPECT_LE(false_alarms, negatives / 20) << false_alarms << " of " << negatives;
  std::printf("PERSON_JSON {\"references\": %d, \"found\": %d, \"found_enlarged_2_5x\": %d, \"negatives\": %d, "
              "\"false_alarms\": %d}\n", references, found, found_enlarged, negatives, false_alarms);
}

}  // namespace
}  // namespace mbslam
