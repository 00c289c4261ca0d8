// Properties the scenarios promise: what moves how, image coverage, occlusions, the
// degenerate following case, odometry, and images that a tracker can work with.

#include <gtest/gtest.h>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>

#include "tools/sim/scenarios.h"
#include "tools/sim/simulator.h"

namespace mbslam {
namespace sim {
namespace {

// One simulator per scenario and size for the whole test binary (creation builds
// textures). The cache is emptied before exit: GL contexts must not be destroyed during
// static destruction, after the driver has shut down.
std::map<std::pair<std::string, int>, std::unique_ptr<Simulator>>& Cache() {
  static auto* cache = new std::map<std::pair<std::string, int>, std::unique_ptr<Simulator>>();
  return *cache;
}

class ClearCache : public ::testing::Environment {
 public:
  void TearDown() override { Cache().clear(); }
};
const auto* const kClearCache = ::testing::AddGlobalTestEnvironment(new ClearCache);

Simulator* Get(const std::string& scenario, int width = 320) {
  auto& slot = Cache()[{scenario, width}];
  if (!slot) {
    SimOptions o;
    o.scenario = scenario;
    o.camera.width = width;
    o.camera.height = width * 3 / 4;
    Status status;
    slot = Simulator::Create(o, &status);
    EXPECT_TRUE(slot) << status.message();
  }
  return slot.get();
}

Eigen::Vector2d Project(const Simulator& sim, const Rigid3d& cam_from_world,
                        const Eigen::Vector3d& p_world, double* depth = nullptr) {
  const Eigen::Vector3d p = cam_from_world * p_world;
  if (depth) {
    *depth = p.z();
  }
  return sim.intrinsics().Project(p);
}

TEST(Scenarios, AllRegistered) {
  const auto names = ScenarioNames();
  for (const char* n : {"static", "crossing", "following", "previously_static", "multi",
                        "robot_odometry", "rotation_only"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
    EXPECT_FALSE(ScenarioDescription(n).empty());
  }
}

// The build generates a fixture for every scenario (tools/sim/CMakeLists.txt).
TEST(Scenarios, EveryScenarioHasABuildFixture) {
  const char* bin = std::getenv("MBSLAM_BIN_DIR");
  if (!bin) {
    GTEST_SKIP() << "MBSLAM_BIN_DIR not set (run through ctest)";
  }
  const std::string fixtures = std::string(bin) + "/../fixtures/sim/";
  for (const auto& name : ScenarioNames()) {
    EXPECT_TRUE(std::ifstream(fixtures + name + "/timestamps.txt").good())
        << "no fixture for " << name;
    EXPECT_TRUE(std::ifstream(fixtures + name + "/sequence.lcmlog").good())
        << "no fixture log for " << name;
  }
}

// multi: 5 movers that cover at least 25 % of the image on average over the sequence.
TEST(Scenarios, MultiCoversAQuarterOfTheImage) {
  Simulator* sim = Get("multi");
  ASSERT_TRUE(sim);
  EXPECT_EQ(sim->MovingBodyIds().size(), 5u);
  SimFrame f;
  double sum = 0.0;
  std::vector<int> visible(5, 0);
  for (int k = 0; k < sim->num_frames(); ++k) {
    ASSERT_TRUE(sim->RenderFrame(k, &f, RenderRequest{false, true}).ok());
    sum += f.MovingFraction();
    for (size_t i = 0; i < f.bodies.size(); ++i) {
      visible[i] += f.bodies[i].visible ? 1 : 0;
    }
  }
  const double mean = sum / sim->num_frames();
  RecordProperty("multi_mean_moving_fraction", std::to_string(mean));
  EXPECT_GE(mean, 0.25);
  for (int v : visible) {
    EXPECT_GT(v, sim->num_frames() / 2);
  }
}

// Outside multi, movers never fill the frame and nothing sits right in front of the lens.
TEST(Scenarios, ObjectsDoNotFillTheFrame) {
  for (const auto& name : ScenarioNames()) {
    Simulator* sim = Get(name);
    ASSERT_TRUE(sim);
    SimFrame f;
    for (int k = 0; k < sim->num_frames(); k += 10) {
      ASSERT_TRUE(sim->RenderFrame(k, &f, RenderRequest{false, true}).ok());
      if (name != "multi") {
        EXPECT_LT(f.MovingFraction(), 0.4) << name << " frame " << k;
      }
      double min_depth;
      cv::minMaxLoc(f.depth, &min_depth, nullptr, nullptr, nullptr, f.depth > 0);
      EXPECT_GT(min_depth, 0.7) << name << " frame " << k;
      // Some sky at most: most of the image shows surfaces.
      EXPECT_GT(cv::countNonZero(f.depth > 0), static_cast<int>(0.5 * f.depth.total()))
          << name << " " << k;
    }
  }
}

// crossing: movers enter and leave the view, and occlude each other.
TEST(Scenarios, CrossingEntersLeavesAndOccludes) {
  Simulator* sim = Get("crossing");
  ASSERT_TRUE(sim);
  const auto ids = sim->MovingBodyIds();
  std::vector<std::vector<bool>> visible(ids.size());
  int occlusion_frames = 0;
  SimFrame f;
  for (int k = 0; k < sim->num_frames(); k += 3) {
    ASSERT_TRUE(sim->RenderFrame(k, &f, RenderRequest{false, true}).ok());
    for (size_t i = 0; i < ids.size(); ++i) {
      visible[i].push_back(f.bodies[i].visible);
    }
    // A mover occluded by another: its surface samples project onto pixels of a
    // different mover that is closer.
    const Rigid3d cam_from_world = f.world_from_cam.Inverse();
    bool occluded = false;
    for (size_t i = 0; i < ids.size() && !occluded; ++i) {
      const Rigid3d world_from_body = f.bodies[i].world_from_body;
      for (const auto& p : sim->SurfacePoints(ids[i])) {
        double z;
        const Eigen::Vector2d uv = Project(*sim, cam_from_world, world_from_body * p, &z);
        if (z <= 0.1 || !sim->intrinsics().InImage(uv, 1.0)) {
          continue;
        }
        const int x = static_cast<int>(std::lround(uv.x())),
                  y = static_cast<int>(std::lround(uv.y()));
        const int other = f.mask.at<uint16_t>(y, x);
        if (other > 0 && other != ids[i] && f.depth.at<float>(y, x) < z - 0.5) {
          occluded = true;
          break;
        }
      }
    }
    occlusion_frames += occluded ? 1 : 0;
  }
  EXPECT_GT(occlusion_frames, 0);
  int enter_and_leave = 0;
  for (const auto& v : visible) {
    const auto first = std::find(v.begin(), v.end(), true);
    if (first == v.end() || first == v.begin()) {
      continue;  // never visible or visible from the start
    }
    const auto after = std::find(first, v.end(), false);
    if (after != v.end()) {
      ++enter_and_leave;
    }
  }
  EXPECT_GE(enter_and_leave, 1);
}

double EpipolarDistance(const Eigen::Matrix3d& F, const Eigen::Vector2d& a,
                        const Eigen::Vector2d& b) {
  const Eigen::Vector3d l = F * a.homogeneous();
  return std::abs(l.dot(b.homogeneous())) / l.head<2>().norm();
}

// Fundamental matrix of the camera motion from time ta to tb with respect to the static
// world: x_b^T F x_a = 0.
Eigen::Matrix3d StaticF(const Simulator& sim, int64_t ta, int64_t tb) {
  const Rigid3d b_from_a = sim.WorldFromCam(tb).Inverse() * sim.WorldFromCam(ta);
  const Eigen::Matrix3d E = Hat(b_from_a.translation) * b_from_a.RotationMatrix();
  const Eigen::Matrix3d Kinv = sim.intrinsics().KInverse();
  return Kinv.transpose() * E * Kinv;
}

struct EpipolarStats {
  int points = 0;
  double max_distance = 0.0;
  double median_motion = 0.0;
};

// Epipolar distances (w.r.t. the static world's motion) of body `id`'s surface points
// between frames ka and kb.
EpipolarStats BodyEpipolar(const Simulator& sim, int id, int ka, int kb) {
  const int64_t ta = sim.FrameUtime(ka), tb = sim.FrameUtime(kb);
  const Eigen::Matrix3d F = StaticF(sim, ta, tb);
  const Rigid3d ca = sim.WorldFromCam(ta).Inverse(), cb = sim.WorldFromCam(tb).Inverse();
  const Rigid3d wa = sim.WorldFromBody(id, ta), wb = sim.WorldFromBody(id, tb);
  EpipolarStats s;
  std::vector<double> motion;
  for (const auto& p : sim.SurfacePoints(id)) {
    double za, zb;
    const Eigen::Vector2d a = Project(sim, ca, wa * p, &za), b = Project(sim, cb, wb * p, &zb);
    if (za < 0.5 || zb < 0.5 || !sim.intrinsics().InImage(a) || !sim.intrinsics().InImage(b)) {
      continue;
    }
    ++s.points;
    s.max_distance = std::max(s.max_distance, EpipolarDistance(F, a, b));
    motion.push_back((b - a).norm());
  }
  if (!motion.empty()) {
    std::nth_element(motion.begin(), motion.begin() + motion.size() / 2, motion.end());
    s.median_motion = motion[motion.size() / 2];
  }
  return s;
}

// following: every mover moves parallel to the camera's translation, so its points stay
// in their epipolar planes (epipolar test blind) although they move in the image; in
// crossing the same test sees the car clearly.
TEST(Scenarios, FollowingIsDegenerate) {
  Simulator* sim = Get("following");
  ASSERT_TRUE(sim);
  int checked = 0;
  for (int id : sim->MovingBodyIds()) {
    for (int k = 0; k + 60 < sim->num_frames(); k += 45) {
      const EpipolarStats s = BodyEpipolar(*sim, id, k, k + 60);
      if (s.points < 20) {
        continue;
      }
      ++checked;
      EXPECT_LT(s.max_distance, 0.01) << "body " << id << " frame " << k;
      EXPECT_GT(s.median_motion, 0.25) << "body " << id << " frame " << k;
    }
  }
  EXPECT_GE(checked, 5);
  // The leader (body 1) is ahead on the camera's line for the whole sequence.
  SimFrame f;
  for (int k = 0; k < sim->num_frames(); k += 50) {
    ASSERT_TRUE(sim->FrameTruth(k, &f).ok());
    const Eigen::Vector3d in_cam =
        f.world_from_cam.Inverse() * f.bodies[0].world_from_body.translation;
    EXPECT_GT(in_cam.z(), 3.0);
    EXPECT_LT(std::abs(in_cam.x()), 0.2);
  }
  Simulator* crossing = Get("crossing");
  ASSERT_TRUE(crossing);
  double worst = 0.0;
  for (int k = 30; k + 30 < crossing->num_frames(); k += 30) {
    worst = std::max(worst, BodyEpipolar(*crossing, 1, k, k + 30).max_distance);
  }
  EXPECT_GT(worst, 5.0);
}

// previously_static: the car and the person stand still, then move, and are seen both ways.
TEST(Scenarios, PreviouslyStaticObjectsStartMoving) {
  Simulator* sim = Get("previously_static");
  ASSERT_TRUE(sim);
  SimFrame f;
  for (int id : {1, 2}) {
    int still_visible = 0, moving_visible = 0;
    bool started = false;
    for (int k = 0; k < sim->num_frames(); k += 5) {
      ASSERT_TRUE(sim->RenderFrame(k, &f, RenderRequest{false, true}).ok());
      const SimBodyState& b = f.bodies[static_cast<size_t>(id - 1)];
      const double speed = b.linear_velocity.norm();
      if (!started && speed > 1e-6) {
        started = true;
      }
      if (!started) {
        EXPECT_LT(speed, 1e-9);
        still_visible += b.visible;
      } else {
        EXPECT_GT(speed, 1e-6) << "stopped again at frame " << k;
        moving_visible += b.visible;
      }
    }
    EXPECT_GT(still_visible, 5) << "body " << id;
    EXPECT_GT(moving_visible, 5) << "body " << id;
  }
}

TEST(Scenarios, RotationOnlyHasNoTranslation) {
  Simulator* sim = Get("rotation_only");
  ASSERT_TRUE(sim);
  const Rigid3d first = sim->WorldFromCam(sim->FrameUtime(0));
  double max_angle = 0.0;
  for (int k = 1; k < sim->num_frames(); ++k) {
    const Rigid3d p = sim->WorldFromCam(sim->FrameUtime(k));
    EXPECT_LT(TranslationDistance(first, p), 1e-9);
    max_angle = std::max(max_angle, RotationDistance(first, p));
  }
  EXPECT_GT(max_angle, 0.35);
}

// robot_odometry: a 50 Hz odometry stream, whose truth is the camera trajectory seen
// through the extrinsic, and whose noise makes it drift by a realistic amount.
TEST(Scenarios, RobotOdometryStream) {
  Simulator* sim = Get("robot_odometry");
  ASSERT_TRUE(sim);
  ASSERT_TRUE(sim->has_odometry());
  ASSERT_TRUE(sim->base_from_cam().has_value());
  const auto& odo = sim->odometry();
  const auto& truth = sim->odometry_truth();
  ASSERT_EQ(odo.size(), truth.size());
  ASSERT_GT(odo.size(), 400u);
  const double duration_s = 1e-6 * static_cast<double>(odo.back().utime - odo.front().utime);
  EXPECT_NEAR((odo.size() - 1) / duration_s, 50.0, 0.5);
  EXPECT_GT(odo.front().utime, sim->FrameUtime(0));  // own clock, offset from the images
  // world_from_cam(t) = world_from_odom * odom_from_base(t) * base_from_cam for one
  // fixed world_from_odom.
  const Rigid3d base_from_cam = *sim->base_from_cam();
  const Rigid3d world_from_odom = sim->WorldFromCam(truth.front().utime) * base_from_cam.Inverse() *
                                  truth.front().odom_from_base.Inverse();
  for (size_t i = 0; i < truth.size(); i += 25) {
    const Rigid3d predicted = world_from_odom * truth[i].odom_from_base * base_from_cam;
    const Rigid3d actual = sim->WorldFromCam(truth[i].utime);
    EXPECT_LT(TranslationDistance(predicted, actual), 1e-6);
    EXPECT_LT(RotationDistance(predicted, actual), 1e-6);
    EXPECT_EQ(odo[i].seq, static_cast<int64_t>(i));
  }
  // Drift: noticeable but bounded (metres of travel, centimetres to decimetres of error).
  const double travelled = [&] {
    double d = 0.0;
    for (size_t i = 1; i < truth.size(); ++i) {
      d += (truth[i].odom_from_base.translation - truth[i - 1].odom_from_base.translation).norm();
    }
    return d;
  }();
  const double drift =
      (odo.back().odom_from_base.translation - truth.back().odom_from_base.translation).norm();
  EXPECT_GT(travelled, 5.0);
  EXPECT_GT(drift, 0.005);
  EXPECT_LT(drift, 0.1 * travelled);
  // Reported covariances grow with time.
  EXPECT_GT(odo.back().pose_covariance(0, 0), odo[10].pose_covariance(0, 0));
  EXPECT_GT(odo.back().twist_covariance(0, 0), 0.0);
}

// Images a feature tracker can work with: FAST corners everywhere, on the static world
// and on every large mover, and pyramidal KLT tracks that follow the true motion.
TEST(Scenarios, TexturedAndTrackable) {
  for (const auto& name : ScenarioNames()) {
    Simulator* sim = Get(name);
    ASSERT_TRUE(sim);
    SimFrame a, b;
    const int k = sim->num_frames() / 2;
    ASSERT_TRUE(sim->RenderFrame(k, &a).ok());
    ASSERT_TRUE(sim->RenderFrame(k + 1, &b).ok());
    std::vector<cv::KeyPoint> kps;
    cv::FAST(a.image_gray, kps, 15, true);
    std::map<int, int> per_body;
    for (const auto& kp : kps) {
      ++per_body[a.mask.at<uint16_t>(cvRound(kp.pt.y), cvRound(kp.pt.x))];
    }
    EXPECT_GT(per_body[0], 300) << name;
    for (const auto& body : a.bodies) {
      if (body.pixel_count < 2000) {
        continue;
      }
      EXPECT_GT(per_body[body.id], body.pixel_count / 250)
          << name << " body " << body.id << " (" << body.pixel_count << " px)";
    }

    // KLT from frame k to k+1 against the true motion of each tracked surface point.
    std::vector<cv::Point2f> p0, p1;
    cv::goodFeaturesToTrack(a.image_gray, p0, 400, 0.01, 6);
    std::vector<uchar> ok;
    std::vector<float> err;
    cv::calcOpticalFlowPyrLK(a.image_gray, b.image_gray, p0, p1, ok, err, cv::Size(21, 21), 3);
    const Rigid3d cam_b_from_world = b.world_from_cam.Inverse();
    std::vector<double> errors;
    for (size_t i = 0; i < p0.size(); ++i) {
      const int x = cvRound(p0[i].x), y = cvRound(p0[i].y);
      if (x < 1 || y < 1 || x >= a.mask.cols - 1 || y >= a.mask.rows - 1) {
        continue;
      }
      const int id = a.mask.at<uint16_t>(y, x);
      // Only interior points of one surface: all 3x3 neighbours on the same body.
      bool interior = a.depth.at<float>(y, x) > 0.0f;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          interior = interior && a.mask.at<uint16_t>(y + dy, x + dx) == id;
        }
      }
      if (!interior) {
        continue;
      }
      // The surface point under the feature (bilinear in the rendered points), moved with
      // its body to frame k+1.
      cv::Mat patch;
      cv::getRectSubPix(a.points_in_cam, cv::Size(1, 1), p0[i], patch, CV_32F);
      const cv::Vec3f q = patch.at<cv::Vec3f>(0, 0);
      const Eigen::Vector3d in_world = a.world_from_cam * Eigen::Vector3d(q[0], q[1], q[2]);
      const Rigid3d b_from_a_body =
          sim->WorldFromBody(id, b.utime) * sim->WorldFromBody(id, a.utime).Inverse();
      const Eigen::Vector2d expected =
          sim->intrinsics().Project(cam_b_from_world * (b_from_a_body * in_world));
      if (!ok[i] || !sim->intrinsics().InImage(expected, 10.0)) {
        continue;
      }
      errors.push_back((expected - Eigen::Vector2d(p1[i].x, p1[i].y)).norm());
    }
    ASSERT_GT(errors.size(), 100u) << name;
    std::sort(errors.begin(), errors.end());
    const double median = errors[errors.size() / 2];
    const double within_1px =
        static_cast<double>(std::lower_bound(errors.begin(), errors.end(), 1.0) - errors.begin()) /
        errors.size();
    EXPECT_LT(median, 0.25) << name;
    EXPECT_GT(within_1px, 0.85) << name;
  }
}

}  // namespace
}  // namespace sim
}  // namespace mbslam
