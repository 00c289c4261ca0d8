#include "drivers/camera/image_list_source.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "common/util/atomic_file.h"
#include "common/util/time.h"
#include "drivers/camera/image_codec.h"
#include "drivers/common/pose_files.h"
#include "mbslam/image_t.hpp"
#include "services/perception/geometry/pose_buffer.h"

namespace mbslam {
namespace fs = std::filesystem;
namespace {

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

bool IsDir(const std::string& path) {
  std::error_code ec;
  return fs::is_directory(path, ec);
}

bool IsFile(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

std::string Join(const std::string& a, const std::string& b) { return (fs::path(a) / b).string(); }

bool IsCommentOrBlank(const std::string& line) {
  for (char c : line) {
    if (c == '#') return true;
    if (!std::isspace(static_cast<unsigned char>(c))) return false;
  }
  return true;
}

SourceStatus ReadDataLines(const std::string& path, std::vector<std::pair<int, std::string>>* out) {
  std::ifstream in(path);
  if (!in) return SourceStatus::Error(SourceError::kNotFound, "cannot open " + path);
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!IsCommentOrBlank(line)) out->emplace_back(number, line);
  }
  return SourceStatus::Ok();
}

SourceStatus CheckIncreasing(const ImageIndex& index, const std::string& what) {
  for (size_t i = 1; i < index.entries.size(); ++i) {
    if (index.entries[i].utime <= index.entries[i - 1].utime) {
      return SourceStatus::Error(SourceError::kConfig,
                                 what + ": frame times do not increase at frame " +
                                     std::to_string(i) + " (" + index.entries[i].path + ")");
    }
  }
  return SourceStatus::Ok();
}

void TimeByRate(const FolderOptions& options, ImageIndex* index) {
  const int64_t origin = SecondsToUtime(options.time_origin_s);
  for (size_t i = 0; i < index->entries.size(); ++i) {
    index->entries[i].utime =
        origin + static_cast<int64_t>(std::llround(static_cast<double>(i) * 1e6 / options.rate_hz));
  }
}

bool AllDigits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isdigit(static_cast<unsigned char>(c)) != 0;
  });
}

SourceStatus ApplyTimestampsFile(const std::string& path, const std::string& unit,
                                 ImageIndex* index) {
  std::vector<std::pair<int, std::string>> lines;
  SourceStatus st = ReadDataLines(path, &lines);
  if (!st.ok()) return st;
  const size_t n = index->entries.size();
  std::vector<std::optional<int64_t>> times(n);
  std::map<std::string, size_t> by_name;
  for (size_t i = 0; i < n; ++i) by_name[fs::path(index->entries[i].path).filename().string()] = i;
  size_t sequential = 0;
  for (const auto& [number, line] : lines) {
    const std::string where = path + ":" + std::to_string(number);
    const std::vector<std::string> f = SplitFields(line);
    int64_t t = 0;
    size_t target = 0;
    if (f.size() == 1) {
      target = sequential++;
    } else if (f.size() == 2) {
      if (AllDigits(f[0])) {
        // An index beyond the images (std::stoull threw out_of_range on 20+ digits).
        target = f[0].size() > 9 ? n : static_cast<size_t>(std::stoul(f[0]));
      } else {
        auto it = by_name.find(fs::path(f[0]).filename().string());
        if (it == by_name.end()) {
          return SourceStatus::Error(SourceError::kConfig,
                                     where + ": no image named '" + f[0] + "' in the folder");
        }
        target = it->second;
      }
    } else {
      return SourceStatus::Error(SourceError::kConfig,
                                 where + ": expected '<t>' or '<index|name> <t>'");
    }
    if (target >= n) {
      return SourceStatus::Error(SourceError::kConfig,
                                 where + ": more timestamps than the " + std::to_string(n) +
                                     " images");
    }
    const Status parsed = ParseTimeToUtime(f.back(), unit, &t);
    if (!parsed.ok()) return SourceStatus::Error(SourceError::kConfig, where + ": " + parsed.message());
    times[target] = t;
  }
  for (size_t i = 0; i < n; ++i) {
    if (!times[i]) {
      return SourceStatus::Error(SourceError::kConfig,
                                 path + ": no timestamp for image " + std::to_string(i) + " (" +
                                     index->entries[i].path + ")");
    }
    index->entries[i].utime = *times[i];
  }
  return CheckIncreasing(*index, path);
}

// "2011-09-26 13:02:25.964389445" (UTC) to µs.
bool ParseKittiDateTime(const std::string& text, int64_t* utime) {
  int year, month, day, hour, minute, second;
  int consumed = 0;
  if (std::sscanf(text.c_str(), "%d-%d-%d %d:%d:%d%n", &year, &month, &day, &hour, &minute,
                  &second, &consumed) != 6) {
    return false;
  }
  // Out-of-range fields overflowed year - 1900 and seconds * 1e6.
  if (year < 1900 || year > 9999 || month < 1 || month > 12 || day < 1 || day > 31 || hour < 0 ||
      hour > 23 || minute < 0 || minute > 59 || second < 0 || second > 60) {
    return false;
  }
  std::tm tm = {};
  tm.tm_year = year - 1900;
  tm.tm_mon = month - 1;
  tm.tm_mday = day;
  tm.tm_hour = hour;
  tm.tm_min = minute;
  tm.tm_sec = second;
  const time_t seconds = timegm(&tm);
  if (seconds == static_cast<time_t>(-1)) return false;
  int64_t fraction_us = 0;
  const std::string rest = text.substr(static_cast<size_t>(consumed));
  if (!rest.empty()) {
    if (rest[0] != '.') return false;
    int64_t frac = 0;
    const Status st = ParseSecondsToUtime("0" + rest, &frac);
    if (!st.ok()) return false;
    fraction_us = frac;
  }
  *utime = static_cast<int64_t>(seconds) * kUsecPerSec + fraction_us;
  return true;
}

SourceStatus EntriesFromFiles(const std::vector<std::string>& files, ImageIndex* index) {
  index->entries.clear();
  for (const std::string& f : files) {
    ImageEntry e;
    e.path = f;
    index->entries.push_back(e);
  }
  return SourceStatus::Ok();
}

}  // namespace

bool NaturalLess(const std::string& a, const std::string& b) {
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const bool da = std::isdigit(static_cast<unsigned char>(a[i])) != 0;
    const bool db = std::isdigit(static_cast<unsigned char>(b[j])) != 0;
    if (da && db) {
      size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      // Compare by value: strip leading zeros, then length, then digits.
      size_t is = i, js = j;
      while (is + 1 < ie && a[is] == '0') ++is;
      while (js + 1 < je && b[js] == '0') ++js;
      if (ie - is != je - js) return ie - is < je - js;
      const int cmp = a.compare(is, ie - is, b, js, je - js);
      if (cmp != 0) return cmp < 0;
      if (ie - i != je - j) return ie - i > je - j;  // more leading zeros first
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

SourceStatus ListImageFiles(const std::string& dir, const std::vector<std::string>& extensions,
                            std::vector<std::string>* paths) {
  if (!IsDir(dir)) return SourceStatus::Error(SourceError::kNotFound, "no folder " + dir);
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    const std::string name = it->path().filename().string();
    const std::string lower = Lower(name);
    for (const std::string& ext : extensions) {
      const std::string e = Lower(ext);
      if (lower.size() > e.size() && lower.compare(lower.size() - e.size(), e.size(), e) == 0) {
        names.push_back(name);
        break;
      }
    }
  }
  if (ec) return SourceStatus::Error(SourceError::kIo, "cannot list " + dir + ": " + ec.message());
  std::sort(names.begin(), names.end(), NaturalLess);
  paths->clear();
  for (const std::string& n : names) paths->push_back(Join(dir, n));
  if (paths->empty()) {
    return SourceStatus::Error(SourceError::kNotFound, "no image files in " + dir);
  }
  return SourceStatus::Ok();
}

SourceStatus IndexImageFolder(const std::string& dir, const FolderOptions& options,
                              ImageIndex* index) {
  std::vector<std::string> files;
  SourceStatus st = ListImageFiles(dir, options.extensions, &files);
  if (!st.ok()) return st;
  EntriesFromFiles(files, index);
  index->description = "image folder " + dir + " (" + std::to_string(files.size()) + " images)";
  if (!options.timestamps_file.empty()) {
    return ApplyTimestampsFile(options.timestamps_file, options.timestamps_unit, index);
  }
  TimeByRate(options, index);
  return SourceStatus::Ok();
}

SourceStatus IndexTumSequence(const std::string& dir, double max_gap_s, ImageIndex* index) {
  if (!IsDir(dir)) return SourceStatus::Error(SourceError::kNotFound, "no folder " + dir);
  index->entries.clear();
  index->has_truth = true;
  index->truth_source = "tum";
  const std::string rgb_txt = Join(dir, "rgb.txt");
  if (IsFile(rgb_txt)) {
    std::vector<std::pair<int, std::string>> lines;
    SourceStatus st = ReadDataLines(rgb_txt, &lines);
    if (!st.ok()) return st;
    for (const auto& [number, line] : lines) {
      const std::vector<std::string> f = SplitFields(line);
      const std::string where = rgb_txt + ":" + std::to_string(number);
      if (f.size() != 2) {
        return SourceStatus::Error(SourceError::kConfig, where + ": expected 'timestamp filename'");
      }
      ImageEntry e;
      const Status parsed = ParseSecondsToUtime(f[0], &e.utime);
      if (!parsed.ok()) return SourceStatus::Error(SourceError::kConfig, where + ": " + parsed.message());
      e.path = Join(dir, f[1]);
      index->entries.push_back(e);
    }
    if (index->entries.empty()) {
      return SourceStatus::Error(SourceError::kNotFound, rgb_txt + " lists no images");
    }
    st = CheckIncreasing(*index, rgb_txt);
    if (!st.ok()) return st;
    index->description = "TUM RGB-D " + dir + " (" + std::to_string(index->entries.size()) + " images)";
    const std::string truth = Join(dir, "groundtruth.txt");
    if (IsFile(truth)) return AttachGroundTruth(truth, "tum", max_gap_s, "tum", index);
    index->has_truth = false;
    return SourceStatus::Ok();
  }
  // Cut-down layout: raw_imgs/ and one truth line per image.
  const std::string images = Join(dir, "raw_imgs");
  const std::string truth = Join(dir, "truth_cam_poses.txt");
  if (!IsDir(images) || !IsFile(truth)) {
    return SourceStatus::Error(SourceError::kNotFound,
                               dir + " is not a TUM sequence (no rgb.txt, nor raw_imgs/ + "
                                     "truth_cam_poses.txt)");
  }
  std::vector<std::string> files;
  SourceStatus st = ListImageFiles(images, {".png", ".jpg", ".jpeg"}, &files);
  if (!st.ok()) return st;
  std::vector<TimedPose> poses;
  const Status read = ReadTumTrajectory(truth, &poses);
  if (!read.ok()) return SourceStatus::Error(SourceError::kConfig, read.message());
  if (poses.size() != files.size()) {
    return SourceStatus::Error(SourceError::kConfig,
                               truth + " has " + std::to_string(poses.size()) + " poses for " +
                                   std::to_string(files.size()) + " images");
  }
  EntriesFromFiles(files, index);
  for (size_t i = 0; i < files.size(); ++i) {
    index->entries[i].utime = poses[i].utime;
    index->entries[i].world_from_cam = poses[i].pose;
  }
  index->description = "TUM subset " + dir + " (" + std::to_string(files.size()) + " images)";
  return SourceStatus::Ok();
}

SourceStatus IndexKitti(const std::string& dir, const FolderOptions& options, ImageIndex* index) {
  if (!IsDir(dir)) return SourceStatus::Error(SourceError::kNotFound, "no folder " + dir);
  index->entries.clear();
  const std::string cam = std::to_string(options.kitti_camera);
  const std::string raw_dir = Join(dir, "image_0" + cam);
  const std::string odo_dir = Join(dir, "image_" + cam);
  if (IsDir(Join(raw_dir, "data"))) {
    std::vector<std::string> files;
    SourceStatus st = ListImageFiles(Join(raw_dir, "data"), {".png"}, &files);
    if (!st.ok()) return st;
    EntriesFromFiles(files, index);
    const std::string stamps = Join(raw_dir, "timestamps.txt");
    std::vector<std::pair<int, std::string>> lines;
    st = ReadDataLines(stamps, &lines);
    if (!st.ok()) return st;
    if (lines.size() != files.size()) {
      return SourceStatus::Error(SourceError::kConfig,
                                 stamps + " has " + std::to_string(lines.size()) +
                                     " lines for " + std::to_string(files.size()) + " images");
    }
    for (size_t i = 0; i < lines.size(); ++i) {
      if (!ParseKittiDateTime(lines[i].second, &index->entries[i].utime)) {
        return SourceStatus::Error(SourceError::kConfig,
                                   stamps + ":" + std::to_string(lines[i].first) +
                                       ": expected 'YYYY-MM-DD hh:mm:ss.fffffffff'");
      }
    }
    index->description = "KITTI raw " + raw_dir + " (" + std::to_string(files.size()) + " images)";
    return CheckIncreasing(*index, stamps);
  }
  if (IsDir(odo_dir)) {
    std::vector<std::string> files;
    SourceStatus st = ListImageFiles(odo_dir, {".png"}, &files);
    if (!st.ok()) return st;
    EntriesFromFiles(files, index);
    const std::string times = Join(dir, "times.txt");
    std::vector<std::pair<int, std::string>> lines;
    st = ReadDataLines(times, &lines);
    if (!st.ok()) return st;
    if (lines.size() != files.size()) {
      return SourceStatus::Error(SourceError::kConfig,
                                 times + " has " + std::to_string(lines.size()) + " lines for " +
                                     std::to_string(files.size()) + " images");
    }
    for (size_t i = 0; i < lines.size(); ++i) {
      // A line of separators only (",") has no field: SplitFields(...).at(0) threw
      // std::out_of_range out of camera_driver (found by fuzz_kitti_times).
      const std::vector<std::string> fields = SplitFields(lines[i].second);
      const Status parsed = fields.empty()
                                ? Status::Error("expected a time in seconds")
                                : ParseSecondsToUtime(fields[0], &index->entries[i].utime);
      if (!parsed.ok()) {
        return SourceStatus::Error(SourceError::kConfig, times + ":" +
                                                             std::to_string(lines[i].first) +
                                                             ": " + parsed.message());
      }
    }
    st = CheckIncreasing(*index, times);
    if (!st.ok()) return st;
    index->description = "KITTI odometry " + odo_dir + " (" + std::to_string(files.size()) + " images)";
    // dataset/sequences/NN -> dataset/poses/NN.txt
    const fs::path seq(fs::absolute(dir).lexically_normal());
    const std::string poses =
        (seq.parent_path().parent_path() / "poses" / (seq.filename().string() + ".txt")).string();
    if (IsFile(poses)) return AttachGroundTruth(poses, "kitti", 0.1, "kitti", index);
    return SourceStatus::Ok();
  }
  return SourceStatus::Error(SourceError::kNotFound,
                             dir + " is not a KITTI sequence (no image_0" + cam +
                                 "/data nor image_" + cam + "/)");
}

SourceStatus IndexTartanAir(const std::string& dir, const FolderOptions& options,
                            ImageIndex* index) {
  if (!IsDir(dir)) return SourceStatus::Error(SourceError::kNotFound, "no folder " + dir);
  std::string images = Join(dir, "image_left");
  if (!IsDir(images)) images = Join(dir, "images");
  std::vector<std::string> files;
  SourceStatus st = ListImageFiles(images, {".png", ".jpg", ".jpeg"}, &files);
  if (!st.ok()) return st;
  EntriesFromFiles(files, index);
  TimeByRate(options, index);
  char rate[32];
  std::snprintf(rate, sizeof(rate), "%g", options.rate_hz);
  index->description =
      "TartanAir " + dir + " (" + std::to_string(files.size()) + " images at " + rate + " Hz)";
  const std::string poses = Join(dir, "pose_left.txt");
  if (IsFile(poses)) return AttachGroundTruth(poses, "tartanair", 0.1, "tartanair", index);
  return SourceStatus::Ok();
}

SourceStatus AttachGroundTruth(const std::string& file, const std::string& format,
                               double max_gap_s, const std::string& source_name,
                               ImageIndex* index) {
  index->has_truth = true;
  index->truth_source = source_name;
  for (ImageEntry& e : index->entries) e.world_from_cam.reset();
  if (format == "tum") {
    std::vector<TimedPose> poses;
    const Status st = ReadTumTrajectory(file, &poses);
    if (!st.ok()) return SourceStatus::Error(SourceError::kConfig, st.message());
    PoseBuffer buffer(SecondsToUtime(max_gap_s), poses.size());
    for (const TimedPose& p : poses) {
      const Status inserted = buffer.Insert(p.utime, p.pose);
      if (!inserted.ok()) return SourceStatus::Error(SourceError::kConfig, file + ": " + inserted.message());
    }
    for (ImageEntry& e : index->entries) {
      Rigid3d pose;
      if (buffer.Interpolate(e.utime, &pose) == InterpolationResult::kOk) e.world_from_cam = pose;
    }
    return SourceStatus::Ok();
  }
  std::vector<Rigid3d> poses;
  const Status st = format == "kitti" ? ReadKittiPoses(file, &poses) : ReadTartanAirPoses(file, &poses);
  if (!st.ok()) return SourceStatus::Error(SourceError::kConfig, st.message());
  if (format != "kitti" && format != "tartanair") {
    return SourceStatus::Error(SourceError::kConfig, "unknown truth format '" + format + "'");
  }
  if (poses.size() < index->entries.size()) {
    return SourceStatus::Error(SourceError::kConfig,
                               file + " has " + std::to_string(poses.size()) + " poses for " +
                                   std::to_string(index->entries.size()) + " images");
  }
  for (size_t i = 0; i < index->entries.size(); ++i) index->entries[i].world_from_cam = poses[i];
  return SourceStatus::Ok();
}

ImageListSource::ImageListSource(std::string kind, std::string input, FolderOptions folder,
                                 GroundTruthOptions truth)
    : kind_(std::move(kind)), input_(std::move(input)), folder_(std::move(folder)),
      truth_(std::move(truth)) {}

SourceStatus ImageListSource::Open() {
  if (input_.empty()) {
    return SourceStatus::Error(SourceError::kConfig,
                               "source '" + kind_ + "' needs an input folder (--input)");
  }
  index_ = ImageIndex();
  position_ = 0;
  SourceStatus st;
  if (kind_ == "folder") {
    st = IndexImageFolder(input_, folder_, &index_);
  } else if (kind_ == "tum") {
    st = IndexTumSequence(input_, truth_.max_gap_s, &index_);
  } else if (kind_ == "kitti") {
    st = IndexKitti(input_, folder_, &index_);
  } else if (kind_ == "tartanair") {
    st = IndexTartanAir(input_, folder_, &index_);
  } else if (kind_ == "sequence") {
    st = IndexSimSequence(input_, truth_.max_gap_s, &index_);
  } else {
    return SourceStatus::Error(SourceError::kConfig, "not an image-list source: " + kind_);
  }
  if (!st.ok()) return st;
  if (!truth_.file.empty()) {
    st = AttachGroundTruth(truth_.file, truth_.format, truth_.max_gap_s, truth_.format, &index_);
    if (!st.ok()) return st;
  }
  if (index_.entries.empty()) {
    return SourceStatus::Error(SourceError::kNotFound, input_ + " has no frames");
  }
  return SourceStatus::Ok();
}

bool ImageListSource::SeekToIndex(int64_t index) {
  if (index < 0) return false;
  position_ = std::min(static_cast<size_t>(index), index_.entries.size());
  return true;
}

FrameSource::ReadResult ImageListSource::Next(Frame* frame, SourceStatus* status) {
  if (position_ >= index_.entries.size()) return ReadResult::kEnd;
  const size_t i = position_++;
  const ImageEntry& e = index_.entries[i];
  *frame = Frame();
  frame->index = static_cast<int64_t>(i);
  frame->utime = e.utime;
  frame->origin = e.path;
  frame->has_truth_source = index_.has_truth;
  frame->truth_source = index_.truth_source;
  frame->world_from_cam = e.world_from_cam;
  frame->bodies = e.bodies;

  std::string bytes;
  Status read = ReadFileToString(e.path, &bytes, size_t{256} << 20);
  if (!read.ok()) {
    *status = SourceStatus::Error(SourceError::kIo, read.message());
    return ReadResult::kBadFrame;
  }
  ImageFileType type;
  bool unchanged = false;
  const Status decoded = DecodeImageBytes(bytes, &frame->image, &type, &unchanged);
  if (!decoded.ok()) {
    *status = SourceStatus::Error(SourceError::kIo, e.path + ": " + decoded.message());
    return ReadResult::kBadFrame;
  }
  if (unchanged) {
    frame->file_bytes = std::move(bytes);
    frame->file_encoding = type == ImageFileType::kJpeg ? mbslam::image_t::ENCODING_JPEG
                                                        : mbslam::image_t::ENCODING_PNG;
  }
  if (!e.mask_path.empty() && !frame->bodies.empty()) {
    // Visibility of each body from the id mask (16-bit, 0 = static world).
    std::string mask_bytes;
    if (ReadFileToString(e.mask_path, &mask_bytes, size_t{256} << 20).ok()) {
      cv::Mat mask;
      try {
        mask = cv::imdecode(cv::Mat(1, static_cast<int>(mask_bytes.size()), CV_8UC1,
                                    mask_bytes.data()),
                            cv::IMREAD_UNCHANGED);
      } catch (const cv::Exception&) {
        mask.release();
      }
      if (!mask.empty() && mask.channels() == 1) {
        mask.convertTo(mask, CV_32S);
        for (BodyTruth& b : frame->bodies) b.visible = cv::countNonZero(mask == b.id) > 0;
      }
    }
  }
  *status = SourceStatus::Ok();
  return ReadResult::kFrame;
}

}  // namespace mbslam
