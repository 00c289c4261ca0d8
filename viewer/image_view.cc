#include "viewer/image_view.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "common/util/time.h"
#include "viewer/colors.h"
#include "viewer/draw_util.h"
#include "viewer/image_decode.h"

namespace mbslam {
namespace viewer {
namespace {

// Fixed-point drawing (4 fractional bits) keeps sub-pixel positions.
constexpr int kShift = 4;
constexpr double kOne = 1 << kShift;

cv::Point Fixed(const Eigen::Vector2d& p) {
  return cv::Point(static_cast<int>(std::lround(p.x() * kOne)),
                   static_cast<int>(std::lround(p.y() * kOne)));
}

Rgb TrackColor(TrackClass c) {
  switch (c) {
    case TrackClass::kStatic:
      return kStaticTrackColor;
    case TrackClass::kMoving:
      return kMovingTrackColor;
    case TrackClass::kOccluded:
      return kOccludedTrackColor;
    default:
      return kUnassignedTrackColor;
  }
}

// Maps pixel coordinates of the tracks' image to the output (pixel centres at integers).
struct PixelMap {
  double sx = 1.0, sy = 1.0;
  Eigen::Vector2d operator()(double u, double v) const {
    return Eigen::Vector2d((u + 0.5) * sx - 0.5, (v + 0.5) * sy - 0.5);
  }
};

bool Finite(float a, float b) { return std::isfinite(a) && std::isfinite(b); }

// The part inside the image of the ray from `origin` along the unit vector `dir`.
bool ClipRay(const Eigen::Vector2d& origin, const Eigen::Vector2d& dir, const cv::Size& size,
             Eigen::Vector2d* a, Eigen::Vector2d* b) {
  if (!origin.allFinite() || !dir.allFinite()) return false;
  // Slab clipping of origin + s dir, s >= 0, against [0, w-1] x [0, h-1].
  double s0 = 0.0, s1 = 1e9;
  const double lo[2] = {0.0, 0.0}, hi[2] = {size.width - 1.0, size.height - 1.0};
  for (int k = 0; k < 2; ++k) {
    if (std::abs(dir[k]) < 1e-12) {
      if (origin[k] < lo[k] || origin[k] > hi[k]) return false;
      continue;
    }
    double t0 = (lo[k] - origin[k]) / dir[k], t1 = (hi[k] - origin[k]) / dir[k];
    if (t0 > t1) std::swap(t0, t1);
    s0 = std::max(s0, t0);
    s1 = std::min(s1, t1);
  }
  if (s0 > s1) return false;
  *a = origin + s0 * dir;
  *b = origin + s1 * dir;
  return true;
}

}  // namespace

TrackClass ClassifyTrack(const TrackFeature& track) {
  if (track.occluded) return TrackClass::kOccluded;
  if (track.body_id == 0) return TrackClass::kStatic;
  if (track.body_id > 0) return TrackClass::kMoving;
  return TrackClass::kUnassigned;
}

Status MakeImageViewInput(const SceneState& scene, int max_image_dimension, ImageViewInput* input) {
  const ImageFrame frame = scene.LatestImageFrame();
  *input = ImageViewInput();
  input->tracks = frame.tracks;
  input->objects = frame.objects;
  input->utime = frame.utime;
  if (!frame.image) {
    if (frame.tracks) input->note = "no camera image with this utime";
    return Status::Ok();
  }
  const Status s = DecodeToBgr(*frame.image, max_image_dimension, &input->image);
  if (!s.ok()) {
    input->image.release();
    input->note = "camera image does not decode";
  }
  return s;
}

void RenderImageView(const ImageViewOptions& options, const ImageViewInput& input, cv::Mat* bgr,
                     int* image_top) {
  if (image_top) *image_top = 0;
  const TracksData* tracks = input.tracks;
  // The canvas: the image, or grey of the tracks' size, or a default size.
  cv::Mat canvas;
  int source_w = 640, source_h = 480;
  if (!input.image.empty()) {
    canvas = input.image;
    source_w = canvas.cols;
    source_h = canvas.rows;
  } else if (tracks && tracks->width > 0 && tracks->height > 0 && tracks->width <= 8192 &&
             tracks->height <= 8192) {
    source_w = tracks->width;
    source_h = tracks->height;
  }
  double scale = options.scale;
  if (source_w * scale < options.min_width)
    scale = static_cast<double>(options.min_width) / source_w;
  // The output's sides stay within kMaxViewDimension: enlarging a 1 x 8192 image (or
  // tracks of that size) to min_width asked for 640 x 5 M pixels, ~10 GB.
  scale = std::min(scale, kMaxViewDimension / static_cast<double>(std::max(source_w, source_h)));
  const cv::Size out_size(std::max(1, static_cast<int>(std::lround(source_w * scale))),
                          std::max(1, static_cast<int>(std::lround(source_h * scale))));
  if (canvas.empty()) {
    bgr->create(out_size, CV_8UC3);
    bgr->setTo(cv::Scalar(90, 90, 90));
  } else {
    cv::resize(canvas, *bgr, out_size, 0, 0, scale >= 1.0 ? cv::INTER_LINEAR : cv::INTER_AREA);
    if (options.dim_image) bgr->convertTo(*bgr, -1, 0.7, 0.0);
  }
  // Tracks may refer to an image of another size than the one shown.
  PixelMap map;
  const double track_w = tracks && tracks->width > 0 ? tracks->width : source_w;
  const double track_h = tracks && tracks->height > 0 ? tracks->height : source_h;
  map.sx = out_size.width / track_w;
  map.sy = out_size.height / track_h;
  const double font = FontScaleFor(std::max(out_size.width, 900));
  const int radius = std::max(1, static_cast<int>(std::lround(options.feature_radius_px)));

  std::map<int, const ObjectData*> objects;
  if (input.objects) {
    for (const ObjectData& o : input.objects->objects) objects[o.id] = &o;
  }
  int counts[4] = {0, 0, 0, 0};
  if (tracks) {
    // Hulls, shaded on a copy and blended, then outlined.
    cv::Mat shade = bgr->clone();
    bool any_hull = false;
    for (const ImageHull& hull : tracks->hulls) {
      if (hull.body_id <= 0 || hull.points.size() < 3) continue;
      std::vector<cv::Point> polygon;
      for (const auto& p : hull.points) {
        if (!p.allFinite()) continue;
        polygon.push_back(Fixed(map(p.x(), p.y())));
      }
      if (polygon.size() < 3) continue;
      const cv::Scalar color = ToBgr(ObjectColor(hull.body_id));
      cv::fillPoly(shade, std::vector<std::vector<cv::Point>>{polygon}, color, cv::LINE_AA, kShift);
      any_hull = true;
    }
    if (any_hull)
      cv::addWeighted(shade, options.hull_alpha, *bgr, 1.0 - options.hull_alpha, 0.0, *bgr);
    for (const ImageHull& hull : tracks->hulls) {
      if (hull.body_id <= 0 || hull.points.size() < 3) continue;
      std::vector<cv::Point> polygon;
      for (const auto& p : hull.points) {
        if (p.allFinite()) polygon.push_back(Fixed(map(p.x(), p.y())));
      }
      if (polygon.size() < 3) continue;
      cv::polylines(*bgr, std::vector<std::vector<cv::Point>>{polygon}, true,
                    ToBgr(ObjectColor(hull.body_id)), 2, cv::LINE_AA, kShift);
    }

    // Epipolar lines through moving features (all, or those the epipolar constraint
    // cannot tell from static ones).
    const Eigen::Vector3d& e = tracks->epipole;
    const bool epipole_known = e.allFinite() && e.norm() > 0.0;
    if (options.epipolar_lines != "off" && epipole_known) {
      int drawn = 0;
      for (const TrackFeature& t : tracks->tracks) {
        if (drawn >= options.max_epipolar_lines) break;
        if (ClassifyTrack(t) != TrackClass::kMoving || !Finite(t.u, t.v)) continue;
        if (options.epipolar_lines == "degenerate" &&
            !(std::isfinite(t.epipolar_px) && t.epipolar_px <= options.degenerate_epipolar_px)) {
          continue;
        }
        // From the epipole through the feature to the image border (the whole line
        // through the feature when the epipole is at infinity).
        const Eigen::Vector2d x = map(t.u, t.v);
        Eigen::Vector2d a, b;
        if (std::abs(e.z()) > 1e-9 * e.head<2>().norm()) {
          const Eigen::Vector2d ep = map(e.x() / e.z(), e.y() / e.z());
          const Eigen::Vector2d d = x - ep;
          if (!(d.norm() > 1e-6) || !ep.allFinite()) continue;
          if (!ClipRay(ep, d.normalized(), out_size, &a, &b)) continue;
        } else {
          const Eigen::Vector2d d = Eigen::Vector2d(e.x() * map.sx, e.y() * map.sy).normalized();
          if (!ClipRay(x - 1e5 * d, d, out_size, &a, &b)) continue;
        }
        cv::line(*bgr, Fixed(a), Fixed(b), ToBgr(kEpipolarLineColor), 1, cv::LINE_AA, kShift);
        ++drawn;
      }
      if (std::abs(e.z()) > 1e-12) {
        const Eigen::Vector2d ep = map(e.x() / e.z(), e.y() / e.z());
        if (ep.x() >= 0 && ep.y() >= 0 && ep.x() < out_size.width && ep.y() < out_size.height) {
          cv::drawMarker(*bgr, cv::Point(static_cast<int>(ep.x()), static_cast<int>(ep.y())),
                         ToBgr(kEpipolarLineColor), cv::MARKER_TILTED_CROSS, 4 * radius + 6, 2,
                         cv::LINE_AA);
        }
      }
    }

    // Flow, then the features on top.
    for (const TrackFeature& t : tracks->tracks) {
      if (!Finite(t.u, t.v)) continue;
      const TrackClass c = ClassifyTrack(t);
      ++counts[static_cast<int>(c)];
      if (!options.show_flow || !Finite(t.prev_u, t.prev_v)) continue;
      cv::line(*bgr, Fixed(map(t.prev_u, t.prev_v)), Fixed(map(t.u, t.v)), ToBgr(TrackColor(c)), 1,
               cv::LINE_AA, kShift);
    }
    for (const TrackFeature& t : tracks->tracks) {
      if (!Finite(t.u, t.v)) continue;
      const TrackClass c = ClassifyTrack(t);
      const cv::Point p = Fixed(map(t.u, t.v));
      if (c == TrackClass::kOccluded) {
        cv::circle(*bgr, p, static_cast<int>((radius + 1) * kOne), ToBgr(TrackColor(c)), 2,
                   cv::LINE_AA, kShift);
      } else {
        cv::circle(*bgr, p, static_cast<int>(radius * kOne), ToBgr(TrackColor(c)), cv::FILLED,
                   cv::LINE_AA, kShift);
      }
    }

    // Object ids and speeds above their hulls.
    if (options.show_labels) {
      const bool metric = input.objects && input.objects->metric;
      for (const ImageHull& hull : tracks->hulls) {
        if (hull.body_id <= 0 || hull.points.empty()) continue;
        Eigen::Vector2d top(0.0, 1e30), left(1e30, 0.0);
        bool any = false;
        for (const auto& p : hull.points) {
          if (!p.allFinite()) continue;
          const Eigen::Vector2d q = map(p.x(), p.y());
          if (q.y() < top.y()) top = q;
          if (q.x() < left.x()) left = q;
          any = true;
        }
        if (!any) continue;
        char text[96];
        auto it = objects.find(hull.body_id);
        // Objects only detected so far have no velocity estimate: no speed for them.
        if (it != objects.end() && it->second->state != ObjectState::kDetected &&
            it->second->linear_velocity.allFinite()) {
          std::snprintf(text, sizeof(text), "#%d  %.2f %s", hull.body_id,
                        it->second->linear_velocity.norm(), metric ? "m/s" : "units/s");
        } else {
          std::snprintf(text, sizeof(text), "#%d", hull.body_id);
        }
        // Clamped as doubles: hull vertices come from the message, and casting 1e30 to
        // int was undefined (found by fuzz_viewer_lcm under UBSan).
        const int x = static_cast<int>(
            std::clamp(left.x(), 2.0, static_cast<double>(std::max(2, out_size.width - 160))));
        const int y = static_cast<int>(std::clamp(std::trunc(top.y()) - 6.0, 14.0,
                                                  static_cast<double>(std::max(14, out_size.height - 4))));
        DrawOutlinedText(bgr, text, cv::Point(x, y), font * 1.1, ObjectColor(hull.body_id), 1);
      }
    }
  }

  if (!options.show_legend) return;
  char header[512];
  if (tracks) {
    std::snprintf(header, sizeof(header),
                  "image view  t = %.3f s  frame %lld  |  static %d  moving %d  unassigned %d  "
                  "occluded %d  |  %zu object hulls%s%s",
                  UtimeToSeconds(input.utime), static_cast<long long>(tracks->frame_seq), counts[0],
                  counts[1], counts[2], counts[3], tracks->hulls.size(),
                  input.note.empty() ? "" : "  |  ", input.note.c_str());
  } else {
    std::snprintf(header, sizeof(header), "image view  t = %.3f s  |  %s",
                  UtimeToSeconds(input.utime),
                  input.image.empty() ? "no image and no tracks yet" : "no tracks for this image");
  }
  const std::vector<LegendEntry> legend = {
      {"static", kStaticTrackColor, LegendEntry::Kind::kPoint},
      {"moving", kMovingTrackColor, LegendEntry::Kind::kPoint},
      {"unassigned", kUnassignedTrackColor, LegendEntry::Kind::kPoint},
      {"occluded", kOccludedTrackColor, LegendEntry::Kind::kPoint},
      {"flow (previous -> current)", Rgb{200, 200, 200}, LegendEntry::Kind::kLine},
      {"epipolar lines", kEpipolarLineColor, LegendEntry::Kind::kLine},
      {"object hull", ObjectColor(1), LegendEntry::Kind::kBox},
  };
  // Header above and legend below the image, so neither hides any of it.
  cv::Mat top = TextBand(out_size.width, header, font);
  cv::Mat bottom = LegendBand(out_size.width, legend, font);
  cv::vconcat(std::vector<cv::Mat>{top, *bgr, bottom}, *bgr);
  if (image_top) *image_top = top.rows;
}

}  // namespace viewer
}  // namespace mbslam
