#include "services/perception/geometry/essential.h"

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>

namespace mbslam {
namespace {

// Monomials in (x, y, z) of degree <= 3, in the order the elimination needs: the ten
// cubics first (they are eliminated), then the ten of degree <= 2 (the quotient ring's
// basis; the solutions are the eigenvectors of x's action on them).
constexpr int kMonomials = 20;
constexpr int kBasis = 10;
constexpr std::array<std::array<int, 3>, kMonomials> kExponents = {{
    {3, 0, 0}, {2, 1, 0}, {2, 0, 1}, {1, 2, 0}, {1, 1, 1}, {1, 0, 2}, {0, 3, 0}, {0, 2, 1}, {0, 1, 2}, {0, 0, 3},
    {2, 0, 0}, {1, 1, 0}, {1, 0, 1}, {0, 2, 0}, {0, 1, 1}, {0, 0, 2}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, 0},
}};
// The basis monomials x, y, z and 1 (indices into kExponents).
constexpr int kX = 16, kY = 17, kZ = 18, kOne = 19;
// A linear polynomial's coefficients, in the order x, y, z, 1.
constexpr std::array<int, 4> kLinear = {kX, kY, kZ, kOne};

struct Tables {
  std::array<std::array<int, 4>, 4> lin_lin;             // index of lin_i * lin_j
  std::array<std::array<int, 4>, kBasis> quad_lin;       // index of basis_i * lin_j
  std::array<int, kBasis> times_x;                       // index of x * basis_i
  Tables() {
    auto index_of = [](int ex, int ey, int ez) {
      for (int k = 0; k < kMonomials; ++k) {
        if (kExponents[k][0] == ex && kExponents[k][1] == ey && kExponents[k][2] == ez) return k;
      }
      return -1;
    };
    auto product = [&](int a, int b) {
      return index_of(kExponents[a][0] + kExponents[b][0], kExponents[a][1] + kExponents[b][1],
                      kExponents[a][2] + kExponents[b][2]);
    };
    for (int i = 0; i < 4; ++i) {
      for (int j = 0; j < 4; ++j) lin_lin[i][j] = product(kLinear[i], kLinear[j]);
    }
    for (int i = 0; i < kBasis; ++i) {
      for (int j = 0; j < 4; ++j) quad_lin[i][j] = product(kBasis + i, kLinear[j]);
      times_x[i] = product(kBasis + i, kX);
    }
  }
};

const Tables& GetTables() {
  static const Tables tables;
  return tables;
}

using Linear = Eigen::Vector4d;                     // x, y, z, 1
using Quadratic = Eigen::Matrix<double, kBasis, 1>;  // the basis monomials (degree <= 2)
using Cubic = Eigen::Matrix<double, kMonomials, 1>;

Quadratic Multiply(const Linear& a, const Linear& b) {
  const Tables& t = GetTables();
  Quadratic q = Quadratic::Zero();
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) q[t.lin_lin[i][j] - kBasis] += a[i] * b[j];
  }
  return q;
}

Cubic Multiply(const Quadratic& q, const Linear& l) {
  const Tables& t = GetTables();
  Cubic c = Cubic::Zero();
  for (int i = 0; i < kBasis; ++i) {
    if (q[i] == 0.0) continue;
    for (int j = 0; j < 4; ++j) c[t.quad_lin[i][j]] += q[i] * l[j];
  }
  return c;
}

}  // namespace

std::vector<Eigen::Matrix3d> FivePointEssentials(const Eigen::Vector2d x_r[5], const Eigen::Vector2d x_n[5]) {
  // Each correspondence: x_n^T E x_r = 0, linear in E's entries (row-major).
  Eigen::Matrix<double, 9, 5> Qt;
  for (int i = 0; i < 5; ++i) {
    const Eigen::Vector3d a = x_r[i].homogeneous(), b = x_n[i].homogeneous();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) Qt(3 * r + c, i) = b[r] * a[c];
    }
  }
  const Eigen::HouseholderQR<Eigen::Matrix<double, 9, 5>> qr(Qt);
  const Eigen::Matrix<double, 9, 9> Q = qr.householderQ();
  // The null space: E = x X + y Y + z Z + W, each entry a linear polynomial.
  std::array<std::array<Linear, 3>, 3> E;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      const int k = 3 * r + c;
      E[r][c] = Linear(Q(k, 5), Q(k, 6), Q(k, 7), Q(k, 8));
    }
  }
  // E E^T and its trace (quadratics).
  std::array<std::array<Quadratic, 3>, 3> EEt;
  for (int i = 0; i < 3; ++i) {
    for (int j = i; j < 3; ++j) {
      EEt[i][j] = Multiply(E[i][0], E[j][0]) + Multiply(E[i][1], E[j][1]) + Multiply(E[i][2], E[j][2]);
      EEt[j][i] = EEt[i][j];
    }
  }
  const Quadratic trace = EEt[0][0] + EEt[1][1] + EEt[2][2];
  // Ten cubic constraints: 2 E E^T E - tr(E E^T) E = 0 and det(E) = 0.
  Eigen::Matrix<double, 10, kMonomials> A;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      Cubic c = -Multiply(trace, E[i][j]);
      for (int k = 0; k < 3; ++k) c += 2.0 * Multiply(EEt[i][k], E[k][j]);
      A.row(3 * i + j) = c.transpose();
    }
  }
  const Quadratic c0 = Multiply(E[1][1], E[2][2]) - Multiply(E[1][2], E[2][1]);
  const Quadratic c1 = Multiply(E[1][2], E[2][0]) - Multiply(E[1][0], E[2][2]);
  const Quadratic c2 = Multiply(E[1][0], E[2][1]) - Multiply(E[1][1], E[2][0]);
  A.row(9) = (Multiply(c0, E[0][0]) + Multiply(c1, E[0][1]) + Multiply(c2, E[0][2])).transpose();
  // Eliminate the cubic monomials: cubic_k = -sum_j B(k, j) basis_j.
  const Eigen::Matrix<double, 10, 10> A1 = A.leftCols<kBasis>();
  const Eigen::FullPivLU<Eigen::Matrix<double, 10, 10>> lu(A1);
  std::vector<Eigen::Matrix3d> out;
  if (!lu.isInvertible()) return out;
  const Eigen::Matrix<double, 10, 10> B = lu.solve(A.rightCols<kBasis>());
  if (!B.allFinite()) return out;
  // x's action on the basis: M b = x b at every solution.
  const Tables& t = GetTables();
  Eigen::Matrix<double, 10, 10> M = Eigen::Matrix<double, 10, 10>::Zero();
  for (int i = 0; i < kBasis; ++i) {
    const int k = t.times_x[i];
    if (k >= kBasis) {
      M(i, k - kBasis) = 1.0;
    } else {
      M.row(i) = -B.row(k);
    }
  }
  const Eigen::EigenSolver<Eigen::Matrix<double, 10, 10>> es(M, /*computeEigenvectors=*/true);
  if (es.info() != Eigen::Success) return out;
  for (int k = 0; k < kBasis; ++k) {
    // Real eigenvalues come from the real Schur form's 1x1 blocks: their imaginary parts
    // are exactly zero.
    if (es.eigenvalues()[k].imag() != 0.0) continue;
    const Eigen::Matrix<double, 10, 1> v = es.eigenvectors().col(k).real();
    const double w = v[kOne - kBasis];
    if (!(std::abs(w) > 1e-12 * v.norm())) continue;
    const double x = v[kX - kBasis] / w, y = v[kY - kBasis] / w, z = v[kZ - kBasis] / w;
    Eigen::Matrix3d Em;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) Em(r, c) = E[r][c].dot(Linear(x, y, z, 1.0));
    }
    const double norm = Em.norm();
    if (!(norm > 0.0) || !Em.allFinite()) continue;
    out.push_back(Em / norm);
  }
  return out;
}

double SampsonDistanceSquared(const Eigen::Matrix3d& E, const Eigen::Vector2d& x_r, const Eigen::Vector2d& x_n) {
  const Eigen::Vector3d a = x_r.homogeneous(), b = x_n.homogeneous();
  const Eigen::Vector3d Ea = E * a, Etb = E.transpose() * b;
  const double r = b.dot(Ea);
  const double d = Ea[0] * Ea[0] + Ea[1] * Ea[1] + Etb[0] * Etb[0] + Etb[1] * Etb[1];
  if (!(d > 0.0)) return r == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  return r * r / d;
}

namespace {

// Samples needed for `confidence` that one was all inliers, given the outlier share
// (never more than `current`).
int UpdateIterations(double confidence, double outlier_share, int current) {
  const double num = std::log(std::max(1.0 - confidence, DBL_MIN));
  const double all_inliers = 1.0 - std::pow(1.0 - outlier_share, 5);
  if (all_inliers < DBL_MIN) return 0;
  const double denom = std::log(all_inliers);
  if (denom >= 0.0 || -num >= current * -denom) return current;
  return static_cast<int>(std::lround(num / denom));
}

}  // namespace

Status EstimateEssentialRansac(const std::vector<Eigen::Vector2d>& x_r, const std::vector<Eigen::Vector2d>& x_n,
                               const EssentialRansacOptions& options, EssentialRansacResult* result) {
  if (!options.Check()) return Status::Error("essential RANSAC: invalid options");
  const int n = static_cast<int>(x_r.size());
  if (n < 5 || x_n.size() != x_r.size()) {
    return Status::Error("essential RANSAC: needs 5 or more correspondences (" + std::to_string(n) + ")");
  }
  const double t2 = options.threshold * options.threshold;
  std::mt19937 rng(options.seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  int best_count = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  Eigen::Matrix3d best_E = Eigen::Matrix3d::Zero();
  int iterations = options.max_iterations;
  const int min_iterations = std::min(options.min_iterations, options.max_iterations);
  int drawn = 0;
  Eigen::Vector2d sr[5], sn[5];
  for (int iter = 0; iter < std::max(iterations, min_iterations); ++iter) {
    int idx[5];
    for (int k = 0; k < 5; ++k) {
      bool repeated = true;
      while (repeated) {
        idx[k] = pick(rng);
        repeated = std::find(idx, idx + k, idx[k]) != idx + k;
      }
      sr[k] = x_r[idx[k]];
      sn[k] = x_n[idx[k]];
    }
    ++drawn;
    for (const Eigen::Matrix3d& E : FivePointEssentials(sr, sn)) {
      int count = 0;
      if (options.msac) {
        double cost = 0.0;
        for (int i = 0; i < n && cost < best_cost; ++i) {
          const double e2 = SampsonDistanceSquared(E, x_r[i], x_n[i]);
          count += e2 <= t2;
          cost += e2 < t2 ? e2 : t2;  // a NaN distance (an infinite coordinate) costs the cap
        }
        // Only a lower cost is kept (a model cut short above the best is not).
        if (!(cost < best_cost)) continue;
        best_cost = cost;
      } else {
        for (int i = 0; i < n; ++i) {
          count += SampsonDistanceSquared(E, x_r[i], x_n[i]) <= t2;
          // The rest cannot make it better than the best: only a larger count is kept.
          if (count + (n - 1 - i) <= best_count) break;
        }
        if (count <= best_count) continue;
      }
      best_E = E;
      if (count > best_count) {
        best_count = count;
        iterations = UpdateIterations(options.confidence, static_cast<double>(n - count) / n, iterations);
      }
    }
  }
  if (best_count == 0) return Status::Error("essential RANSAC: no sample gave a model");
  result->E = best_E;
  result->inliers.assign(n, 0);
  result->num_inliers = 0;
  for (int i = 0; i < n; ++i) {
    result->inliers[i] = SampsonDistanceSquared(best_E, x_r[i], x_n[i]) <= t2 ? 1 : 0;
    result->num_inliers += result->inliers[i];
  }
  result->iterations = drawn;
  return Status::Ok();
}

}  // namespace mbslam
