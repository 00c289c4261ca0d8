// Writes the seed corpora of the fuzz targets (test/fuzz) from the project's own
// outputs, so nothing big is committed:
//
//   make_fuzz_seeds OUT_DIR [--log LOG.lcmlog]... [--file TARGET TAG PATH]...
//
// * --log: every message of an LCM log (make_test_log, make_viewer_test_log, a
//   simulator or service run) becomes seeds of the targets that decode its channel
//   (the first few per target and channel, at most 64 KiB each).
// * --file: a file's bytes, after one tag byte (TAG < 0: no tag), become a seed of
//   TARGET (config/*.yaml for the options loader, calibration files, ...).
// * Always: tiny PNG / JPEG / raw images in image_t and in the image-decode header,
//   typical dataset text files, a snapshot request.
//
// Writes OUT_DIR/<target>/<name> (the folders are created).

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/lcm/all_types.h"
#include "common/util/command_line.h"
#include "common/lcm/channels.h"
#include "common/lcm/lcm_log.h"
#include "common/lcm/wire_check.h"
#include "test/fuzz/fuzz_util.h"
#include "test/fuzz/lcm_types.h"

namespace {

using Bytes = std::vector<uint8_t>;
constexpr size_t kMaxSeedBytes = 64 << 10;
constexpr int kMaxSeedsPerKind = 6;

class SeedWriter {
 public:
  explicit SeedWriter(std::string root) : root_(std::move(root)) {}

  // Writes a seed unless it is too big or this (target, kind) has enough.
  void Add(const std::string& target, const std::string& kind, const Bytes& bytes) {
    if (bytes.size() > kMaxSeedBytes) return;
    int& n = counts_[target + "/" + kind];
    if (n >= kMaxSeedsPerKind) return;
    const std::string dir = root_ + "/" + target;
    std::filesystem::create_directories(dir);
    const std::string path = dir + "/" + kind + "-" + std::to_string(n++);
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!out) {
      std::fprintf(stderr, "make_fuzz_seeds: cannot write %s\n", path.c_str());
      std::exit(1);
    }
    ++written_;
  }
  int written() const { return written_; }

 private:
  std::string root_;
  std::map<std::string, int> counts_;
  int written_ = 0;
};

Bytes Tagged(uint8_t tag, const Bytes& bytes) {
  Bytes out(bytes.size() + 1);
  out[0] = tag;
  std::copy(bytes.begin(), bytes.end(), out.begin() + 1);
  return out;
}

Bytes Records(const std::vector<std::pair<uint8_t, Bytes>>& records) {
  Bytes out;
  for (const auto& [tag, bytes] : records) mbslam::fuzz::AppendRecord(tag, bytes.data(), bytes.size(), &out);
  return out;
}

Bytes Text(const std::string& s) { return Bytes(s.begin(), s.end()); }

template <typename Msg>
Bytes Encode(const Msg& m) {
  Bytes buf(static_cast<size_t>(m.getEncodedSize()));
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  return buf;
}

// fuzz_image_decode's header (see that file) followed by the image bytes.
Bytes ImageDecodeInput(const mbslam::image_t& m, bool keep_color) {
  Bytes out(12 + m.data.size(), 0);
  out[0] = static_cast<uint8_t>(m.encoding);
  out[1] = keep_color ? 1 : 0;
  out[2] = static_cast<uint8_t>(m.width);
  out[3] = static_cast<uint8_t>(m.width >> 8);
  out[4] = static_cast<uint8_t>(m.height);
  out[5] = static_cast<uint8_t>(m.height >> 8);
  for (int b = 0; b < 4; ++b) out[6 + b] = static_cast<uint8_t>(static_cast<uint32_t>(m.row_stride) >> (8 * b));
  std::copy(m.data.begin(), m.data.end(), out.begin() + 12);
  return out;
}

// Channel name -> (viewer channel tag or -1, lcm type name).
struct ChannelInfo {
  int viewer_tag;
  std::string type;
};

std::map<std::string, ChannelInfo> ChannelTable() {
  const mbslam::ChannelOptions c;
  return {{c.perception_camera_pose, {0, "camera_pose_t"}},
          {c.perception_map, {1, "map_t"}},
          {c.perception_objects, {2, "objects_t"}},
          {c.perception_occupancy, {3, "occupancy_t"}},
          {c.perception_tracks, {4, "tracks_t"}},
          {c.camera_image, {5, "image_t"}},
          {c.snapshot_request, {6, "snapshot_request_t"}},
          {c.camera_calibration, {-1, "camera_calibration_t"}},
          {c.odometry, {-1, "odometry_t"}},
          {c.ground_truth, {-1, "ground_truth_t"}},
          {c.perception_status, {-1, "status_t"}}};
}

void SeedsFromLog(const std::string& path, SeedWriter* seeds) {
  std::vector<mbslam::LcmLogEvent> events;
  const mbslam::Status st = mbslam::ReadLcmLog(path, &events);
  if (!st.ok()) {
    std::fprintf(stderr, "make_fuzz_seeds: %s\n", st.message().c_str());
    std::exit(1);
  }
  const auto table = ChannelTable();
  const mbslam::ChannelOptions c;
  Bytes last_calibration;
  std::vector<Bytes> recent_odometry;
  std::vector<std::pair<uint8_t, Bytes>> viewer_window;
  for (const mbslam::LcmLogEvent& e : events) {
    auto it = table.find(e.channel);
    if (it == table.end()) continue;
    const Bytes& msg = e.data;
    const int type_index = mbslam::fuzz::LcmTypeIndex(it->second.type);
    seeds->Add("fuzz_lcm_decode", it->second.type, Tagged(static_cast<uint8_t>(type_index), msg));
    if (it->second.viewer_tag >= 0) {
      const uint8_t tag = static_cast<uint8_t>(it->second.viewer_tag);
      seeds->Add("fuzz_viewer_lcm", "one-" + e.channel, Records({{tag, msg}}));
      viewer_window.emplace_back(tag, msg);
      if (viewer_window.size() > 4) viewer_window.erase(viewer_window.begin());
      if (viewer_window.size() == 4) seeds->Add("fuzz_viewer_lcm", "window", Records(viewer_window));
    }
    if (e.channel == c.camera_image) {
      seeds->Add("fuzz_input_image", "log", Records({{0, msg}}));
      if (!last_calibration.empty()) {
        seeds->Add("fuzz_input_calibration", "with-image", Records({{0, last_calibration}, {1, msg}}));
      }
      mbslam::image_t image{};
      if (mbslam::DecodeLcmMessage(msg.data(), msg.size(), &image).ok()) {
        seeds->Add("fuzz_image_decode", "log", ImageDecodeInput(image, true));
      }
    } else if (e.channel == c.camera_calibration) {
      last_calibration = msg;
      seeds->Add("fuzz_input_calibration", "alone", Records({{0, msg}}));
    } else if (e.channel == c.odometry) {
      recent_odometry.push_back(msg);
      if (recent_odometry.size() == 3) {
        seeds->Add("fuzz_input_odometry", "log",
                   Records({{0, recent_odometry[0]}, {0, recent_odometry[1]}, {0, recent_odometry[2]}}));
        recent_odometry.clear();
      }
    } else if (e.channel == c.perception_occupancy) {
      seeds->Add("fuzz_octree_stream", "message", Tagged(1, msg));
      mbslam::occupancy_t occupancy{};
      if (mbslam::DecodeLcmMessage(msg.data(), msg.size(), &occupancy).ok()) {
        seeds->Add("fuzz_octree_stream", "stream", Tagged(0, occupancy.data));
      }
    } else if (e.channel == c.snapshot_request) {
      seeds->Add("fuzz_input_snapshot", "log", msg);
    }
  }
}

// Tiny images in every encoding.
void ImageSeeds(SeedWriter* seeds) {
  cv::Mat gray(12, 16, CV_8UC1);
  cv::Mat bgr(12, 16, CV_8UC3);
  for (int r = 0; r < 12; ++r) {
    for (int c = 0; c < 16; ++c) {
      gray.at<uint8_t>(r, c) = static_cast<uint8_t>(16 * r + c);
      bgr.at<cv::Vec3b>(r, c) = cv::Vec3b(static_cast<uint8_t>(20 * r), static_cast<uint8_t>(15 * c), 99);
    }
  }
  int seq = 0;
  auto add = [&](const cv::Mat& pixels, int8_t encoding, const std::string& name) {
    mbslam::image_t m{};
    m.utime = 1000000 + seq;
    m.seq = seq++;
    m.camera_name = "fuzz";
    m.width = pixels.cols;
    m.height = pixels.rows;
    m.encoding = encoding;
    if (encoding == mbslam::image_t::ENCODING_JPEG || encoding == mbslam::image_t::ENCODING_PNG) {
      std::vector<uchar> file;
      cv::imencode(encoding == mbslam::image_t::ENCODING_JPEG ? ".jpg" : ".png", pixels, file);
      m.data.assign(file.begin(), file.end());
      m.row_stride = 0;
    } else {
      m.row_stride = static_cast<int32_t>(pixels.cols * pixels.channels());
      m.data.assign(pixels.data, pixels.data + pixels.total() * pixels.elemSize());
    }
    m.size = static_cast<int32_t>(m.data.size());
    seeds->Add("fuzz_image_decode", name, ImageDecodeInput(m, true));
    seeds->Add("fuzz_image_decode", name + "-gray-out", ImageDecodeInput(m, false));
    const Bytes encoded = Encode(m);
    seeds->Add("fuzz_input_image", name, Records({{0, encoded}}));
    seeds->Add("fuzz_viewer_lcm", "image-" + name, Records({{5, encoded}}));
    seeds->Add("fuzz_lcm_decode", "image-" + name,
               Tagged(static_cast<uint8_t>(mbslam::fuzz::LcmTypeIndex("image_t")), encoded));
  };
  add(gray, mbslam::image_t::ENCODING_GRAY8, "gray8");
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  add(rgb, mbslam::image_t::ENCODING_RGB8, "rgb8");
  add(bgr, mbslam::image_t::ENCODING_BGR8, "bgr8");
  add(gray, mbslam::image_t::ENCODING_JPEG, "jpeg-gray");
  add(bgr, mbslam::image_t::ENCODING_JPEG, "jpeg-color");
  add(gray, mbslam::image_t::ENCODING_PNG, "png-gray");
  add(bgr, mbslam::image_t::ENCODING_PNG, "png-color");

  // A calibration for the 16x12 images, then one of them.
  mbslam::camera_calibration_t cal{};
  cal.utime = 1;
  cal.camera_name = "fuzz";
  cal.width = 16;
  cal.height = 12;
  cal.fx = cal.fy = 20.0;
  cal.cx = 7.5;
  cal.cy = 5.5;
  cal.distortion_model = mbslam::camera_calibration_t::DISTORTION_RADTAN;
  cal.distortion = {0.01, -0.002, 0.0, 0.0};
  cal.num_distortion = static_cast<int32_t>(cal.distortion.size());
  mbslam::image_t image{};
  image.utime = 2;
  image.camera_name = "fuzz";
  image.width = 16;
  image.height = 12;
  image.row_stride = 16;
  image.encoding = mbslam::image_t::ENCODING_GRAY8;
  image.data.assign(gray.data, gray.data + gray.total());
  image.size = static_cast<int32_t>(image.data.size());
  seeds->Add("fuzz_input_calibration", "tiny", Records({{0, Encode(cal)}, {1, Encode(image)}}));
}

void MessageSeeds(SeedWriter* seeds) {
  mbslam::snapshot_request_t request{};
  request.utime = 5;
  request.path_prefix = "snap/run1_";
  request.what = mbslam::snapshot_request_t::WHAT_OUTPUTS | mbslam::snapshot_request_t::WHAT_VIEW_3D;
  const Bytes r = Encode(request);
  seeds->Add("fuzz_input_snapshot", "tiny", r);
  seeds->Add("fuzz_viewer_lcm", "snapshot", Records({{6, r}}));
  // Poses for the odometry bridge's LCM input, 20 ms apart.
  std::vector<std::pair<uint8_t, Bytes>> poses;
  for (int i = 0; i < 3; ++i) {
    mbslam::pose_t p{};
    p.utime = 1000000 + 20000 * i;
    p.target_frame = "odom";
    p.source_frame = "base_link";
    p.position[0] = 0.01 * i;
    p.orientation[0] = 1.0;
    poses.emplace_back(0, Encode(p));
  }
  seeds->Add("fuzz_bridge_pose", "three", Records(poses));
  // Random valid encodings of every type, from the schema.
  int index = 0;
#define MBSLAM_SEED_TYPE(t)                                                                \
  for (uint32_t k = 0; k < 2; ++k) {                                                       \
    const Bytes b = mbslam::RandomLcmEncoding(#t, mbslam::t::getHash(), 17 + k, 3);        \
    seeds->Add("fuzz_lcm_decode", "random-" #t, Tagged(static_cast<uint8_t>(index), b));   \
  }                                                                                        \
  ++index;
  MBSLAM_FOR_EACH_LCM_TYPE(MBSLAM_SEED_TYPE)
#undef MBSLAM_SEED_TYPE
}

// Typical dataset files (the readers' documented formats).
void TextSeeds(SeedWriter* seeds) {
  const std::string rgb =
      "# color images\n# timestamp filename\n1305031102.175304 rgb/1305031102.175304.png\n"
      "1305031102.211214 rgb/1305031102.211214.png\n1305031102.243211 rgb/1305031102.243211.png\n";
  const std::string truth =
      "# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n"
      "1305031102.1600 1.3405 0.6266 1.6575 0.6574 0.6126 -0.2949 -0.3248\n"
      "1305031102.2000 1.3303 0.6256 1.6464 0.6579 0.6161 -0.2932 -0.3189\n"
      "1305031102.2500 1.3160 0.6254 1.6302 0.6609 0.6199 -0.2893 -0.3086\n";
  const std::string cut = "1.0 0 0 0 0 0 0 1\n1.1 0.1 0 0 0 0 0 1\n1.2 0.2 0 0 0 0 0 1\n";
  seeds->Add("fuzz_tum_dataset", "rgb", Records({{0, Text(rgb)}}));
  seeds->Add("fuzz_tum_dataset", "rgb-truth", Records({{0, Text(rgb)}, {1, Text(truth)}}));
  seeds->Add("fuzz_tum_dataset", "cut-down", Records({{2, Text(cut)}}));

  const std::string times = "0.000000e+00\n1.036594e-01\n2.073188e-01\n";
  const std::string poses =
      "1 0 0 0 0 1 0 0 0 0 1 0\n0.9999 0.0001 0.0001 0.01 -0.0001 0.9999 0.0001 0.0 -0.0001 "
      "-0.0001 0.9999 0.8\n1 0 0 0.02 0 1 0 0 0 0 1 1.6\n";
  const std::string stamps =
      "2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26.068102373\n2011-09-26 13:02:26.171819019\n";
  seeds->Add("fuzz_kitti_times", "odometry", Records({{0, Text(times)}}));
  seeds->Add("fuzz_kitti_times", "odometry-poses", Records({{0, Text(times)}, {1, Text(poses)}}));
  seeds->Add("fuzz_kitti_times", "raw", Records({{2, Text(stamps)}}));

  seeds->Add("fuzz_folder_timestamps", "plain", Tagged(0, Text("0.0\n0.1\n0.2\n")));
  seeds->Add("fuzz_folder_timestamps", "named", Tagged(1, Text("# name t\nimg1.png 0\nimg2.png 33\nimg10.png 66\n")));
  seeds->Add("fuzz_folder_timestamps", "indexed", Tagged(3, Text("0 1000000000\n1 1033333333\n2 1066666666\n")));

  seeds->Add("fuzz_pose_files", "tum", Tagged(0, Text(truth)));
  seeds->Add("fuzz_pose_files", "kitti", Tagged(1, Text(poses)));
  seeds->Add("fuzz_pose_files", "tartanair", Tagged(2, Text("0 0 0 0 0 0 1\n0.1 0 0 0 0 0.0499792 0.99875\n")));

  const std::string csv =
      "utime,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz,frame_id,child_frame_id\n"
      "1000000,0,0,0,0,0,0,1,0.5,0,0,0,0,0.1,odom,base_link\n"
      "1010000,0.005,0,0,0,0,0.0005,1,0.5,0,0,0,0,0.1,odom,base_link\n";
  const std::string csv_ros =
      "header.stamp.sec,header.stamp.nanosec,pose.pose.position.x,pose.pose.position.y,"
      "pose.pose.position.z,pose.pose.orientation.x,pose.pose.orientation.y,"
      "pose.pose.orientation.z,pose.pose.orientation.w\n"
      "1700000000,500000000,1,2,0,0,0,0,1\n1700000000,600000000,1.1,2,0,0,0,0,1\n";
  std::string echo = "1700000000,0,odom,base_link,1,2,0,0,0,0,1";
  for (int i = 0; i < 36; ++i) echo += ",0";
  echo += ",0.5,0,0,0,0,0.1";
  for (int i = 0; i < 36; ++i) echo += ",0";
  echo += "\n";
  seeds->Add("fuzz_odometry_files", "csv", Tagged(0, Text(csv)));
  seeds->Add("fuzz_odometry_files", "csv-ros", Tagged(0, Text(csv_ros)));
  seeds->Add("fuzz_odometry_files", "ros2-echo", Tagged(0, Text(echo)));
  seeds->Add("fuzz_odometry_files", "tum", Tagged(1, Text(cut)));
  seeds->Add("fuzz_odometry_files", "tum-twist", Tagged(2, Text(cut)));
}

Bytes ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "make_fuzz_seeds: cannot read %s\n", path.c_str());
    std::exit(1);
  }
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: make_fuzz_seeds OUT_DIR [--log LOG]... [--file TARGET TAG PATH]...\n");
    return 2;
  }
  SeedWriter seeds(argv[1]);
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--log" && i + 1 < argc) {
      SeedsFromLog(argv[++i], &seeds);
    } else if (a == "--file" && i + 3 < argc) {
      const std::string target = argv[++i];
      int64_t tag = 0;
      const mbslam::Status st = mbslam::ParseInt64(argv[++i], "--file TAG", &tag);
      if (!st.ok() || tag > 255) {
        std::fprintf(stderr, "make_fuzz_seeds: %s\n", st.ok() ? "--file TAG must be at most 255 (negative: untagged)" : st.message().c_str());
        return 2;
      }
      const std::string path = argv[++i];
      const Bytes bytes = ReadFile(path);
      seeds.Add(target, std::filesystem::path(path).stem().string(),
                tag < 0 ? bytes : Tagged(static_cast<uint8_t>(tag), bytes));
    } else {
      std::fprintf(stderr, "make_fuzz_seeds: bad argument '%s'\n", a.c_str());
      return 2;
    }
  }
  ImageSeeds(&seeds);
  MessageSeeds(&seeds);
  TextSeeds(&seeds);
  std::printf("make_fuzz_seeds: %d seeds in %s\n", seeds.written(), argv[1]);
  return 0;
}
