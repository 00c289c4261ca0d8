#include "tools/eval/trajectory.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>

#include "common/util/atomic_file.h"
#include "common/util/command_line.h"

namespace mbslam {
namespace eval {
namespace {

// Splits a line into tokens at whitespace and commas; drops a '#' comment.
std::vector<std::string> Tokens(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == '#') {
      break;
    }
    if (c == ' ' || c == '\t' || c == ',' || c == '\r') {
      if (!cur.empty()) {
        out.push_back(cur), cur.clear();
      }
    } else {
      cur.push_back(c);
    }
  }
  if (!cur.empty()) {
    out.push_back(cur);
  }
  return out;
}

// A whole, finite number (the tools' one parser).
bool ParseDouble(const std::string& token, double* value) { return mbslam::ParseDouble(token, "", value).ok(); }

Rigid3d PoseFromXyzQxyzw(const double v[7]) {
  Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);  // w, x, y, z
  return Rigid3d(q, Eigen::Vector3d(v[0], v[1], v[2]));
}

}  // namespace

std::string UtimeToSecondsString(int64_t utime) {
  const bool negative = utime < 0;
  const uint64_t a =
      negative ? static_cast<uint64_t>(-(utime + 1)) + 1 : static_cast<uint64_t>(utime);
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%s%llu.%06llu", negative ? "-" : "",
                static_cast<unsigned long long>(a / 1000000),
                static_cast<unsigned long long>(a % 1000000));
  return buf;
}

bool ParseSecondsToUtime(const std::string& token, int64_t* utime) {
  if (token.empty()) {
    return false;
  }
  size_t i = 0;
  bool negative = false;
  if (token[i] == '+' || token[i] == '-') {
    negative = token[i++] == '-';
  }
  int64_t whole = 0;
  size_t digits = 0;
  while (i < token.size() && std::isdigit(static_cast<unsigned char>(token[i]))) {
    whole = whole * 10 + (token[i++] - '0');
    ++digits;
    if (digits > 12) {
      break;
    }
  }
  int64_t frac = 0;
  int frac_digits = 0;
  bool round_up = false;
  if (i < token.size() && token[i] == '.') {
    ++i;
    while (i < token.size() && std::isdigit(static_cast<unsigned char>(token[i]))) {
      if (frac_digits < 6) {
        frac = frac * 10 + (token[i] - '0');
        ++frac_digits;
      } else if (frac_digits == 6) {
        round_up = token[i] >= '5';
        ++frac_digits;
      }
      ++i;
    }
  }
  if (i != token.size() || (digits == 0 && frac_digits == 0) || digits > 12) {
    // Exponent or very large: fall back to floating point.
    double v;
    if (!ParseDouble(token, &v) || !std::isfinite(v)) {
      return false;
    }
    *utime = static_cast<int64_t>(std::llround(v * 1e6));
    return true;
  }
  for (int k = std::min(frac_digits, 6); k < 6; ++k) {
    frac *= 10;
  }
  int64_t us = whole * 1000000 + frac + (round_up ? 1 : 0);
  *utime = negative ? -us : us;
  return true;
}

void SortByTime(Trajectory* trajectory) {
  std::stable_sort(trajectory->begin(), trajectory->end(),
                   [](const TimedPose& a, const TimedPose& b) { return a.utime < b.utime; });
}

Status ParseTumTrajectory(const std::string& text, Trajectory* trajectory) {
  trajectory->clear();
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto tokens = Tokens(line);
    if (tokens.empty()) {
      continue;
    }
    if (tokens.size() != 8) {
      return Status::Error("line " + std::to_string(line_no) +
                           ": expected 8 values (t tx ty tz qx qy qz qw), got " +
                           std::to_string(tokens.size()));
    }
    TimedPose p;
    if (!ParseSecondsToUtime(tokens[0], &p.utime)) {
      return Status::Error("line " + std::to_string(line_no) + ": bad timestamp '" + tokens[0] +
                           "'");
    }
    double v[7];
    for (int k = 0; k < 7; ++k) {
      const std::string& token = tokens[static_cast<size_t>(k) + 1];
      if (!ParseDouble(token, &v[k]) || !std::isfinite(v[k])) {
        return Status::Error("line " + std::to_string(line_no) + ": bad number '" + token + "'");
      }
    }
    const double qn = std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
    if (qn < 1e-6) {
      return Status::Error("line " + std::to_string(line_no) + ": zero quaternion");
    }
    p.pose = PoseFromXyzQxyzw(v);
    trajectory->push_back(p);
  }
  SortByTime(trajectory);
  for (size_t i = 1; i < trajectory->size(); ++i) {
    if ((*trajectory)[i].utime == (*trajectory)[i - 1].utime) {
      return Status::Error("duplicate timestamp " + UtimeToSecondsString((*trajectory)[i].utime));
    }
  }
  return Status::Ok();
}

Status ReadTumTrajectory(const std::string& path, Trajectory* trajectory) {
  std::string text;
  MBSLAM_RETURN_IF_ERROR(ReadFileToString(path, &text));
  return ParseTumTrajectory(text, trajectory).WithContext(path);
}

std::string FormatTumLine(int64_t utime, const Rigid3d& pose) {
  const Eigen::Quaterniond& q = pose.rotation;
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%s %.9f %.9f %.9f %.9f %.9f %.9f %.9f",
                UtimeToSecondsString(utime).c_str(), pose.translation.x(), pose.translation.y(),
                pose.translation.z(), q.x(), q.y(), q.z(), q.w());
  return buf;
}

Status WriteTumTrajectory(const std::string& path, const Trajectory& trajectory,
                          const std::string& header_comment) {
  std::string text;
  if (!header_comment.empty()) {
    text += "# " + header_comment + "\n";
  }
  text += "# timestamp tx ty tz qx qy qz qw\n";
  for (const auto& p : trajectory) {
    text += FormatTumLine(p.utime, p.pose) + "\n";
  }
  return WriteStringAtomically(path, text);
}

Status ReadTartanAirPoses(const std::string& path, int64_t frame_period_us,
                          Trajectory* trajectory) {
  std::string text;
  MBSLAM_RETURN_IF_ERROR(ReadFileToString(path, &text));
  trajectory->clear();
  // Columns of ned_from_cam: camera x (right) = NED y, camera y (down) = NED z, camera z
  // (forward) = NED x.
  Eigen::Matrix3d ned_from_cam;
  ned_from_cam << 0, 0, 1, 1, 0, 0, 0, 1, 0;
  const Rigid3d ned_from_cam_pose(ned_from_cam, Eigen::Vector3d::Zero());
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  int64_t index = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const auto tokens = Tokens(line);
    if (tokens.empty()) {
      continue;
    }
    if (tokens.size() != 7) {
      return Status::Error(path + ":" + std::to_string(line_no) +
                           ": expected 7 values (tx ty tz qx qy qz qw)");
    }
    double v[7];
    for (int k = 0; k < 7; ++k) {
      if (!ParseDouble(tokens[static_cast<size_t>(k)], &v[k])) {
        return Status::Error(path + ":" + std::to_string(line_no) + ": bad number");
      }
    }
    TimedPose p;
    p.utime = index++ * frame_period_us;
    p.pose = PoseFromXyzQxyzw(v) * ned_from_cam_pose;
    trajectory->push_back(p);
  }
  return Status::Ok();
}

std::vector<AssociatedPair> AssociateByTime(const Trajectory& est, const Trajectory& gt,
                                            int64_t max_dt_us) {
  std::vector<AssociatedPair> candidates;
  if (gt.empty()) {
    return candidates;
  }
  for (size_t i = 0; i < est.size(); ++i) {
    const int64_t t = est[i].utime;
    auto it = std::lower_bound(gt.begin(), gt.end(), t,
                               [](const TimedPose& p, int64_t time) { return p.utime < time; });
    // Nearest neighbours on both sides.
    for (int side = 0; side < 2; ++side) {
      if (side == 0 && it == gt.end()) {
        continue;
      }
      if (side == 1 && it == gt.begin()) {
        continue;
      }
      const auto jt = side == 0 ? it : std::prev(it);
      const int64_t dt = t - jt->utime;
      if (std::llabs(dt) <= max_dt_us) {
        candidates.push_back({i, static_cast<size_t>(jt - gt.begin()), dt});
      }
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const AssociatedPair& a, const AssociatedPair& b) {
                     return std::llabs(a.dt_us) < std::llabs(b.dt_us);
                   });
  std::vector<bool> est_used(est.size(), false), gt_used(gt.size(), false);
  std::vector<AssociatedPair> pairs;
  for (const auto& c : candidates) {
    if (est_used[c.est] || gt_used[c.gt]) {
      continue;
    }
    est_used[c.est] = gt_used[c.gt] = true;
    pairs.push_back(c);
  }
  std::sort(pairs.begin(), pairs.end(),
            [](const AssociatedPair& a, const AssociatedPair& b) { return a.est < b.est; });
  return pairs;
}

}  // namespace eval
}  // namespace mbslam
