#include "services/perception/tracking/feature_tracker.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <unordered_map>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "common/util/parallel_for.h"
#include "common/util/statistics.h"
#include "services/perception/geometry/patch_warp.h"
#include "services/perception/geometry/polygon.h"
#include "services/perception/tracking/disc_stamp.h"
#include "services/perception/tracking/klt.h"
#include "services/perception/tracking/orb_features.h"
#include "services/perception/tracking/patch_matcher.h"

namespace mbslam {

FeatureTracker::FeatureTracker(const TrackerOptions& options) : options_(options) {}

void FeatureTracker::Reset() {
  tracks_.clear();
  recently_lost_.clear();
  prev_pyramid_.clear();
  prev_klt_pyramid_ = KltPyramid();
  last_rejected_ = false;
  last_median_flow_px_ = 0.0;
}

namespace {

bool InBorder(const Eigen::Vector2f& uv, const cv::Mat& image, float border) {
  return uv.x() >= border && uv.y() >= border && uv.x() <= image.cols - 1 - border &&
         uv.y() <= image.rows - 1 - border;
}

// The brightness change of one image to the next, as the map that undoes it:
// previous ~ gain * new + offset; mean_change is the new image's mean minus the previous
// one's (grey levels).
struct ExposureChange {
  double gain = 1.0;
  double offset = 0.0;
  double mean_change = 0.0;
};

// From the same scene points seen in both images (a track's template and its new patch):
// the line through the patches' mean grey levels, previous = gain * new + offset, fitted
// as the principal axis with outliers (wrong matches, a mover's changing shade) trimmed
// at three robust standard deviations. Means, not contrasts: a patch sampled between
// pixels is smoother than one sampled on them, so contrast ratios are biased, means are
// not. With too narrow a spread of means (under 10 grey levels) for a slope, the gain
// is 1 and only the offset is measured.
// At most kMaxExposurePairs pairs, evenly spaced, take part.
double PatchMean(const cv::Mat& patch) {
  uint32_t sum = 0;  // patches are small: no overflow
  for (int r = 0; r < patch.rows; ++r) {
    const uint8_t* p = patch.ptr<uint8_t>(r);
    for (int c = 0; c < patch.cols; ++c) sum += p[c];
  }
  return static_cast<double>(sum) / static_cast<double>(patch.total());
}

std::optional<ExposureChange> ExposureChangeOfPatches(const std::vector<std::pair<const cv::Mat*, const cv::Mat*>>& pairs) {
  constexpr size_t kMaxExposurePairs = 64;
  std::vector<double> x, y;  // new, previous means
  const size_t stride = std::max<size_t>(1, (pairs.size() + kMaxExposurePairs - 1) / kMaxExposurePairs);
  for (size_t i = 0; i < pairs.size(); i += stride) {
    const auto& [old_patch, new_patch] = pairs[i];
    if (old_patch->type() != CV_8UC1 || new_patch->type() != CV_8UC1 || old_patch->empty() || new_patch->empty()) continue;
    x.push_back(PatchMean(*new_patch));
    y.push_back(PatchMean(*old_patch));
  }
  const size_t n = x.size();
  if (n < 8) return std::nullopt;
  ExposureChange c;
  std::vector<double> d(n);
  for (size_t i = 0; i < n; ++i) d[i] = x[i] - y[i];
  c.mean_change = Median(d);
  std::vector<uint8_t> in(n, 1);
  for (int round = 0; round < 3; ++round) {
    double sx = 0.0, sy = 0.0, m = 0.0;
    for (size_t i = 0; i < n; ++i) {
      if (!in[i]) continue;
      sx += x[i];
      sy += y[i];
      m += 1.0;
    }
    if (m < 8.0) return std::nullopt;
    const double mx = sx / m, my = sy / m;
    double sxx = 0.0, sxy = 0.0, syy = 0.0;
    for (size_t i = 0; i < n; ++i) {
      if (!in[i]) continue;
      sxx += (x[i] - mx) * (x[i] - mx);
      sxy += (x[i] - mx) * (y[i] - my);
      syy += (y[i] - my) * (y[i] - my);
    }
    // The principal axis (total least squares): both means carry the same noise, and
    // regressing one on the other would pull the gain towards 0.
    const double tls = sxy != 0.0 ? (syy - sxx + std::sqrt((syy - sxx) * (syy - sxx) + 4.0 * sxy * sxy)) / (2.0 * sxy) : 1.0;
    c.gain = std::sqrt(sxx / m) >= 10.0 && tls > 0.0 ? tls : 1.0;
    c.offset = my - c.gain * mx;
    std::vector<double> r(n);  // vertical distances (the gain is near 1)
    for (size_t i = 0; i < n; ++i) r[i] = std::abs(y[i] - (c.gain * x[i] + c.offset));
    const double sigma = std::max(1.0, kMadToSigma * Median(r));
    for (size_t i = 0; i < n; ++i) in[i] = r[i] <= 3.0 * sigma;
  }
  return c;
}

// From the two whole images' means and standard deviations (consecutive images see
// nearly the same scene); nullopt for a flat image.
std::optional<ExposureChange> ExposureChangeOfImages(const cv::Mat& previous, const cv::Mat& image) {
  cv::Scalar mp, sp, mn, sn;
  cv::meanStdDev(previous, mp, sp);
  cv::meanStdDev(image, mn, sn);
  if (!(sn[0] > 1.0) || !(sp[0] > 1.0)) return std::nullopt;
  ExposureChange c;
  c.gain = sp[0] / sn[0];
  c.offset = mp[0] - c.gain * mn[0];
  c.mean_change = mn[0] - mp[0];
  return c;
}

// `pyramid` (as cv::buildOpticalFlowPyramid made it: its levels, borders and
// derivative levels) of the image gain * image + offset (saturated to 8 bits).
std::vector<cv::Mat> ExposureCorrected(const std::vector<cv::Mat>& pyramid, double gain, double offset) {
  cv::Mat corrected;
  pyramid[0].convertTo(corrected, CV_8U, gain, offset);
  cv::Size whole;
  cv::Point ofs;
  pyramid[0].locateROI(whole, ofs);
  const bool derivatives = pyramid.size() > 1 && pyramid[1].type() != CV_8UC1;
  const int levels = static_cast<int>(pyramid.size() / (derivatives ? 2 : 1)) - 1;
  std::vector<cv::Mat> out;
  cv::buildOpticalFlowPyramid(corrected, out, cv::Size(ofs.x, ofs.y), levels, derivatives);
  return out;
}

// An image's pyramid for KLT: as built (OpenCV's KLT reads it) and as the project's KLT
// reads it (floats, converted once per image; empty with the OpenCV backend).
struct LkPyramid {
  const std::vector<cv::Mat>& bytes;
  const KltPyramid& floats;
};

// Pyramidal KLT from the initial guesses in `next`. Every point is tracked independently,
// so the points are split into `threads` contiguous chunks run concurrently; the result
// is identical to one call.
void TrackLk(const LkPyramid& from, const LkPyramid& to, const std::vector<cv::Point2f>& pts,
             std::vector<cv::Point2f>* next, std::vector<uint8_t>* status, int window_px, int max_level,
             const TrackerOptions& o, int threads) {
  auto track = [&](const std::vector<cv::Point2f>& p, std::vector<cv::Point2f>* q, std::vector<uint8_t>* st) {
    if (o.klt_backend == "opencv") {
      std::vector<float> err;
      const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, o.klt_max_iterations,
                                  o.klt_epsilon);
      cv::calcOpticalFlowPyrLK(from.bytes, to.bytes, p, *q, *st, err, cv::Size(window_px, window_px), max_level,
                               term, cv::OPTFLOW_USE_INITIAL_FLOW);
      return;
    }
    KltParams params;
    params.window_px = window_px;
    params.max_level = max_level;
    params.max_iterations = o.klt_max_iterations;
    params.epsilon_px = o.klt_epsilon;
    params.min_eigen = o.klt_min_eigen;
    TrackPointsKlt(from.floats, to.floats, p, q, st, params);
  };
  const size_t n = pts.size();
  constexpr size_t kMinPointsPerThread = 150;
  const size_t chunks = std::max<size_t>(1, std::min<size_t>(static_cast<size_t>(std::max(1, threads)),
                                                             n / kMinPointsPerThread));
  if (chunks <= 1) {
    track(pts, next, status);
    return;
  }
  status->assign(n, 0);
  auto run = [&](size_t begin, size_t end) {
    std::vector<cv::Point2f> p(pts.begin() + begin, pts.begin() + end);
    std::vector<cv::Point2f> q(next->begin() + begin, next->begin() + end);
    std::vector<uint8_t> st;
    track(p, &q, &st);
    std::copy(q.begin(), q.end(), next->begin() + begin);
    std::copy(st.begin(), st.end(), status->begin() + begin);
  };
  ParallelFor(chunks, static_cast<int>(chunks), [&](size_t c) { run(n * c / chunks, n * (c + 1) / chunks); });
}

}  // namespace

void FeatureTracker::TrackFrame(const std::vector<cv::Mat>& pyramid, int64_t frame_index,
                           const TrackingHints& hints) {
  stats_ = TrackerStats();
  frame_index_ = frame_index;
  recently_lost_.clear();
  // The image tracked: this one, or (exposure_compensation) its exposure-corrected copy.
  std::vector<cv::Mat> corrected_pyramid;
  const std::vector<cv::Mat>* tracked_pyramid = &pyramid;
  cv::Mat image = pyramid[0];
  KltPyramid klt_pyramid;
  if (options_.klt_backend != "opencv") klt_pyramid = MakeKltPyramid(pyramid);
  if (prev_pyramid_.empty()) {
    tracks_.clear();
    DetectNew(image, frame_index);
    prev_pyramid_ = pyramid;
    prev_klt_pyramid_ = std::move(klt_pyramid);
    return;
  }
  const LkPyramid prev_lk{prev_pyramid_, prev_klt_pyramid_};

  const float border = static_cast<float>(options_.border_px);
  // Nothing in tracks_ changes until the glitch test below has passed (a glitch image
  // leaves them as they were).
  std::vector<Track> next_tracks;
  next_tracks.reserve(tracks_.size() + 64);
  std::vector<size_t> klt_index;  // into tracks_
  std::vector<cv::Point2f> prev_pts, next_pts;
  std::vector<std::pair<size_t, Eigen::Vector2f>> reappearing;  // occluded, predicted visible
  std::vector<std::pair<size_t, Eigen::Vector2f>> still_occluded;  // occluded, predicted behind a hull

  // Predictions. Tracks already occluded stay so while their predicted position is
  // inside a hull of another body; outside, they are re-detected on their template.
  std::vector<Eigen::Vector2f> predicted(tracks_.size());
  auto inside_other_hull = [&hints](const Track& t, const Eigen::Vector2f& p) {
    for (const TrackingHints::Hull& h : hints.occluders) {
      if (h.body_id != t.body_id && InsideConvexHull(h.points, p)) return true;
    }
    return false;
  };
  for (size_t i = 0; i < tracks_.size(); ++i) {
    const Track& t = tracks_[i];
    auto it = hints.predicted_uv.find(t.id);
    const Eigen::Vector2f pred =
        it != hints.predicted_uv.end() ? it->second : Eigen::Vector2f(t.uv + t.velocity);
    predicted[i] = pred;
    if (!pred.allFinite()) continue;
    if (t.status == TrackStatus::kOccluded) {
      if (inside_other_hull(t, pred)) {
        if (t.occluded_frames >= options_.max_occluded_frames || !InBorder(pred, image, border)) continue;
        still_occluded.emplace_back(i, pred);
      } else {
        reappearing.emplace_back(i, pred);
      }
      continue;
    }
    klt_index.push_back(i);
    prev_pts.emplace_back(t.uv.x(), t.uv.y());
    next_pts.emplace_back(pred.x(), pred.y());
  }

  // Stage 1: KLT from the predicted positions, forward then backward, and the checks.
  stats_.fast_motion = options_.klt_fast_flow_px > 0.0 && last_median_flow_px_ > options_.klt_fast_flow_px;
  const int win_px = stats_.fast_motion ? options_.klt_fast_window_px : options_.klt_window_px;
  const int max_level = (stats_.fast_motion ? options_.klt_fast_levels : options_.klt_levels) - 1;
  const float fb2 = static_cast<float>(options_.max_forward_backward_px *
                                       options_.max_forward_backward_px);
  const float a = static_cast<float>(options_.velocity_smoothing);
  const std::vector<cv::Point2f> guesses = next_pts;
  std::vector<uint8_t> status, back_status;
  std::vector<cv::Point2f> back_pts;
  // Which tracks KLT matched (forward-backward, border, appearance).
  std::vector<uint8_t> matched;
  // Each patch has its own buffer: map points keep their track's latest patch (a shallow
  // copy), and a view into one per-image buffer would keep that whole buffer alive.
  std::vector<cv::Mat> patches;
  auto match_all = [&](const LkPyramid& lk, const cv::Mat& img) {
    next_pts = guesses;
    status.clear();
    back_status.clear();
    back_pts.clear();
    matched.assign(prev_pts.size(), 0);
    patches.assign(prev_pts.size(), cv::Mat());
    stats_.lost_forward = stats_.lost_backward = stats_.lost_consistency = stats_.lost_border = 0;
    stats_.lost_appearance = stats_.established = stats_.established_matched = 0;
    if (!prev_pts.empty()) {
      TrackLk(prev_lk, lk, prev_pts, &next_pts, &status, win_px, max_level, options_,
              options_.klt_threads);
      // Wide search: a failed prediction (a body that changed its motion) is retried
      // from the previous position.
      std::vector<size_t> retry;
      std::vector<cv::Point2f> retry_prev, retry_next;
      for (size_t k = 0; k < prev_pts.size(); ++k) {
        const cv::Point2f guess_offset = next_pts[k] - prev_pts[k];
        if (!status[k] && guess_offset.dot(guess_offset) > 1.0f) {
          retry.push_back(k);
          retry_prev.push_back(prev_pts[k]);
          retry_next.push_back(prev_pts[k]);
        }
      }
      if (!retry.empty()) {
        std::vector<uint8_t> rs;
        TrackLk(prev_lk, lk, retry_prev, &retry_next, &rs, win_px, max_level, options_, 1);
        for (size_t r = 0; r < retry.size(); ++r) {
          if (rs[r]) {
            status[retry[r]] = 1;
            next_pts[retry[r]] = retry_next[r];
          }
        }
      }
      back_pts = prev_pts;
      back_status.assign(prev_pts.size(), 0);
      // The backward pass starts where the track came from; with fewer levels it is faster
      // but lets more false matches through (7.5 % of tracks on an unrelated image with 3
      // levels, 10 % with 2, 11.6 % with 1: feature_tracker_test). Only the points the
      // forward pass found go back (each point is tracked on its own: the same result).
      std::vector<size_t> found;
      std::vector<cv::Point2f> found_next, found_back;
      for (size_t k = 0; k < prev_pts.size(); ++k) {
        if (!status[k]) continue;
        found.push_back(k);
        found_next.push_back(next_pts[k]);
        found_back.push_back(prev_pts[k]);
      }
      if (!found.empty()) {
        std::vector<uint8_t> found_status;
        TrackLk(lk, prev_lk, found_next, &found_back, &found_status, win_px,
                options_.klt_backward_levels - 1, options_, options_.klt_threads);
        for (size_t f = 0; f < found.size(); ++f) {
          back_pts[found[f]] = found_back[f];
          back_status[found[f]] = found_status[f];
        }
      }
    }

    for (size_t k = 0; k < prev_pts.size(); ++k) {
      const Track& t = tracks_[klt_index[k]];
      const Eigen::Vector2f next(next_pts[k].x, next_pts[k].y);
      const cv::Point2f d = back_pts[k] - prev_pts[k];
      if (!status[k]) {
        ++stats_.lost_forward;
      } else if (!back_status[k]) {
        ++stats_.lost_backward;
      } else if (!(d.dot(d) <= fb2) || !next.allFinite()) {
        ++stats_.lost_consistency;
      } else if (!InBorder(next, img, border)) {
        ++stats_.lost_border;
      } else {
        matched[k] = ExtractPatch(img, next, options_.patch_size, &patches[k]) &&
                     (t.patch.empty() || PatchNcc(patches[k], t.patch) >= options_.min_patch_ncc) &&
                     (t.anchor.empty() || PatchNcc(patches[k], t.anchor) >= options_.min_anchor_ncc);
        stats_.lost_appearance += !matched[k];
      }
      if (t.age >= 3) {
        ++stats_.established;
        stats_.established_matched += matched[k];
      }
    }
  };
  // Images far apart in time (tracking.wide_baseline_min_interval_us): most tracks lost
  // is what such a baseline does, not a glitch.
  const bool wide_baseline =
      options_.wide_baseline_min_interval_us > 0 && hints.interval_us >= options_.wide_baseline_min_interval_us;
  auto is_glitch = [&]() {
    return options_.glitch_max_survival > 0.0 && !wide_baseline && !last_rejected_ &&
           stats_.established >= options_.glitch_min_tracks &&
           static_cast<double>(stats_.established_matched) <
               options_.glitch_max_survival * static_cast<double>(stats_.established);
  };
  match_all(LkPyramid{pyramid, klt_pyramid}, image);

  // An exposure step (automatic exposure; KLT assumes constant brightness): detected on
  // the matched tracks' patches against their templates, or by an image that looks like
  // a glitch (its few matches may be wrong), and confirmed on the whole images. The first correction maps the image's
  // mean and standard deviation onto the previous image's (the matches under a step are
  // off target, their patches a poor measure); the image is tracked again, and the
  // remaining change is measured on the new, aligned matches and undone, at most
  // kMaxCorrections times in all. The last correction stands if it keeps at least as
  // many established tracks as the image as it came, else none does.
  if (options_.exposure_compensation) {
    constexpr size_t kMinExposurePairs = 20;
    constexpr int kMaxCorrections = 3;
    auto measure = [&]() -> std::optional<ExposureChange> {
      std::vector<std::pair<const cv::Mat*, const cv::Mat*>> pairs;  // (template, new patch)
      for (size_t k = 0; k < prev_pts.size(); ++k) {
        const Track& t = tracks_[klt_index[k]];
        if (matched[k] && !t.patch.empty()) pairs.emplace_back(&t.patch, &patches[k]);
      }
      if (pairs.size() >= kMinExposurePairs) return ExposureChangeOfPatches(pairs);
      return std::nullopt;
    };
    auto significant = [&](const ExposureChange& c) {
      return std::abs(c.mean_change) > options_.exposure_min_mean_change ||
             std::abs(c.gain - 1.0) > options_.exposure_min_contrast_change;
    };
    const std::optional<ExposureChange> on_patches = measure();
    std::optional<ExposureChange> change;
    if ((on_patches && significant(*on_patches)) || is_glitch()) {
      change = ExposureChangeOfImages(prev_pyramid_[0], pyramid[0]);
      // The whole images must show the step too: an image that looks like a glitch
      // without a change of exposure is one, and patches that disagree with the whole
      // images are wrong matches, not an exposure step.
      if (change && !significant(*change)) change.reset();
    }
    if (change) {
      // The image as it came, in case no correction does better.
      struct Attempt {
        std::vector<cv::Point2f> next_pts, back_pts;
        std::vector<uint8_t> status, back_status, matched;
        std::vector<cv::Mat> patches;
        TrackerStats stats;
        KltPyramid klt;
      };
      Attempt as_it_came{next_pts, back_pts, status, back_status, matched, patches, stats_, std::move(klt_pyramid)};
      const bool glitch_as_it_came = is_glitch();
      double gain = 1.0, offset = 0.0;
      for (int n = 0; n < kMaxCorrections && change && (n == 0 || significant(*change)); ++n) {
        // The change measured on the current image, undone on top of its own correction.
        gain = change->gain * gain;
        offset = change->gain * offset + change->offset;
        corrected_pyramid = ExposureCorrected(pyramid, gain, offset);
        klt_pyramid = KltPyramid();
        if (options_.klt_backend != "opencv") klt_pyramid = MakeKltPyramid(corrected_pyramid);
        match_all(LkPyramid{corrected_pyramid, klt_pyramid}, corrected_pyramid[0]);
        change = measure();
      }
      const bool better = !is_glitch() && (glitch_as_it_came || stats_.established_matched >=
                                                                      as_it_came.stats.established_matched);
      if (better) {
        tracked_pyramid = &corrected_pyramid;
        image = corrected_pyramid[0];
        stats_.exposure_corrected = true;
        stats_.exposure_gain = gain;
        stats_.exposure_offset = offset;
      } else {
        next_pts = std::move(as_it_came.next_pts);
        back_pts = std::move(as_it_came.back_pts);
        status = std::move(as_it_came.status);
        back_status = std::move(as_it_came.back_status);
        matched = std::move(as_it_came.matched);
        patches = std::move(as_it_came.patches);
        stats_ = as_it_came.stats;
        klt_pyramid = std::move(as_it_came.klt);
      }
    }
  }

  // A glitch image: nearly every established track lost at once. Nothing changes; the
  // last good image stays the reference.
  if (is_glitch()) {
    const TrackerStats seen = stats_;
    stats_ = TrackerStats();
    stats_.rejected = true;
    stats_.established = seen.established;
    stats_.established_matched = seen.established_matched;
    last_rejected_ = true;
    return;
  }

  for (Track& t : tracks_) t.is_new = false;
  for (const auto& [i, pred] : still_occluded) {
    Track& t = tracks_[i];
    ++t.occluded_frames;
    t.prev_uv = t.uv;
    t.uv = pred;
    ++stats_.occluded;
    next_tracks.push_back(std::move(t));
  }
  for (size_t k = 0; k < prev_pts.size(); ++k) {
    Track& t = tracks_[klt_index[k]];
    const Eigen::Vector2f next(next_pts[k].x, next_pts[k].y);
    const cv::Point2f d = back_pts[k] - prev_pts[k];
    if (!matched[k]) {
      // A failed match of a static track predicted behind a moving object's hull is an
      // occlusion (thesis sec. 2.2 c): keep it, unmatched, until it reappears.
      const Eigen::Vector2f& pred = predicted[klt_index[k]];
      if (t.body_id == 0 && t.age >= 3 && pred.allFinite() && InBorder(pred, image, border) &&
          inside_other_hull(t, pred)) {
        t.status = TrackStatus::kOccluded;
        t.occluded_frames = 1;
        t.prev_uv = t.uv;
        t.uv = pred;
        ++stats_.occluded;
        next_tracks.push_back(std::move(t));
        continue;
      }
      ++stats_.lost;
      recently_lost_.push_back(std::move(t));
      continue;
    }
    const Eigen::Vector2f flow = next - t.uv;
    t.velocity = t.age > 1 ? Eigen::Vector2f(a * flow + (1.0f - a) * t.velocity) : flow;
    t.prev_uv = t.uv;
    t.uv = next;
    t.match_error = std::sqrt(d.dot(d));
    ++t.age;
    t.last_seen_frame = frame_index;
    t.occluded_frames = 0;
    t.patch = patches[k];
    ++stats_.tracked;
    next_tracks.push_back(std::move(t));
  }

  last_rejected_ = false;
  {
    std::vector<float> flows;
    flows.reserve(next_tracks.size());
    for (const Track& t : next_tracks) {
      if (t.status == TrackStatus::kActive && t.last_seen_frame == frame_index) flows.push_back((t.uv - t.prev_uv).norm());
    }
    if (!flows.empty()) {
      std::nth_element(flows.begin(), flows.begin() + flows.size() / 2, flows.end());
      last_median_flow_px_ = flows[flows.size() / 2];
    }
    stats_.median_flow_px = last_median_flow_px_;
  }

  // Wide baseline: when KLT kept too few, ORB descriptors re-match the lost tracks.
  if (options_.descriptor_fallback && !prev_pts.empty() &&
      static_cast<double>(stats_.tracked) < options_.fallback_survival * static_cast<double>(prev_pts.size())) {
    MatchByDescriptors(prev_pyramid_[0], image, frame_index, wide_baseline, &recently_lost_, &next_tracks);
  }

  // Tracks coming out from behind a hull: re-found on their template.
  for (auto& [i, pred] : reappearing) {
    Track& t = tracks_[i];
    if (t.patch.empty() || !InBorder(pred, image, border)) continue;
    const PatchMatch m = FindPatchZssd(image, t.patch, pred, options_.guided_radius_px);
    if (!m.found || m.score > options_.max_patch_score || m.second < 1.5f * m.score) {
      ++stats_.lost;
      continue;
    }
    t.prev_uv = t.uv;
    t.uv = m.uv;
    t.status = TrackStatus::kActive;
    t.occluded_frames = 0;
    t.match_error = 0.0f;
    ++t.age;
    t.last_seen_frame = frame_index;
    ExtractPatch(image, t.uv, options_.patch_size, &t.patch);
    ++stats_.recovered;
    next_tracks.push_back(std::move(t));
  }

  tracks_ = std::move(next_tracks);
  EnforceUnicity();
  prev_pyramid_ = *tracked_pyramid;
  prev_klt_pyramid_ = std::move(klt_pyramid);
  DetectNew(image, frame_index);
  stats_.created_on_objects = DetectOnObjects(image, frame_index, hints.occluders);
  stats_.created += stats_.created_on_objects;
}

int FeatureTracker::GuidedMatch(const std::unordered_map<int64_t, Eigen::Vector2f>& predicted_uv) {
  if (prev_pyramid_.empty()) return 0;
  const cv::Mat& image = prev_pyramid_[0];  // the latest image
  const float border = static_cast<float>(options_.border_px);
  int found = 0;
  std::vector<Track> still_lost;
  for (Track& t : recently_lost_) {
    auto it = predicted_uv.find(t.id);
    if (it == predicted_uv.end() || t.patch.empty() || !InBorder(it->second, image, border)) {
      still_lost.push_back(std::move(t));
      continue;
    }
    const PatchMatch m = FindPatchZssd(image, t.patch, it->second, options_.guided_radius_px);
    if (!m.found || m.score > options_.max_patch_score || m.second < 1.5f * m.score) {
      still_lost.push_back(std::move(t));
      continue;
    }
    t.prev_uv = t.uv;
    t.uv = m.uv;
    t.status = TrackStatus::kActive;
    t.occluded_frames = 0;
    ++t.age;
    t.last_seen_frame = frame_index_;
    ExtractPatch(image, t.uv, options_.patch_size, &t.patch);
    tracks_.push_back(std::move(t));
    ++found;
  }
  recently_lost_ = std::move(still_lost);
  stats_.recovered += found;
  if (found > 0) EnforceUnicity();
  return found;
}

void FeatureTracker::MatchByDescriptors(const cv::Mat& prev_image, const cv::Mat& image, int64_t frame_index,
                                        bool wide_baseline, std::vector<Track>* lost,
                                        std::vector<Track>* next_tracks) {
  if (lost->empty()) return;
  cv::Ptr<cv::ORB> orb =
      wide_baseline ? cv::ORB::create(options_.fallback_features, 1.2f, /*nlevels=*/1, /*edgeThreshold=*/31,
                                      /*firstLevel=*/0, /*WTA_K=*/2, cv::ORB::HARRIS_SCORE, /*patchSize=*/31,
                                      options_.wide_baseline_fast_threshold)
                    : cv::ORB::create(options_.fallback_features);
  // Descriptors of the lost tracks at their previous positions.
  std::vector<cv::KeyPoint> prev_kps;
  for (const Track& t : *lost) {
    const cv::Point2f pt(t.uv.x(), t.uv.y());
    if (options_.fallback_orientation) {
      const float angle = IntensityCentroidAngle(prev_image, pt);
      if (angle < 0.0f) continue;  // ORB would drop it at the border anyway
      prev_kps.emplace_back(pt, 31.0f, angle);
    } else {
      prev_kps.emplace_back(pt, 31.0f, wide_baseline ? 0.0f : -1.0f);
    }
  }
  cv::Mat prev_desc;
  orb->compute(prev_image, prev_kps, prev_desc);  // drops keypoints too close to the border
  if (prev_kps.empty()) return;
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  if (wide_baseline && !options_.fallback_orientation) {
    // Unoriented like the lost tracks' descriptors.
    orb->detect(image, kps);
    for (cv::KeyPoint& kp : kps) kp.angle = 0.0f;
    orb->compute(image, kps, desc);
  } else {
    orb->detectAndCompute(image, cv::noArray(), kps, desc);
  }
  if (kps.size() < 2) return;
  // Each lost track (by surviving keypoint) matched among the keypoints near it.
  const auto described = [](const std::vector<cv::KeyPoint>& k, const cv::Mat& d,
                            std::vector<Eigen::Vector2f>* uv, std::vector<OrbDescriptor>* out) {
    if (d.type() != CV_8UC1 || d.cols != static_cast<int>(OrbDescriptor().bits.size())) return;
    for (int r = 0; r < d.rows && r < static_cast<int>(k.size()); ++r) {
      uv->emplace_back(k[static_cast<size_t>(r)].pt.x, k[static_cast<size_t>(r)].pt.y);
      out->emplace_back();
      std::memcpy(out->back().bits.data(), d.ptr<uint8_t>(r), out->back().bits.size());
    }
  };
  std::vector<Eigen::Vector2f> prev_uv, uv;
  std::vector<OrbDescriptor> prev_d, d;
  described(prev_kps, prev_desc, &prev_uv, &prev_d);
  described(kps, desc, &uv, &d);
  std::vector<int> best_of(prev_kps.size(), -1);
  for (const auto& [i, j] : MatchOrbWithinRadius(
           prev_uv, prev_d, uv, d, options_.fallback_radius * std::hypot(image.cols, image.rows),
           options_.fallback_max_hamming, options_.fallback_ratio)) {
    best_of[static_cast<size_t>(i)] = j;
  }
  // ORB's compute() may drop keypoints: map them back to tracks by position.
  std::vector<Track> still_lost;
  std::vector<bool> used(lost->size(), false);
  for (size_t i = 0; i < prev_kps.size(); ++i) {
    if (best_of[i] < 0) continue;
    for (size_t t = 0; t < lost->size(); ++t) {
      if (used[t]) continue;
      Track& tr = (*lost)[t];
      if (std::abs(tr.uv.x() - prev_kps[i].pt.x) > 0.01f || std::abs(tr.uv.y() - prev_kps[i].pt.y) > 0.01f) continue;
      const cv::Point2f& p = kps[static_cast<size_t>(best_of[i])].pt;
      cv::Mat patch;
      if (!ExtractPatch(image, Eigen::Vector2f(p.x, p.y), options_.patch_size, &patch)) break;
      used[t] = true;
      tr.prev_uv = tr.uv;
      tr.uv = Eigen::Vector2f(p.x, p.y);
      tr.velocity = tr.uv - tr.prev_uv;
      tr.patch = patch;
      tr.anchor = patch;  // appearance changes a lot across a wide baseline
      ++tr.age;
      tr.last_seen_frame = frame_index;
      tr.match_error = 0.0f;
      ++stats_.descriptor_matched;
      next_tracks->push_back(std::move(tr));
      break;
    }
  }
  for (size_t t = 0; t < lost->size(); ++t) {
    if (!used[t]) still_lost.push_back(std::move((*lost)[t]));
  }
  *lost = std::move(still_lost);
}

std::unordered_map<int64_t, size_t> FeatureTracker::IndexById() const {
  std::unordered_map<int64_t, size_t> index_of;
  for (size_t i = 0; i < tracks_.size(); ++i) index_of[tracks_[i].id] = i;
  return index_of;
}

int FeatureTracker::SetWarpReferences(const std::vector<std::pair<int64_t, int64_t>>& track_keys) {
  if (prev_pyramid_.empty() || track_keys.empty()) return 0;
  const cv::Mat& image = prev_pyramid_[0];  // the latest image
  const std::unordered_map<int64_t, size_t> index_of = IndexById();
  const int side = options_.warp_reference_px;
  int stored = 0;
  for (const auto& [id, key] : track_keys) {
    auto it = index_of.find(id);
    if (it == index_of.end()) continue;
    Track& t = tracks_[it->second];
    if (!t.active() || t.last_seen_frame != frame_index_) continue;
    const float half = 0.5f * static_cast<float>(side - 1);
    if (t.uv.x() - half < 0.0f || t.uv.y() - half < 0.0f || t.uv.x() + half > image.cols - 1.0f ||
        t.uv.y() + half > image.rows - 1.0f) {
      continue;
    }
    cv::getRectSubPix(image, cv::Size(side, side), cv::Point2f(t.uv.x(), t.uv.y()), t.warp_reference, CV_32F);
    t.warp_reference_uv = t.uv;
    t.warp_reference_key = key;
    ++stored;
  }
  return stored;
}

WarpAlignStats FeatureTracker::AlignToReferences(const std::vector<WarpedReference>& warps) {
  WarpAlignStats out;
  if (prev_pyramid_.empty() || warps.empty()) return out;
  const cv::Mat& image = prev_pyramid_[0];  // the latest image
  const std::unordered_map<int64_t, size_t> index_of = IndexById();
  const float max_scale = static_cast<float>(options_.warp_max_scale);
  const float max_px2 = static_cast<float>(options_.warp_align_max_px * options_.warp_align_max_px);
  const float border = static_cast<float>(options_.border_px);
  const float a = static_cast<float>(options_.velocity_smoothing);
  double correction_sum = 0.0;
  cv::Mat templ;
  for (const WarpedReference& w : warps) {
    auto it = index_of.find(w.track_id);
    if (it == index_of.end()) continue;
    Track& t = tracks_[it->second];
    if (!t.active() || t.last_seen_frame != frame_index_ || t.warp_reference.empty() || !w.cur_from_ref.allFinite()) {
      continue;
    }
    const Eigen::Vector2f sv = SingularValues2x2(w.cur_from_ref);
    if (!(sv[0] <= max_scale && sv[1] >= 1.0f / max_scale)) continue;
    // One pixel of border gives the template's gradients.
    if (!WarpReferencePatch(t.warp_reference, w.cur_from_ref, options_.patch_size + 2, &templ)) continue;
    ++out.tried;
    const PatchAlignment al = AlignPatch(image, templ, t.uv);
    const Eigen::Vector2f shift = al.uv - t.uv;
    cv::Mat patch;
    if (!al.converged || al.ncc < options_.warp_align_min_ncc || shift.squaredNorm() > max_px2 ||
        !InBorder(al.uv, image, border) || !ExtractPatch(image, al.uv, options_.patch_size, &patch)) {
      ++out.refused;
      continue;
    }
    t.uv = al.uv;
    t.velocity += (t.age > 2 ? a : 1.0f) * shift;
    t.patch = patch;
    ++out.corrected;
    correction_sum += shift.norm();
  }
  if (out.corrected > 0) out.mean_correction_px = correction_sum / out.corrected;
  return out;
}

int64_t FeatureTracker::AdoptTrack(const Eigen::Vector2f& uv, int body_id) {
  if (prev_pyramid_.empty()) return -1;
  const cv::Mat& image = prev_pyramid_[0];
  if (!InBorder(uv, image, static_cast<float>(options_.border_px))) return -1;
  const float r2 = static_cast<float>(options_.unicity_px * options_.unicity_px);
  for (const Track& t : tracks_) {
    if ((t.uv - uv).squaredNorm() < std::max(r2, 1.0f)) return -1;
  }
  Track t;
  t.id = next_id_++;
  t.uv = uv;
  t.first_frame = frame_index_;
  t.last_seen_frame = frame_index_;
  t.body_id = body_id;
  t.p_static = body_id == 0 ? 0.9f : 0.5f;
  t.age = 2;  // established: it continues a known point
  t.is_new = false;
  if (!ExtractPatch(image, t.uv, options_.patch_size, &t.patch)) return -1;
  t.anchor = t.patch;
  tracks_.push_back(std::move(t));
  return tracks_.back().id;
}

void FeatureTracker::EnforceUnicity() {
  if (options_.unicity_px <= 0.0) return;
  const float cell = static_cast<float>(std::max(1.0, options_.unicity_px));
  // Better tracks first: older, then smaller matching error.
  std::vector<size_t> order(tracks_.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    if (tracks_[a].active() != tracks_[b].active()) return tracks_[a].active();
    if (tracks_[a].age != tracks_[b].age) return tracks_[a].age > tracks_[b].age;
    return tracks_[a].match_error < tracks_[b].match_error;
  });
  // The kept tracks by grid cell: the cell's first track, then a chain through `next`
  // (no per-cell allocation).
  std::unordered_map<int64_t, size_t> first_in_cell;
  first_in_cell.reserve(tracks_.size());
  constexpr size_t kNone = static_cast<size_t>(-1);
  std::vector<size_t> next(tracks_.size(), kNone);
  auto key = [](int gx, int gy) { return (static_cast<int64_t>(gx) << 32) ^ static_cast<uint32_t>(gy); };
  std::vector<bool> keep(tracks_.size(), true);
  const float r2 = static_cast<float>(options_.unicity_px * options_.unicity_px);
  for (size_t i : order) {
    const Track& t = tracks_[i];
    if (!t.active()) continue;
    const int gx = static_cast<int>(std::floor(t.uv.x() / cell));
    const int gy = static_cast<int>(std::floor(t.uv.y() / cell));
    bool clash = false;
    for (int dx = -1; dx <= 1 && !clash; ++dx) {
      for (int dy = -1; dy <= 1 && !clash; ++dy) {
        auto it = first_in_cell.find(key(gx + dx, gy + dy));
        if (it == first_in_cell.end()) continue;
        for (size_t j = it->second; j != kNone; j = next[j]) {
          if ((tracks_[j].uv - t.uv).squaredNorm() < r2) {
            clash = true;
            break;
          }
        }
      }
    }
    if (clash) {
      keep[i] = false;
      ++stats_.rejected_unicity;
    } else {
      auto [it, inserted] = first_in_cell.try_emplace(key(gx, gy), i);
      if (!inserted) {
        next[i] = it->second;
        it->second = i;
      }
    }
  }
  std::vector<Track> out;
  out.reserve(tracks_.size());
  for (size_t i = 0; i < tracks_.size(); ++i) {
    if (keep[i]) out.push_back(std::move(tracks_[i]));
  }
  tracks_ = std::move(out);
}

void FeatureTracker::DetectNew(const cv::Mat& image, int64_t frame_index) {
  const int cells = options_.grid_cols * options_.grid_rows;
  // Tracks added on moving objects (object_features) are above max_features and take
  // no cell's share, until the segmentation puts them in the static world (a false
  // detection, or an object that stopped): from then on they are ordinary tracks.
  int on_objects = 0;
  for (Track& t : tracks_) {
    if (t.body_id == 0) t.on_object = false;
    on_objects += t.on_object;
  }
  const int room = options_.max_features - (static_cast<int>(tracks_.size()) - on_objects);
  if (room <= 0) return;
  const int per_cell = std::max(1, (options_.max_features + cells - 1) / cells);
  const float cell_w = static_cast<float>(image.cols) / options_.grid_cols;
  const float cell_h = static_cast<float>(image.rows) / options_.grid_rows;
  auto cell_of = [&](float x, float y) {
    const int cx = std::clamp(static_cast<int>(x / cell_w), 0, options_.grid_cols - 1);
    const int cy = std::clamp(static_cast<int>(y / cell_h), 0, options_.grid_rows - 1);
    return cy * options_.grid_cols + cx;
  };

  // Occupancy: a min-distance disc around every existing track.
  cv::Mat mask(image.size(), CV_8UC1, cv::Scalar(0));
  const int b = options_.border_px + 3;  // FAST needs 3 px around a corner
  if (image.cols > 2 * b && image.rows > 2 * b) {
    mask(cv::Rect(b, b, image.cols - 2 * b, image.rows - 2 * b)).setTo(255);
  }
  const int radius = static_cast<int>(std::ceil(options_.min_distance_px));
  if (disc_.radius() != radius) disc_ = DiscStamp(radius);  // the option is fixed: built once
  std::vector<int> count(static_cast<size_t>(cells), 0);
  for (const Track& t : tracks_) {
    disc_.Stamp(&mask, cv::Point(static_cast<int>(std::lround(t.uv.x())), static_cast<int>(std::lround(t.uv.y()))), 0);
    if (!t.on_object) ++count[static_cast<size_t>(cell_of(t.uv.x(), t.uv.y()))];
  }

  // FAST only where features are wanted: over each run of neighbouring cells of a grid
  // row that lack them, grown by 5 px (the 3-px circle and the non-maximum neighbours),
  // keeping the corners of those cells: the same corners, in the same order, as FAST
  // over the whole image would give them.
  std::vector<std::vector<cv::KeyPoint>> corners(static_cast<size_t>(cells));
  const int kMargin = 5;
  for (int cy = 0; cy < options_.grid_rows; ++cy) {
    const int row = cy * options_.grid_cols;
    for (int cx = 0; cx < options_.grid_cols;) {
      if (count[static_cast<size_t>(row + cx)] >= per_cell) {
        ++cx;
        continue;
      }
      int end = cx + 1;
      while (end < options_.grid_cols && count[static_cast<size_t>(row + end)] < per_cell) ++end;
      const int x0 = std::max(0, static_cast<int>(std::floor(cx * cell_w)) - kMargin);
      const int x1 = std::min(image.cols, static_cast<int>(std::ceil(end * cell_w)) + kMargin);
      const int y0 = std::max(0, static_cast<int>(std::floor(cy * cell_h)) - kMargin);
      const int y1 = std::min(image.rows, static_cast<int>(std::ceil((cy + 1) * cell_h)) + kMargin);
      std::vector<cv::KeyPoint> found;
      if (x1 - x0 > 7 && y1 - y0 > 7) {
        cv::FAST(image(cv::Rect(x0, y0, x1 - x0, y1 - y0)), found, options_.fast_threshold, /*nonmaxSuppression=*/true);
      }
      for (cv::KeyPoint& kp : found) {
        kp.pt.x += static_cast<float>(x0);
        kp.pt.y += static_cast<float>(y0);
        const int c = cell_of(kp.pt.x, kp.pt.y);
        if (c >= row + cx && c < row + end) corners[static_cast<size_t>(c)].push_back(kp);
      }
      cx = end;
    }
  }
  std::vector<std::vector<const cv::KeyPoint*>> by_cell(static_cast<size_t>(cells));
  for (int c = 0; c < cells; ++c) {
    for (const cv::KeyPoint& kp : corners[static_cast<size_t>(c)]) by_cell[static_cast<size_t>(c)].push_back(&kp);
  }
  // Empty cells get a second chance at the lower threshold.
  std::vector<std::vector<cv::KeyPoint>> extra(static_cast<size_t>(cells));
  for (int c = 0; c < cells; ++c) {
    if (!by_cell[static_cast<size_t>(c)].empty() || count[static_cast<size_t>(c)] >= per_cell) continue;
    const int cx = c % options_.grid_cols, cy = c / options_.grid_cols;
    const cv::Rect roi(static_cast<int>(cx * cell_w), static_cast<int>(cy * cell_h),
                       static_cast<int>(cell_w), static_cast<int>(cell_h));
    const cv::Rect clipped = roi & cv::Rect(0, 0, image.cols, image.rows);
    if (clipped.width < 8 || clipped.height < 8) continue;
    std::vector<cv::KeyPoint>& kps = extra[static_cast<size_t>(c)];
    cv::FAST(image(clipped), kps, options_.min_fast_threshold, true);
    for (cv::KeyPoint& kp : kps) {
      kp.pt.x += static_cast<float>(clipped.x);
      kp.pt.y += static_cast<float>(clipped.y);
      by_cell[static_cast<size_t>(c)].push_back(&kp);
    }
  }

  // Round robin over the cells by rank, so that a shortage of room does not starve
  // the last cells.
  for (auto& candidates : by_cell) {
    std::sort(candidates.begin(), candidates.end(),
              [](const cv::KeyPoint* a, const cv::KeyPoint* b) { return a->response > b->response; });
  }
  std::vector<size_t> next_candidate(static_cast<size_t>(cells), 0);
  int created = 0;
  bool progress = true;
  while (created < room && progress) {
    progress = false;
    for (int c = 0; c < cells && created < room; ++c) {
      const size_t cu = static_cast<size_t>(c);
      auto& candidates = by_cell[cu];
      if (count[cu] >= per_cell) continue;
      // The next candidate of this cell that is still free.
      while (next_candidate[cu] < candidates.size()) {
        const cv::KeyPoint* kp = candidates[next_candidate[cu]++];
        const int x = static_cast<int>(std::lround(kp->pt.x)), y = static_cast<int>(std::lround(kp->pt.y));
        if (x < 0 || y < 0 || x >= image.cols || y >= image.rows || !mask.at<uint8_t>(y, x)) continue;
        Track t;
        t.id = next_id_++;
        t.uv = Eigen::Vector2f(kp->pt.x, kp->pt.y);
        t.first_frame = frame_index;
        t.last_seen_frame = frame_index;
        t.is_new = true;
        if (!ExtractPatch(image, t.uv, options_.patch_size, &t.patch)) continue;
        t.anchor = t.patch;
        disc_.Stamp(&mask, cv::Point(x, y), 0);
        ++count[cu];
        ++created;
        progress = true;
        tracks_.push_back(std::move(t));
        break;
      }
    }
  }
  stats_.created = created;
}

int FeatureTracker::DetectOnObjects(const cv::Mat& image, int64_t frame_index,
                                    const std::vector<TrackingHints::Hull>& hulls) {
  if (options_.object_features <= 0 || hulls.empty()) return 0;
  int budget = options_.object_extra_features;
  for (const Track& t : tracks_) budget -= t.on_object;
  if (budget <= 0) return 0;
  const int b = options_.border_px + 3;  // the border DetectNew leaves
  if (image.cols <= 2 * b || image.rows <= 2 * b) return 0;
  const cv::Rect usable(b, b, image.cols - 2 * b, image.rows - 2 * b);
  const float min_d = static_cast<float>(options_.object_min_distance_px);
  const float margin = static_cast<float>(options_.object_hull_margin_px);
  // Distance from p to the hull's boundary (p inside).
  auto boundary_distance = [](const std::vector<Eigen::Vector2f>& hull, const Eigen::Vector2f& p) {
    float best = std::numeric_limits<float>::infinity();
    for (size_t i = 0; i < hull.size(); ++i) {
      const Eigen::Vector2f a = hull[i], e = hull[(i + 1) % hull.size()] - a;
      const float len2 = e.squaredNorm();
      const float s = len2 > 0.0f ? std::clamp((p - a).dot(e) / len2, 0.0f, 1.0f) : 0.0f;
      best = std::min(best, (a + s * e - p).norm());
    }
    return best;
  };
  int created = 0;
  for (const TrackingHints::Hull& h : hulls) {
    if (budget <= 0) break;
    if (h.points.size() < 3 || h.age_frames < options_.object_min_age_frames) continue;
    Eigen::Vector2f lo = h.points[0], hi = h.points[0];
    bool finite = true;
    for (const Eigen::Vector2f& p : h.points) {
      finite = finite && p.allFinite();
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    if (!finite) continue;
    double area2 = 0.0;  // twice the hull's area (shoelace)
    for (size_t i = 0; i < h.points.size(); ++i) {
      const Eigen::Vector2f& a = h.points[i];
      const Eigen::Vector2f& c = h.points[(i + 1) % h.points.size()];
      area2 += static_cast<double>(a.x()) * c.y() - static_cast<double>(c.x()) * a.y();
    }
    if (0.5 * std::abs(area2) > options_.object_max_hull_share * image.total()) continue;
    const cv::Rect box = cv::Rect(cv::Point(static_cast<int>(std::floor(lo.x())), static_cast<int>(std::floor(lo.y()))),
                                  cv::Point(static_cast<int>(std::ceil(hi.x())) + 1, static_cast<int>(std::ceil(hi.y())) + 1)) &
                         usable;
    if (box.width < 8 || box.height < 8) continue;
    // The tracks in and around the hull: how many it holds, and the spacing of new ones.
    std::vector<Eigen::Vector2f> near;
    int inside = 0;
    for (const Track& t : tracks_) {
      if (t.uv.x() < box.x - min_d || t.uv.y() < box.y - min_d || t.uv.x() > box.x + box.width + min_d ||
          t.uv.y() > box.y + box.height + min_d) {
        continue;
      }
      near.push_back(t.uv);
      inside += t.active() && InsideConvexHull(h.points, t.uv);
    }
    int want = std::min(options_.object_features - inside, budget);
    if (want <= 0) continue;
    // Shi-Tomasi corners (what KLT tracks well) inside the hull, best first.
    cv::Mat hull_mask(box.size(), CV_8UC1, cv::Scalar(0));
    std::vector<cv::Point> polygon;
    for (const Eigen::Vector2f& p : h.points) {
      polygon.emplace_back(static_cast<int>(std::lround(p.x())) - box.x, static_cast<int>(std::lround(p.y())) - box.y);
    }
    cv::fillConvexPoly(hull_mask, polygon, cv::Scalar(255));
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(image(box), corners, 3 * want + static_cast<int>(near.size()), /*qualityLevel=*/0.01,
                            options_.object_min_distance_px, hull_mask);
    for (const cv::Point2f& c : corners) {
      if (want <= 0) break;
      const Eigen::Vector2f p(c.x + static_cast<float>(box.x), c.y + static_cast<float>(box.y));
      if (!InsideConvexHull(h.points, p) || boundary_distance(h.points, p) < margin) continue;
      bool free = true;
      for (const Eigen::Vector2f& q : near) {
        if ((q - p).squaredNorm() < min_d * min_d) {
          free = false;
          break;
        }
      }
      if (!free) continue;
      Track t;
      t.id = next_id_++;
      t.uv = p;
      t.first_frame = frame_index;
      t.last_seen_frame = frame_index;
      t.is_new = true;
      t.on_object = true;
      if (!ExtractPatch(image, t.uv, options_.patch_size, &t.patch)) continue;
      t.anchor = t.patch;
      near.push_back(p);
      tracks_.push_back(std::move(t));
      --want;
      --budget;
      ++created;
    }
  }
  return created;
}

}  // namespace mbslam
