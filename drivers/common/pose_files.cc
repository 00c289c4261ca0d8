#include "drivers/common/pose_files.h"

#include <Eigen/SVD>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>

#include "common/util/atomic_file.h"

namespace mbslam {
namespace {

Status ParseDoubleField(const std::string& text, double* value) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v)) {
    return Status::Error("'" + text + "' is not a finite number");
  }
  *value = v;
  return Status::Ok();
}

bool IsCommentOrBlank(const std::string& line) {
  for (char c : line) {
    if (c == '#' || c == '%') return true;
    if (!std::isspace(static_cast<unsigned char>(c))) return false;
  }
  return true;
}

Status ReadLines(const std::string& path, std::vector<std::string>* lines) {
  std::ifstream in(path);
  if (!in) return Status::Error("cannot open " + path);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines->push_back(line);
  }
  return Status::Ok();
}

// Exact decimal to a scaled integer: digits before and up to `decimals` after the
// point, the next digit rounding.
bool ParsePlainDecimal(const std::string& text, int decimals, int64_t* scaled) {
  size_t i = 0;
  bool negative = false;
  if (i < text.size() && (text[i] == '-' || text[i] == '+')) negative = text[i++] == '-';
  int64_t whole = 0;
  bool any_digit = false;
  for (; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i) {
    if (whole > std::numeric_limits<int64_t>::max() / 100) return false;
    whole = whole * 10 + (text[i] - '0');
    any_digit = true;
  }
  int64_t fraction = 0;
  int digits = 0;
  bool round_up = false;
  if (i < text.size() && text[i] == '.') {
    ++i;
    for (; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i) {
      any_digit = true;
      if (digits < decimals) {
        fraction = fraction * 10 + (text[i] - '0');
        ++digits;
      } else if (digits == decimals) {
        round_up = text[i] >= '5';
        ++digits;
      }
    }
  }
  if (!any_digit || i != text.size()) return false;
  int64_t scale = 1;
  for (int d = 0; d < decimals; ++d) scale *= 10;
  for (int d = std::min(digits, decimals); d < decimals; ++d) fraction *= 10;
  if (whole > (std::numeric_limits<int64_t>::max() - scale) / scale) return false;
  int64_t value = whole * scale + fraction + (round_up ? 1 : 0);
  *scaled = negative ? -value : value;
  return true;
}

}  // namespace

bool IsValidTimeUnit(const std::string& unit) {
  return unit == "s" || unit == "ms" || unit == "us" || unit == "ns";
}

Status ParseTimeToUtime(const std::string& text, const std::string& unit, int64_t* utime) {
  int decimals = 6;
  double factor = 1e6;
  if (unit == "ms") {
    decimals = 3;
    factor = 1e3;
  } else if (unit == "us") {
    decimals = 0;
    factor = 1.0;
  } else if (unit == "ns") {
    factor = 1e-3;
  } else if (unit != "s") {
    return Status::Error("unknown time unit '" + unit + "' (s, ms, us, ns)");
  }
  if (unit == "ns") {
    int64_t ns = 0;
    if (ParsePlainDecimal(text, 0, &ns)) {
      *utime = ns >= 0 ? (ns + 500) / 1000 : -((-ns + 500) / 1000);
      return Status::Ok();
    }
  } else {
    int64_t scaled = 0;
    if (ParsePlainDecimal(text, decimals, &scaled)) {
      *utime = scaled;
      return Status::Ok();
    }
  }
  double value = 0.0;
  MBSLAM_RETURN_IF_ERROR(ParseDoubleField(text, &value));
  const double us = value * factor;
  if (std::abs(us) > 9e18) return Status::Error("time '" + text + "' out of range");
  *utime = static_cast<int64_t>(std::llround(us));
  return Status::Ok();
}

Status ParseSecondsToUtime(const std::string& text, int64_t* utime) {
  return ParseTimeToUtime(text, "s", utime);
}

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::string current;
  for (char c : line) {
    if (c == ' ' || c == '\t' || c == ',') {
      if (!current.empty()) fields.push_back(current);
      current.clear();
    } else {
      current += c;
    }
  }
  if (!current.empty()) fields.push_back(current);
  return fields;
}

Status QuaternionFromXyzw(double x, double y, double z, double w, Eigen::Quaterniond* q) {
  const Eigen::Quaterniond raw(w, x, y, z);
  const double norm = raw.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 0.02) {
    std::ostringstream os;
    os << "quaternion norm " << norm << " is not 1";
    return Status::Error(os.str());
  }
  *q = raw.normalized();
  return Status::Ok();
}

Status ReadTumTrajectory(const std::string& path, std::vector<TimedPose>* poses) {
  std::vector<std::string> lines;
  MBSLAM_RETURN_IF_ERROR(ReadLines(path, &lines));
  poses->clear();
  for (size_t i = 0; i < lines.size(); ++i) {
    if (IsCommentOrBlank(lines[i])) continue;
    const std::string where = path + ":" + std::to_string(i + 1);
    const std::vector<std::string> f = SplitFields(lines[i]);
    if (f.size() != 8) {
      return Status::Error(where + ": expected 't tx ty tz qx qy qz qw', got " +
                           std::to_string(f.size()) + " fields");
    }
    TimedPose p;
    MBSLAM_RETURN_IF_ERROR(ParseSecondsToUtime(f[0], &p.utime).WithContext(where));
    double v[7];
    for (int k = 0; k < 7; ++k) {
      MBSLAM_RETURN_IF_ERROR(ParseDoubleField(f[static_cast<size_t>(k) + 1], &v[k])
                                 .WithContext(where));
    }
    Eigen::Quaterniond q;
    MBSLAM_RETURN_IF_ERROR(QuaternionFromXyzw(v[3], v[4], v[5], v[6], &q).WithContext(where));
    p.pose = Rigid3d(q, Eigen::Vector3d(v[0], v[1], v[2]));
    if (!poses->empty() && p.utime <= poses->back().utime) {
      return Status::Error(where + ": time does not increase");
    }
    poses->push_back(p);
  }
  if (poses->empty()) return Status::Error(path + ": no poses");
  return Status::Ok();
}

Status WriteTumTrajectory(const std::string& path, const std::vector<TimedPose>& poses) {
  std::ostringstream out;
  out << "# timestamp tx ty tz qx qy qz qw\n" << std::setprecision(17);
  for (const TimedPose& p : poses) {
    const int64_t sec = p.utime / 1000000;
    const int64_t usec = p.utime % 1000000;
    const Eigen::Quaterniond& q = p.pose.rotation;
    out << sec << '.' << std::setw(6) << std::setfill('0') << usec << std::setfill(' ')
        << std::setw(0) << ' ' << p.pose.translation.x() << ' ' << p.pose.translation.y() << ' '
        << p.pose.translation.z() << ' ' << q.x() << ' ' << q.y() << ' ' << q.z() << ' ' << q.w()
        << '\n';
  }
  return WriteStringAtomically(path, out.str());
}

Status ReadKittiPoses(const std::string& path, std::vector<Rigid3d>* poses) {
  std::vector<std::string> lines;
  MBSLAM_RETURN_IF_ERROR(ReadLines(path, &lines));
  poses->clear();
  for (size_t i = 0; i < lines.size(); ++i) {
    if (IsCommentOrBlank(lines[i])) continue;
    const std::string where = path + ":" + std::to_string(i + 1);
    const std::vector<std::string> f = SplitFields(lines[i]);
    if (f.size() != 12) {
      return Status::Error(where + ": expected 12 numbers (3x4 row-major), got " +
                           std::to_string(f.size()));
    }
    Eigen::Matrix<double, 3, 4> m;
    for (int k = 0; k < 12; ++k) {
      MBSLAM_RETURN_IF_ERROR(
          ParseDoubleField(f[static_cast<size_t>(k)], &m(k / 4, k % 4)).WithContext(where));
    }
    const Eigen::Matrix3d r = m.leftCols<3>();
    // Files store rotations to ~9 digits: project onto SO(3).
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d rot = svd.matrixU() * svd.matrixV().transpose();
    if (rot.determinant() < 0 || (rot - r).norm() > 1e-2) {
      return Status::Error(where + ": not a rotation matrix");
    }
    poses->push_back(Rigid3d(rot, m.col(3)));
  }
  if (poses->empty()) return Status::Error(path + ": no poses");
  return Status::Ok();
}

Rigid3d NedBodyFromOptical() {
  // Columns: the optical axes (x right, y down, z forward) in the NED body frame.
  Eigen::Matrix3d r;
  r << 0, 0, 1,  //
      1, 0, 0,   //
      0, 1, 0;
  return Rigid3d(r, Eigen::Vector3d::Zero());
}

Status ReadTartanAirPoses(const std::string& path, std::vector<Rigid3d>* world_from_cam) {
  std::vector<std::string> lines;
  MBSLAM_RETURN_IF_ERROR(ReadLines(path, &lines));
  world_from_cam->clear();
  const Rigid3d body_from_optical = NedBodyFromOptical();
  for (size_t i = 0; i < lines.size(); ++i) {
    if (IsCommentOrBlank(lines[i])) continue;
    const std::string where = path + ":" + std::to_string(i + 1);
    const std::vector<std::string> f = SplitFields(lines[i]);
    if (f.size() != 7) {
      return Status::Error(where + ": expected 'tx ty tz qx qy qz qw', got " +
                           std::to_string(f.size()) + " fields");
    }
    double v[7];
    for (int k = 0; k < 7; ++k) {
      MBSLAM_RETURN_IF_ERROR(
          ParseDoubleField(f[static_cast<size_t>(k)], &v[k]).WithContext(where));
    }
    Eigen::Quaterniond q;
    MBSLAM_RETURN_IF_ERROR(QuaternionFromXyzw(v[3], v[4], v[5], v[6], &q).WithContext(where));
    world_from_cam->push_back(Rigid3d(q, Eigen::Vector3d(v[0], v[1], v[2])) * body_from_optical);
  }
  if (world_from_cam->empty()) return Status::Error(path + ": no poses");
  return Status::Ok();
}

}  // namespace mbslam
