#include "services/perception/tracking/orb_features.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <unordered_map>

#include <opencv2/features2d.hpp>

namespace mbslam {

namespace {

constexpr int kPatchSize = 31;  // ORB's patch (and edge threshold) (px)

cv::Ptr<cv::ORB> SingleLevelOrb(int max_features, int fast_threshold) {
  return cv::ORB::create(
      max_features, 1.2f, /*nlevels=*/1, /*edgeThreshold=*/kPatchSize, /*firstLevel=*/0,
      /*WTA_K=*/2, cv::ORB::HARRIS_SCORE, /*patchSize=*/kPatchSize, fast_threshold);
}

void CopyRow(const cv::Mat& desc, int row, OrbDescriptor* out) {
  std::memcpy(out->bits.data(), desc.ptr<uint8_t>(row), out->bits.size());
}

}  // namespace

int HammingDistance(const uint8_t* a, const uint8_t* b, int bytes) {
  int d = 0;
  int k = 0;
  for (; k + 8 <= bytes; k += 8) {
    uint64_t x, y;
    std::memcpy(&x, a + k, 8);
    std::memcpy(&y, b + k, 8);
    d += __builtin_popcountll(x ^ y);
  }
  for (; k < bytes; ++k) d += __builtin_popcount(static_cast<unsigned>(a[k] ^ b[k]));
  return d;
}

namespace {

// Half-widths of the rows of ORB's orientation disc (radius 15): round(sqrt(r^2 - v^2))
// near the centre, and beyond 45 deg the transposed disc's columns, so that the disc
// is the same under swapping u and v (as ORB builds it; a disc from the formula alone
// differs in a few rows and turns the angle by up to several degrees, enough to change
// the descriptor's rotation bin).
std::array<int, 16> OrientationDiscRows() {
  constexpr int kRadius = 15;
  std::array<int, kRadius + 1> rows{};
  const int inner = static_cast<int>(std::floor(kRadius * std::sqrt(2.0) / 2.0 + 1.0));
  const int outer = static_cast<int>(std::ceil(kRadius * std::sqrt(2.0) / 2.0));
  std::array<int, kRadius + 2> formula{};
  for (int v = 0; v <= inner; ++v)
    formula[static_cast<size_t>(v)] =
        static_cast<int>(std::lround(std::sqrt(static_cast<double>(kRadius * kRadius - v * v))));
  for (int v = 0; v < outer; ++v) rows[static_cast<size_t>(v)] = formula[static_cast<size_t>(v)];
  // Row v >= outer: the last column u (counting distinct widths) whose width reaches v.
  int u = 0;
  for (int v = kRadius; v >= outer; --v) {
    while (u + 1 <= inner && formula[static_cast<size_t>(u)] == formula[static_cast<size_t>(u + 1)])
      ++u;
    rows[static_cast<size_t>(v)] = u;
    ++u;
  }
  return rows;
}

}  // namespace

float IntensityCentroidAngle(const cv::Mat& image, const cv::Point2f& pt) {
  constexpr int kRadius = 15;
  static const std::array<int, kRadius + 1> kRows = OrientationDiscRows();
  const int cx = static_cast<int>(std::lround(pt.x)), cy = static_cast<int>(std::lround(pt.y));
  if (cx < kRadius || cy < kRadius || cx >= image.cols - kRadius || cy >= image.rows - kRadius)
    return -1.0f;
  int64_t m01 = 0, m10 = 0;
  for (int v = -kRadius; v <= kRadius; ++v) {
    const int half = kRows[static_cast<size_t>(std::abs(v))];
    const uint8_t* row = image.ptr<uint8_t>(cy + v);
    for (int u = -half; u <= half; ++u) {
      const int i = row[cx + u];
      m10 += u * i;
      m01 += v * i;
    }
  }
  return cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
}

void DescribeOrbAt(const cv::Mat& image, const std::vector<Eigen::Vector2f>& points,
                   std::vector<OrbDescriptor>* descriptors, std::vector<uint8_t>* valid) {
  descriptors->assign(points.size(), OrbDescriptor());
  valid->assign(points.size(), 0);
  if (image.empty() || image.type() != CV_8UC1) return;
  std::vector<cv::KeyPoint> kps;
  kps.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) continue;
    const cv::Point2f pt(points[i].x(), points[i].y());
    const float angle = IntensityCentroidAngle(image, pt);
    if (angle < 0.0f) continue;
    kps.emplace_back(pt, static_cast<float>(kPatchSize), angle, 0.0f, /*octave=*/0,
                     /*class_id=*/static_cast<int>(i));
  }
  if (kps.empty()) return;
  cv::Mat desc;
  SingleLevelOrb(static_cast<int>(kps.size()), 20)
      ->compute(image, kps, desc);  // drops points near the border
  for (int r = 0; r < static_cast<int>(kps.size()) && r < desc.rows; ++r) {
    const size_t i = static_cast<size_t>(kps[static_cast<size_t>(r)].class_id);
    CopyRow(desc, r, &(*descriptors)[i]);
    (*valid)[i] = 1;
  }
}

void DetectOrb(const cv::Mat& image, int max_features, int fast_threshold,
               std::vector<Eigen::Vector2f>* points, std::vector<OrbDescriptor>* descriptors) {
  points->clear();
  descriptors->clear();
  if (image.empty() || image.type() != CV_8UC1 || max_features <= 0) return;
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  SingleLevelOrb(max_features, fast_threshold)->detectAndCompute(image, cv::noArray(), kps, desc);
  for (int r = 0; r < static_cast<int>(kps.size()) && r < desc.rows; ++r) {
    points->emplace_back(kps[static_cast<size_t>(r)].pt.x, kps[static_cast<size_t>(r)].pt.y);
    descriptors->emplace_back();
    CopyRow(desc, r, &descriptors->back());
  }
}

namespace {

struct Words {
  uint64_t w[4];
};

Words WordsOf(const OrbDescriptor& d) {
  Words out;
  std::memcpy(out.w, d.bits.data(), sizeof(out.w));
  return out;
}

// For each query, the nearest and second nearest train descriptor: the brute-force
// search is most of a relocalisation's time (2 M pairs for 1000 corners and 2000 points),
// so it is built for the CPU's popcount instruction too, picked at load time.
__attribute__((target_clones("popcnt", "default"))) void NearestTwo(const std::vector<Words>& query,
                                                                    const std::vector<Words>& train,
                                                                    int* best, int* best_index,
                                                                    int* second) {
  for (size_t i = 0; i < query.size(); ++i) {
    const Words& q = query[i];
    int b1 = 257, b2 = 257, bi = -1;
    for (size_t j = 0; j < train.size(); ++j) {
      const Words& t = train[j];
      const int d = __builtin_popcountll(q.w[0] ^ t.w[0]) + __builtin_popcountll(q.w[1] ^ t.w[1]) +
                    __builtin_popcountll(q.w[2] ^ t.w[2]) + __builtin_popcountll(q.w[3] ^ t.w[3]);
      if (d < b1) {
        b2 = b1;
        b1 = d;
        bi = static_cast<int>(j);
      } else if (d < b2) {
        b2 = d;
      }
    }
    best[i] = b1;
    best_index[i] = bi;
    second[i] = b2;
  }
}

}  // namespace

namespace {

// The matches kept of each query's nearest (b1, at index bi) and second nearest (b2)
// train descriptor: within max_hamming, strictly nearer than the second (an exact tie,
// which the ratio test lets through at 0 against 0, is ambiguous too), and passing the
// ratio test; a train descriptor claimed twice goes to the nearer query (the first on a
// tie).
std::vector<std::pair<int, int>> OneToOne(const std::vector<int>& b1, const std::vector<int>& bi,
                                          const std::vector<int>& b2, size_t train_size,
                                          int max_hamming, double ratio) {
  const size_t n = b1.size();
  std::vector<int> best_of(n, -1), dist_of(n, 257);
  std::vector<int> claimed(train_size, -1);
  for (size_t i = 0; i < n; ++i) {
    if (bi[i] < 0 || b1[i] > max_hamming || b1[i] >= b2[i] ||
        static_cast<double>(b1[i]) > ratio * static_cast<double>(b2[i])) {
      continue;
    }
    const size_t j = static_cast<size_t>(bi[i]);
    if (claimed[j] >= 0) {
      const size_t other = static_cast<size_t>(claimed[j]);
      if (dist_of[other] <= b1[i]) continue;
      best_of[other] = -1;
    }
    claimed[j] = static_cast<int>(i);
    best_of[i] = bi[i];
    dist_of[i] = b1[i];
  }
  std::vector<std::pair<int, int>> matches;
  for (size_t i = 0; i < n; ++i) {
    if (best_of[i] >= 0) matches.emplace_back(static_cast<int>(i), best_of[i]);
  }
  return matches;
}

}  // namespace

std::vector<std::pair<int, int>> MatchOrb(const std::vector<OrbDescriptor>& query,
                                          const std::vector<OrbDescriptor>& train, int max_hamming,
                                          double ratio) {
  std::vector<Words> q(query.size()), t(train.size());
  for (size_t i = 0; i < query.size(); ++i) q[i] = WordsOf(query[i]);
  for (size_t j = 0; j < train.size(); ++j) t[j] = WordsOf(train[j]);
  std::vector<int> b1(query.size()), bi(query.size()), b2(query.size());
  NearestTwo(q, t, b1.data(), bi.data(), b2.data());
  return OneToOne(b1, bi, b2, train.size(), max_hamming, ratio);
}

std::vector<std::pair<int, int>> MatchOrbWithinRadius(const std::vector<Eigen::Vector2f>& query_uv,
                                                      const std::vector<OrbDescriptor>& query,
                                                      const std::vector<Eigen::Vector2f>& train_uv,
                                                      const std::vector<OrbDescriptor>& train,
                                                      double radius_px, int max_hamming,
                                                      double ratio) {
  const size_t nq = std::min(query_uv.size(), query.size());
  const size_t nt = std::min(train_uv.size(), train.size());
  std::vector<int> b1(nq, 257), bi(nq, -1), b2(nq, 257);
  if (nq == 0 || nt == 0 || !(radius_px > 0.0) || !std::isfinite(radius_px)) return {};
  // Train points hashed into cells of the radius: a query looks in its cell's 3 x 3.
  const double r = radius_px;
  const auto cell_of = [r](double u, double v) {
    return std::make_pair(static_cast<int64_t>(std::floor(u / r)),
                          static_cast<int64_t>(std::floor(v / r)));
  };
  struct CellHash {
    size_t operator()(const std::pair<int64_t, int64_t>& c) const {
      return std::hash<int64_t>()(c.first * 73856093 ^ c.second * 19349663);
    }
  };
  std::unordered_map<std::pair<int64_t, int64_t>, std::vector<int>, CellHash> grid;
  // Positions this far out are no image's (and their cell index would overflow).
  const auto usable = [](const Eigen::Vector2f& uv) {
    return uv.allFinite() && uv.cwiseAbs().maxCoeff() < 1e9f;
  };
  for (size_t j = 0; j < nt; ++j) {
    if (!usable(train_uv[j])) continue;
    grid[cell_of(train_uv[j].x(), train_uv[j].y())].push_back(static_cast<int>(j));
  }
  for (size_t i = 0; i < nq; ++i) {
    if (!usable(query_uv[i])) continue;
    const Eigen::Vector2d uv = query_uv[i].cast<double>();
    const auto [cu, cv] = cell_of(uv.x(), uv.y());
    for (int64_t du = -1; du <= 1; ++du) {
      for (int64_t dv = -1; dv <= 1; ++dv) {
        const auto g = grid.find({cu + du, cv + dv});
        if (g == grid.end()) continue;
        for (const int j : g->second) {
          if ((train_uv[static_cast<size_t>(j)].cast<double>() - uv).squaredNorm() > r * r)
            continue;
          const int d = HammingDistance(query[i], train[static_cast<size_t>(j)]);
          if (d < b1[i]) {
            b2[i] = b1[i];
            b1[i] = d;
            bi[i] = j;
          } else if (d < b2[i]) {
            b2[i] = d;
          }
        }
      }
    }
  }
  return OneToOne(b1, bi, b2, nt, max_hamming, ratio);
}

}  // namespace mbslam
