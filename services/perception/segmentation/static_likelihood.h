#ifndef MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_STATIC_LIKELIHOOD_H_
#define MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_STATIC_LIKELIHOOD_H_

// The probability that one tracked point is static w.r.t. a body, from one image pair
// (thesis sec. 3.5-3.6, EQUATIONS.md): the epipolar constraint evaluated over an
// envelope of motions sampled from the pose uncertainty, fused with the Flow Vector
// Bound constraint through alpha from a chi-square test on the epipolar residual.

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/config/options.h"
#include "services/perception/segmentation/relative_motion.h"

namespace mbslam {

struct StaticLikelihoodOptions {
  double sigma_px = 1.0;       // feature position noise (px)
  double fvb_beta = 10.0;      // Butterworth order of P_FVB (thesis: 10)
  double fvb_margin_sigmas = 2.5;  // the flow bound is widened by this many noise sigmas
  double alpha_min = 0.01;     // epipolar weight when the epipolar constraint is met exactly
  double chi2_threshold = 3.84;  // chi-square (1 dof) value above which the epipolar test fails (95 %)
  double chi2_softness = 1.0;  // width of the transition of alpha around the threshold
  bool use_fvb = true;         // false: epipolar constraint alone (ablation)
  bool use_envelope = true;    // false: only the mean motion (no pose uncertainty)
  // How the envelope's motions combine: "mean" (weighted average of their likelihoods),
  // "max" (a track is as static as the motion in the envelope that explains it best), or
  // "max_odometry": max for ego-motion from wheel odometry, whose envelope stands for
  // errors it cannot model (a planar odometry misses roll and pitch), mean otherwise.
  std::string envelope_combine = "max_odometry";

  bool Check() const {
    MBSLAM_CHECK_OPTION_GT(sigma_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(fvb_beta, 1.0);
    MBSLAM_CHECK_OPTION_GT(fvb_margin_sigmas, 0.0);
    MBSLAM_CHECK_OPTION(alpha_min >= 0.0 && alpha_min <= 1.0);
    MBSLAM_CHECK_OPTION_GT(chi2_threshold, 0.0);
    MBSLAM_CHECK_OPTION_GT(chi2_softness, 0.0);
    MBSLAM_CHECK_OPTION(envelope_combine == "mean" || envelope_combine == "max" || envelope_combine == "max_odometry");
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("sigma_px", &sigma_px, "feature position noise (px)");
    v("fvb_beta", &fvb_beta, "Butterworth order of P_FVB (thesis: 10)");
    v("fvb_margin_sigmas", &fvb_margin_sigmas, "flow bound widened by this many noise sigmas");
    v("alpha_min", &alpha_min, "epipolar weight when the epipolar constraint holds exactly");
    v("chi2_threshold", &chi2_threshold, "chi-square (1 dof) value where the epipolar test fails");
    v("chi2_softness", &chi2_softness, "width of alpha's transition around the threshold");
    v("use_fvb", &use_fvb, "use the Flow Vector Bound constraint (false = epipolar only)");
    v("use_envelope", &use_envelope, "sample the pose uncertainty (false = mean motion only)");
    v("envelope_combine", &envelope_combine, "mean | max | max_odometry (max for wheel-odometry ego-motion, else mean): how the envelope's motions combine");
  }
};

// Depth of the point in the reference camera (units of the motion's translation when
// scale_known; otherwise only z_max = inf is meaningful).
struct DepthBound {
  double z_min = 0.0;
  double z_max = std::numeric_limits<double>::infinity();
};

struct StaticLikelihood {
  double p_static = 0.5;    // fused P(static) for this image pair [0, 1]
  double epipolar_px = 0.0; // |distance| to the mean epipolar line (px)
  double p_fvb = 1.0;       // P_FVB under the mean motion
  double alpha = 1.0;       // weight of the epipolar term under the mean motion
  double flow_along = 0.0;  // rotation-compensated flow along the epipolar direction (px)
  double parallax_px = 0.0; // rotation-compensated image motion (px): how informative the pair is
};

// `samples[0]` must be the mean motion. `translation_known` false = pure rotation: the
// static point must then stay where the rotation puts it.
StaticLikelihood ComputeStaticLikelihood(const Eigen::Vector2d& x_r, const Eigen::Vector2d& x_n,
                                         const std::vector<MotionSample>& samples,
                                         bool translation_known, bool scale_known,
                                         const DepthBound& depth, double focal_px,
                                         const StaticLikelihoodOptions& options);

// The Butterworth band probability with a noise margin: 1 inside [lo, hi], falling
// as 1 / (1 + (distance / margin)^(2 beta)) outside.
double FlowBoundProbability(double flow, double lo, double hi, double margin, double beta);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_STATIC_LIKELIHOOD_H_
