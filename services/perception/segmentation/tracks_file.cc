#include "services/perception/segmentation/tracks_file.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace mbslam {

int TrackSet::num_groups() const { return static_cast<int>(std::set<int>(labels.begin(), labels.end()).size()); }

Eigen::MatrixXd TrackSet::CompleteTrajectoryMatrix(std::vector<int>* used) const {
  used->clear();
  for (int p = 0; p < num_tracks(); ++p) {
    bool complete = true;
    for (const Eigen::Vector2d& x : positions[static_cast<size_t>(p)]) complete = complete && x.allFinite();
    if (complete) used->push_back(p);
  }
  Eigen::MatrixXd Y(2 * frames, static_cast<Eigen::Index>(used->size()));
  for (size_t c = 0; c < used->size(); ++c) {
    const auto& track = positions[static_cast<size_t>((*used)[c])];
    for (int f = 0; f < frames; ++f) {
      Y(2 * f, static_cast<Eigen::Index>(c)) = track[static_cast<size_t>(f)].x();
      Y(2 * f + 1, static_cast<Eigen::Index>(c)) = track[static_cast<size_t>(f)].y();
    }
  }
  return Y;
}

namespace {
bool ReadNumber(std::istream& in, double* v) {
  std::string token;
  if (!(in >> token)) return false;
  if (token == "nan" || token == "NaN" || token == "NAN") {
    *v = std::nan("");
    return true;
  }
  char* end = nullptr;
  *v = std::strtod(token.c_str(), &end);
  return end != token.c_str() && *end == '\0';
}
}  // namespace

Status ReadTrackSet(const std::string& path, TrackSet* out) {
  std::ifstream in(path);
  if (!in) return Status::Error("cannot open " + path);
  TrackSet t;
  const size_t slash = path.find_last_of('/');
  t.name = path.substr(slash == std::string::npos ? 0 : slash + 1);
  const size_t suffix = t.name.find(".tracks.txt");
  if (suffix != std::string::npos) t.name = t.name.substr(0, suffix);
  long long p = 0, f = 0;
  if (!(in >> p >> f >> t.width >> t.height) || p <= 0 || f <= 0 || p > 1000000 || f > 100000) {
    return Status::Error(path + ": bad header (expected 'P F width height')");
  }
  t.frames = static_cast<int>(f);
  t.labels.resize(static_cast<size_t>(p));
  for (long long i = 0; i < p; ++i) {
    if (!(in >> t.labels[static_cast<size_t>(i)])) return Status::Error(path + ": too few labels");
  }
  t.positions.assign(static_cast<size_t>(p), std::vector<Eigen::Vector2d>(static_cast<size_t>(f)));
  for (long long i = 0; i < p; ++i) {
    for (long long k = 0; k < f; ++k) {
      double x = 0, y = 0;
      if (!ReadNumber(in, &x) || !ReadNumber(in, &y)) {
        return Status::Error(path + ": track " + std::to_string(i) + " is short");
      }
      t.positions[static_cast<size_t>(i)][static_cast<size_t>(k)] = Eigen::Vector2d(x, y);
    }
  }
  *out = std::move(t);
  return Status::Ok();
}

}  // namespace mbslam
