#include "drivers/odometry_bridge/odometry_files.h"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>

#include "common/util/time.h"
#include "drivers/common/pose_files.h"

namespace mbslam {
namespace {

// Splits a CSV line at commas (fields trimmed; quotes around a field removed).
std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::string current;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      fields.push_back(current);
      current.clear();
    } else {
      current += c;
    }
  }
  fields.push_back(current);
  for (std::string& f : fields) {
    size_t b = 0, e = f.size();
    while (b < e && std::isspace(static_cast<unsigned char>(f[b]))) ++b;
    while (e > b && std::isspace(static_cast<unsigned char>(f[e - 1]))) --e;
    f = f.substr(b, e - b);
  }
  return fields;
}

bool ParseNumber(const std::string& text, double* value) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v)) return false;
  *value = v;
  return true;
}

// Canonical column names for the accepted spellings.
std::string CanonicalColumn(std::string name) {
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (!name.empty() && name[0] == '%') name = name.substr(1);
  static const std::map<std::string, std::string> kAliases = {
      {"time", "t"}, {"timestamp", "t"}, {"stamp", "t"}, {"time_s", "t"},
      {"header.stamp.sec", "sec"}, {"header.stamp.nanosec", "nanosec"},
      {"header.frame_id", "frame_id"},
      {"pose.pose.position.x", "x"}, {"pose.pose.position.y", "y"}, {"pose.pose.position.z", "z"},
      {"pose.pose.orientation.x", "qx"}, {"pose.pose.orientation.y", "qy"},
      {"pose.pose.orientation.z", "qz"}, {"pose.pose.orientation.w", "qw"},
      {"twist.twist.linear.x", "vx"}, {"twist.twist.linear.y", "vy"}, {"twist.twist.linear.z", "vz"},
      {"twist.twist.angular.x", "wx"}, {"twist.twist.angular.y", "wy"},
      {"twist.twist.angular.z", "wz"}};
  auto it = kAliases.find(name);
  return it == kAliases.end() ? name : it->second;
}

constexpr int kRos2EchoColumns = 89;

// sec + nanosec (ROS time) to µs. Out-of-range values were undefined behaviour in the
// double -> int64 cast and the multiplication.
Status StampToUtime(double sec, double nanosec, int64_t* utime) {
  constexpr double kMaxSec = 9.0e12;  // int64 µs hold +-9.2e12 s
  if (!(std::abs(sec) <= kMaxSec) || !(nanosec >= 0.0 && nanosec < 1e9)) {
    return Status::Error("stamp " + std::to_string(sec) + " s + " + std::to_string(nanosec) +
                         " ns out of range");
  }
  *utime = static_cast<int64_t>(sec) * kUsecPerSec + std::llround(nanosec / 1000.0);
  return Status::Ok();
}

Status SampleFromRos2EchoRow(const std::vector<std::string>& f, OdometrySample* s) {
  std::vector<double> v(f.size(), 0.0);
  for (size_t i = 0; i < f.size(); ++i) {
    if (i == 2 || i == 3) continue;  // frame ids
    if (!ParseNumber(f[i], &v[i])) return Status::Error("column " + std::to_string(i + 1) + " ('" + f[i] + "') is not a number");
  }
  MBSLAM_RETURN_IF_ERROR(StampToUtime(v[0], v[1], &s->utime));
  s->frame_id = f[2];
  s->child_frame_id = f[3];
  s->odom_from_base.translation = Eigen::Vector3d(v[4], v[5], v[6]);
  bool renormalised = false;
  MBSLAM_RETURN_IF_ERROR(OdometryQuaternion(v[7], v[8], v[9], v[10], &s->odom_from_base.rotation, &renormalised));
  for (size_t i = 0; i < 36; ++i) s->pose_covariance[i] = v[11 + i];
  s->linear_velocity = Eigen::Vector3d(v[47], v[48], v[49]);
  s->angular_velocity = Eigen::Vector3d(v[50], v[51], v[52]);
  for (size_t i = 0; i < 36; ++i) s->twist_covariance[i] = v[53 + i];
  return Status::Ok();
}

}  // namespace

Status ReadOdometryCsv(const std::string& path, std::vector<OdometrySample>* samples) {
  std::ifstream in(path);
  if (!in) return Status::Error("cannot open " + path);
  samples->clear();
  std::string line;
  int number = 0;
  std::map<std::string, size_t> columns;
  size_t header_width = 0;  // fields of the header line (columns may repeat a name)
  bool headerless = false;
  bool have_layout = false;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string> f = SplitCsv(line);
    const std::string where = path + ":" + std::to_string(number);
    if (!have_layout) {
      have_layout = true;
      double first = 0.0;
      if (ParseNumber(f[0], &first)) {
        if (static_cast<int>(f.size()) != kRos2EchoColumns) {
          return Status::Error(where + ": a CSV without a header must have the " +
                               std::to_string(kRos2EchoColumns) +
                               " columns of `ros2 topic echo --csv` (got " +
                               std::to_string(f.size()) + ")");
        }
        headerless = true;
      } else {
        for (size_t i = 0; i < f.size(); ++i) columns[CanonicalColumn(f[i])] = i;
        header_width = f.size();
        for (const char* need : {"x", "y", "z", "qx", "qy", "qz", "qw"}) {
          if (!columns.count(need)) return Status::Error(where + ": header lacks column '" + need + "'");
        }
        if (!columns.count("utime") && !columns.count("t") &&
            !(columns.count("sec") && columns.count("nanosec"))) {
          return Status::Error(where + ": header needs a time column (utime, t or sec + nanosec)");
        }
        continue;
      }
    }
    OdometrySample s;
    if (headerless) {
      if (static_cast<int>(f.size()) != kRos2EchoColumns) {
        return Status::Error(where + ": expected " + std::to_string(kRos2EchoColumns) + " columns");
      }
      MBSLAM_RETURN_IF_ERROR(SampleFromRos2EchoRow(f, &s).WithContext(where));
    } else {
      // Compared with the header's width, not the number of distinct names: with a
      // repeated name the last column's index was past the end of a short row.
      if (f.size() < header_width) return Status::Error(where + ": too few columns");
      auto num = [&](const std::string& name, double* v) -> Status {
        if (!ParseNumber(f[columns.at(name)], v)) {
          return Status::Error(where + ": column '" + name + "' ('" + f[columns.at(name)] + "') is not a number");
        }
        return Status::Ok();
      };
      if (columns.count("utime")) {
        int64_t t = 0;
        MBSLAM_RETURN_IF_ERROR(ParseTimeToUtime(f[columns.at("utime")], "us", &t).WithContext(where));
        s.utime = t;
      } else if (columns.count("t")) {
        MBSLAM_RETURN_IF_ERROR(ParseSecondsToUtime(f[columns.at("t")], &s.utime).WithContext(where));
      } else {
        double sec = 0, nsec = 0;
        MBSLAM_RETURN_IF_ERROR(num("sec", &sec));
        MBSLAM_RETURN_IF_ERROR(num("nanosec", &nsec));
        MBSLAM_RETURN_IF_ERROR(StampToUtime(sec, nsec, &s.utime).WithContext(where));
      }
      double p[7];
      const char* names[7] = {"x", "y", "z", "qx", "qy", "qz", "qw"};
      for (int k = 0; k < 7; ++k) MBSLAM_RETURN_IF_ERROR(num(names[k], &p[k]));
      s.odom_from_base.translation = Eigen::Vector3d(p[0], p[1], p[2]);
      bool renormalised = false;
      MBSLAM_RETURN_IF_ERROR(OdometryQuaternion(p[3], p[4], p[5], p[6], &s.odom_from_base.rotation,
                                                &renormalised)
                                 .WithContext(where));
      const char* twist[6] = {"vx", "vy", "vz", "wx", "wy", "wz"};
      for (int k = 0; k < 6; ++k) {
        if (!columns.count(twist[k])) continue;
        double v = 0;
        MBSLAM_RETURN_IF_ERROR(num(twist[k], &v));
        (k < 3 ? s.linear_velocity : s.angular_velocity)[k % 3] = v;
      }
      for (int k = 0; k < 36; ++k) {
        const std::string pc = "pose_cov_" + std::to_string(k), tc = "twist_cov_" + std::to_string(k);
        if (columns.count(pc)) MBSLAM_RETURN_IF_ERROR(num(pc, &s.pose_covariance[static_cast<size_t>(k)]));
        if (columns.count(tc)) MBSLAM_RETURN_IF_ERROR(num(tc, &s.twist_covariance[static_cast<size_t>(k)]));
      }
      if (columns.count("frame_id")) s.frame_id = f[columns.at("frame_id")];
      if (columns.count("child_frame_id")) s.child_frame_id = f[columns.at("child_frame_id")];
    }
    if (!samples->empty() && s.utime <= samples->back().utime) {
      return Status::Error(where + ": time does not increase");
    }
    s.seq = static_cast<int64_t>(samples->size());
    MBSLAM_RETURN_IF_ERROR(ValidateOdometrySample(s).WithContext(where));
    samples->push_back(s);
  }
  if (samples->empty()) return Status::Error(path + ": no odometry samples");
  return Status::Ok();
}

Status ReadOdometryTum(const std::string& path, bool derive_twist,
                       std::vector<OdometrySample>* samples) {
  std::vector<TimedPose> poses;
  MBSLAM_RETURN_IF_ERROR(ReadTumTrajectory(path, &poses));
  samples->clear();
  for (size_t i = 0; i < poses.size(); ++i) {
    OdometrySample s;
    s.utime = poses[i].utime;
    s.seq = static_cast<int64_t>(i);
    s.odom_from_base = poses[i].pose;
    samples->push_back(s);
  }
  if (derive_twist) DeriveTwists(samples);
  // Twists derived from far-apart poses a microsecond apart are not finite.
  for (const OdometrySample& s : *samples) {
    MBSLAM_RETURN_IF_ERROR(ValidateOdometrySample(s).WithContext(
        path + ": sample at " + std::to_string(s.utime) + " us"));
  }
  return Status::Ok();
}

void DeriveTwists(std::vector<OdometrySample>* samples) {
  for (size_t i = 0; i < samples->size(); ++i) {
    const size_t a = i == 0 ? 0 : i - 1;
    const size_t b = i == 0 ? std::min<size_t>(1, samples->size() - 1) : i;
    if (a == b) continue;
    OdometrySample& s = (*samples)[i];
    // In double: the difference of two file times can exceed int64.
    const double dt_s = (static_cast<double>((*samples)[b].utime) -
                         static_cast<double>((*samples)[a].utime)) * 1e-6;
    TwistFromPoses((*samples)[a].odom_from_base, (*samples)[b].odom_from_base, dt_s,
                   &s.linear_velocity, &s.angular_velocity);
  }
}

}  // namespace mbslam
