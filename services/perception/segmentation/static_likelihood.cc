#include "services/perception/segmentation/static_likelihood.h"

#include <algorithm>
#include <cmath>

namespace mbslam {

double FlowBoundProbability(double flow, double lo, double hi, double margin, double beta) {
  double dist = 0.0;
  if (flow < lo) dist = lo - flow;
  else if (flow > hi) dist = flow - hi;
  if (dist <= 0.0) return 1.0;
  return 1.0 / (1.0 + std::pow(dist / margin, 2.0 * beta));
}

namespace {

struct PairTerms {
  double d_epi = 0.0;  // normalised units
  double p_fvb = 1.0;
  double flow = 0.0;   // normalised units
  double parallax = 0.0;  // |x_n - p'| (normalised units)
};

PairTerms Evaluate(const Eigen::Vector2d& x_r, const Eigen::Vector2d& x_n, const MotionSample& m,
                   bool translation_known, bool scale_known, const DepthBound& depth,
                   double sigma_norm, const StaticLikelihoodOptions& o) {
  PairTerms out;
  // Rotation compensation with the infinite homography: p' = R x_r.
  const Eigen::Vector3d rx = m.R * x_r.homogeneous();
  const double margin = o.fvb_margin_sigmas * sigma_norm;
  if (rx.z() <= 1e-9) {  // the point went behind the camera under this motion
    out.d_epi = 1.0;
    out.p_fvb = 0.0;
    return out;
  }
  const Eigen::Vector2d p = rx.hnormalized();
  out.parallax = (x_n - p).norm();
  if (!translation_known || m.t.norm() < 1e-12) {
    // Pure rotation: a static point stays at p'. Treat the whole residual as both the
    // epipolar and the flow term.
    const double r = (x_n - p).norm();
    out.d_epi = r;
    out.flow = r;
    out.p_fvb = FlowBoundProbability(r, 0.0, 0.0, margin, o.fvb_beta);
    return out;
  }
  out.d_epi = std::abs(EpipolarDistance(m.E, x_r, x_n));
  // Static point at depth z' (after rotation): x_n = p' + (t_xy - t_z p') / (z' + t_z).
  const DepthFlow df = DepthFlowAt(p, m.t, x_n);
  if (!df.valid) {  // the point sits on the epipole: no flow information
    out.p_fvb = 1.0;
    return out;
  }
  const double dir_norm = df.dir_norm;
  out.flow = df.flow;
  double lo = 0.0;
  double hi = std::numeric_limits<double>::infinity();
  if (scale_known) {
    const double s = rx.z();  // z' = z_r * (R x_r)_z
    const double zmin = depth.z_min * s, zmax = depth.z_max * s;
    if (std::isfinite(zmax) && zmax + m.t.z() > 0.0) lo = dir_norm / (zmax + m.t.z());
    if (zmin + m.t.z() > 1e-12) hi = dir_norm / (zmin + m.t.z());
  }
  out.p_fvb = FlowBoundProbability(out.flow, lo, hi, margin, o.fvb_beta);
  return out;
}

}  // namespace

StaticLikelihood ComputeStaticLikelihood(const Eigen::Vector2d& x_r, const Eigen::Vector2d& x_n,
                                         const std::vector<MotionSample>& samples,
                                         bool translation_known, bool scale_known,
                                         const DepthBound& depth, double focal_px,
                                         const StaticLikelihoodOptions& o) {
  StaticLikelihood out;
  if (samples.empty()) return out;
  const double sigma = o.sigma_px / focal_px;
  const size_t count = o.use_envelope ? samples.size() : 1;
  const bool use_max = o.envelope_combine == "max";
  double weight_sum = 0.0, p = 0.0, p_max = 0.0;
  for (size_t j = 0; j < count; ++j) {
    const MotionSample& m = samples[j];
    const double w = o.use_envelope ? m.weight : 1.0;
    const PairTerms terms = Evaluate(x_r, x_n, m, translation_known, scale_known, depth, sigma, o);
    const double s = terms.d_epi / sigma;
    const double p_ep = std::exp(-0.5 * s * s);
    // Chi-square (1 dof) test of the epipolar residual: alpha -> 1 when it fails (the
    // FVB is then inconsequential), alpha_min when it passes (the FVB decides).
    const double pass = 1.0 / (1.0 + std::exp(-(s * s - o.chi2_threshold) / o.chi2_softness));
    const double alpha = o.alpha_min + (1.0 - o.alpha_min) * pass;
    const double p_j = o.use_fvb ? alpha * p_ep + (1.0 - alpha) * terms.p_fvb : p_ep;
    p += w * p_j;
    p_max = std::max(p_max, p_j);
    weight_sum += w;
    if (j == 0) {
      out.epipolar_px = terms.d_epi * focal_px;
      out.p_fvb = terms.p_fvb;
      out.alpha = alpha;
      out.flow_along = terms.flow * focal_px;
      out.parallax_px = terms.parallax * focal_px;
    }
  }
  if (use_max) out.p_static = std::clamp(p_max, 0.0, 1.0);
  else out.p_static = weight_sum > 0.0 ? std::clamp(p / weight_sum, 0.0, 1.0) : 0.5;
  return out;
}

}  // namespace mbslam
