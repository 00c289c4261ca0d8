#ifndef MBSLAM_TOOLS_EVAL_PLOT_H_
#define MBSLAM_TOOLS_EVAL_PLOT_H_

// Top-view trajectory plots (OpenCV drawing): ground truth and aligned estimate
// projected onto the plane of the ground truth's two main directions of motion.

#include <opencv2/core.hpp>

#include <string>

#include "common/util/status.h"
#include "tools/eval/trajectory.h"

namespace mbslam {
namespace eval {

struct TopViewPlot {
  int width = 900;   // image size (px)
  int height = 700;  // (px)
  std::string title;
  bool draw_errors = true;  // a grey segment from each estimate pose to the truth at the same time
};

// Draws into a BGR image. The estimate should already be aligned to the truth.
Status DrawTopView(const Trajectory& gt, const Trajectory& est_aligned, const TopViewPlot& options,
                   cv::Mat* image);
Status WriteTopView(const std::string& path, const Trajectory& gt, const Trajectory& est_aligned,
                    const TopViewPlot& options);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_EVAL_PLOT_H_
