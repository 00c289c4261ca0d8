#ifndef MBSLAM_DRIVERS_CAMERA_IMAGE_LIST_SOURCE_H_
#define MBSLAM_DRIVERS_CAMERA_IMAGE_LIST_SOURCE_H_

// File sources made of one image file per frame: plain folders and the datasets
// (TUM RGB-D, KITTI, TartanAir, the simulator's sequence folder). Each dataset is an
// indexer that lists the frames with their times and truth; one reader plays them.

#include <optional>
#include <string>
#include <vector>

#include "drivers/camera/camera_driver_options.h"
#include "drivers/camera/frame_source.h"

namespace mbslam {

struct ImageEntry {
  std::string path;                       // image file
  int64_t utime = 0;                      // µs
  std::optional<Rigid3d> world_from_cam;  // camera truth
  std::vector<BodyTruth> bodies;          // simulator truth (visibility from mask_path)
  std::string mask_path;                  // 16-bit body-id mask (simulator), may be empty
};

struct ImageIndex {
  std::vector<ImageEntry> entries;
  std::string calibration_file;  // calibration that comes with the data, if any
  bool has_truth = false;        // the dataset carries truth (frames may still lack it)
  std::string truth_source;      // ground_truth_t.source
  std::string description;
};

// Sorts names so that embedded numbers compare by value ("img2" < "img10").
bool NaturalLess(const std::string& a, const std::string& b);

// Image files directly inside `dir` with one of `extensions` (case-insensitive),
// natural-sorted.
SourceStatus ListImageFiles(const std::string& dir, const std::vector<std::string>& extensions,
                            std::vector<std::string>* paths);

// A folder of images timed by options.timestamps_file or options.rate_hz.
SourceStatus IndexImageFolder(const std::string& dir, const FolderOptions& options,
                              ImageIndex* index);
// TUM RGB-D: rgb.txt (+ groundtruth.txt, interpolated to image times). Also the
// cut-down layout raw_imgs/ + truth_cam_poses.txt (one truth line per image).
SourceStatus IndexTumSequence(const std::string& dir, double max_gap_s, ImageIndex* index);
// KITTI raw (image_0N/data + image_0N/timestamps.txt) or odometry (image_N + times.txt,
// truth from ../../poses/<seq>.txt when present).
SourceStatus IndexKitti(const std::string& dir, const FolderOptions& options, ImageIndex* index);
// TartanAir: image_left/ or images/ + pose_left.txt (truth by frame index), timed by rate_hz.
SourceStatus IndexTartanAir(const std::string& dir, const FolderOptions& options,
                            ImageIndex* index);
// The simulator's sequence folder (tools/sim/SEQUENCE_FORMAT.md).
SourceStatus IndexSimSequence(const std::string& dir, double max_gap_s, ImageIndex* index);

// Replaces the index's truth with a file: "tum" (timed, interpolated on SE(3) to the
// image times, none outside or across gaps > max_gap_s) or "kitti" / "tartanair" (one
// pose per frame, by index).
SourceStatus AttachGroundTruth(const std::string& file, const std::string& format,
                               double max_gap_s, const std::string& source_name,
                               ImageIndex* index);

class ImageListSource : public FrameSource {
 public:
  // `kind`: folder | tum | kitti | tartanair | sequence.
  ImageListSource(std::string kind, std::string input, FolderOptions folder,
                  GroundTruthOptions truth);

  SourceStatus Open() override;
  void Close() override {}
  ReadResult Next(Frame* frame, SourceStatus* status) override;
  bool is_live() const override { return false; }
  int64_t num_frames() const override { return static_cast<int64_t>(index_.entries.size()); }
  SourceStatus Rewind() override {
    position_ = 0;
    return SourceStatus::Ok();
  }
  bool SeekToIndex(int64_t index) override;
  std::string dataset_calibration_file() const override { return index_.calibration_file; }
  std::string description() const override { return index_.description; }
  const ImageIndex& index() const { return index_; }

 private:
  std::string kind_;
  std::string input_;
  FolderOptions folder_;
  GroundTruthOptions truth_;
  ImageIndex index_;
  size_t position_ = 0;
};

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_CAMERA_IMAGE_LIST_SOURCE_H_
