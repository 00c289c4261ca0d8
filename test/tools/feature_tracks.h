#ifndef MBSLAM_TEST_TOOLS_FEATURE_TRACKS_H_
#define MBSLAM_TEST_TOOLS_FEATURE_TRACKS_H_

// A feature as a run's PERCEPTION_TRACKS holds it, for the scoring tools' tests.

#include <cstdint>

#include "mbslam/feature_track_t.hpp"

namespace mbslam {
namespace testing_util {

// At (u, v) in the image, labelled `body` (0 static world, > 0 object, -1 unassigned),
// not moved since the last image.
inline mbslam::feature_track_t FeatureTrack(int64_t id, float u, float v, int body, int age = 3,
                                            int8_t flags = 0) {
  mbslam::feature_track_t t{};
  t.id = id;
  t.u = u;
  t.v = v;
  t.prev_u = u;
  t.prev_v = v;
  t.age = age;
  t.body_id = body;
  t.flags = flags;
  return t;
}

}  // namespace testing_util
}  // namespace mbslam

#endif  // MBSLAM_TEST_TOOLS_FEATURE_TRACKS_H_
