#include "tools/sim/scenarios.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <random>
#include <thread>

#include "common/util/logging.h"

namespace mbslam {
namespace sim {
namespace {

struct Timeline {
  int64_t start = 0;  // first image (µs)
  int64_t end = 0;    // last image (µs)
  int64_t begin = 0;  // trajectories are sampled from here (µs) ...
  int64_t stop = 0;   // ... to here
  double duration_s = 0.0;

  double Seconds(int64_t utime) const { return 1e-6 * static_cast<double>(utime - start); }
};

struct MoverSpec {
  BodyClass body_class = BodyClass::kBox;
  Eigen::Vector3d extent = Eigen::Vector3d::Ones();
  PoseTrack track;
  cv::Scalar tint = cv::Scalar(-1, -1, -1);
};

struct ScenarioPlan {
  PoseTrack camera;
  std::optional<PoseTrack> base;
  Rigid3d base_from_cam;
  std::vector<MoverSpec> movers;
  double building_margin_m = 14.0;     // distance of the building rows from the camera path (m)
  double clutter_per_m2 = 1.0 / 70.0;  // clutter boxes per square metre of free area
  int max_clutter = 40;
};

const Eigen::Vector3d kCarExtent(4.2, 1.8, 1.5);
const Eigen::Vector3d kPersonExtent(0.4, 0.5, 1.75);  // depth (forward), shoulder width, height
const Eigen::Vector3d kRobotExtent(0.7, 0.5, 0.6);

MoverSpec Mover(BodyClass c, const Eigen::Vector3d& extent, PoseTrack track,
                const cv::Scalar& tint = cv::Scalar(-1, -1, -1)) {
  MoverSpec m;
  m.body_class = c;
  m.extent = extent;
  m.track = std::move(track);
  m.tint = tint;
  return m;
}

// A body riding a planar path with its box resting on the ground.
MoverSpec PathMover(BodyClass c, const Eigen::Vector3d& extent, const PlanarPath& path,
                    const Timeline& tl, const cv::Scalar& tint = cv::Scalar(-1, -1, -1)) {
  return Mover(c, extent, path.ToTrack(tl.start, tl.begin, tl.stop, 0.5 * extent.z()), tint);
}

// A body driving around an ellipse (semi-axes ax along x, ay along y) at roughly constant
// speed, heading along the tangent; direction +1 counter-clockwise, -1 clockwise.
MoverSpec EllipseMover(BodyClass c, const Eigen::Vector3d& extent, const Eigen::Vector2d& center,
                       double ax, double ay, double speed, double phase, int direction,
                       const Timeline& tl, const cv::Scalar& tint = cv::Scalar(-1, -1, -1)) {
  // Ramanujan's perimeter gives the mean angular rate for the requested speed.
  const double h = std::pow(ax - ay, 2) / std::pow(ax + ay, 2);
  const double perimeter = M_PI * (ax + ay) * (1.0 + 3.0 * h / (10.0 + std::sqrt(4.0 - 3.0 * h)));
  const double rate = direction * 2.0 * M_PI * speed / perimeter;
  const double z = 0.5 * extent.z();
  auto track = PoseTrack::Sample(
      [=](int64_t utime) {
        const double th = phase + rate * tl.Seconds(utime);
        const double x = center.x() + ax * std::cos(th), y = center.y() + ay * std::sin(th);
        const double dx = -ax * std::sin(th) * rate, dy = ay * std::cos(th) * rate;
        return PlanarPose(x, y, z, std::atan2(dy, dx));
      },
      tl.begin, tl.stop);
  return Mover(c, extent, std::move(track), tint);
}

struct HandheldSpec {
  double height = 1.55;           // eye height (m)
  double pitch_down = 0.08;       // mean downward pitch (rad)
  double pitch_amplitude = 0.03;  // slow pitch oscillation (rad)
  double pitch_period_s = 5.0;
  std::function<double(double)> look_yaw = [](double) {
    return 0.0;
  };                                     // relative to the path heading (rad)
  double shake_rotation_rms = 0.004;     // hand tremor (rad)
  double shake_translation_rms = 0.006;  // (m)
  double bob_amplitude = 0.015;          // walking bob at 2 Hz (m)
};

// world_from_cam of a hand-held camera carried along `head(t)` = (x, y, yaw, speed).
PoseTrack HandheldCamera(const std::function<PlanarPath::State(double)>& head,
                         const HandheldSpec& spec, const Timeline& tl, uint64_t seed) {
  const SmoothNoise3 tremor(seed * 3 + 1, spec.shake_rotation_rms, 0.5, 4.0);
  const SmoothNoise3 sway(seed * 3 + 2, spec.shake_translation_rms, 0.6, 3.0);
  return PoseTrack::Sample(
      [&](int64_t utime) {
        const double t = tl.Seconds(utime);
        const PlanarPath::State s = head(t);
        const double bob =
            spec.bob_amplitude * std::min(1.0, s.speed) * std::sin(2.0 * M_PI * 2.0 * t);
        const Eigen::Vector3d offset = sway.At(t) + Eigen::Vector3d(0.0, 0.0, bob);
        const Rigid3d world_from_head = PlanarPose(
            s.x + offset.x(), s.y + offset.y(), spec.height + offset.z(), s.yaw + spec.look_yaw(t));
        const double pitch =
            spec.pitch_down + spec.pitch_amplitude * std::sin(2.0 * M_PI * t / spec.pitch_period_s);
        const Rigid3d head_from_cam =
            ForwardCameraMount(Eigen::Vector3d::Zero(), pitch) *
            Rigid3d(Eigen::Matrix3d(ExpSO3(tremor.At(t))), Eigen::Vector3d::Zero());
        return world_from_head * head_from_cam;
      },
      tl.begin, tl.stop);
}

// world_from_base of a ground robot on a path, with small roll / pitch / bounce from
// uneven ground.
PoseTrack RobotBase(const PlanarPath& path, const Timeline& tl, uint64_t seed, double vibration_rad,
                    double bounce_m) {
  const SmoothNoise3 rock(seed * 5 + 1, vibration_rad, 1.0, 6.0);
  const SmoothNoise3 bounce(seed * 5 + 2, bounce_m, 1.0, 6.0);
  return PoseTrack::Sample(
      [&](int64_t utime) {
        const double t = tl.Seconds(utime);
        const PlanarPath::State s = path.At(t);
        Eigen::Vector3d r = rock.At(t);
        r.z() = 0.0;  // no yaw jitter: heading follows the wheels
        return PlanarPose(s.x, s.y, bounce.At(t).z(), s.yaw) *
               Rigid3d(Eigen::Matrix3d(ExpSO3(r)), Eigen::Vector3d::Zero());
      },
      tl.begin, tl.stop);
}

PoseTrack CameraOnBase(const PoseTrack& base, const Rigid3d& base_from_cam, const Timeline& tl) {
  return PoseTrack::Sample([&](int64_t utime) { return base.WorldFromBody(utime) * base_from_cam; },
                           tl.begin, tl.stop);
}

// ---------------------------------------------------------------- scenarios

ScenarioPlan StaticPlan(const Timeline& tl, uint64_t seed) {
  ScenarioPlan plan;
  PlanarPath path(0.0, 0.0, 0.0, 1.0);
  path.Drive(tl.duration_s + 2.0, 0.0, 0.04);
  HandheldSpec spec;
  spec.look_yaw = [](double t) { return 0.35 * std::sin(2.0 * M_PI * t / 7.0); };
  plan.camera = HandheldCamera([&](double t) { return path.At(t); }, spec, tl, seed);
  return plan;
}

ScenarioPlan CrossingPlan(const Timeline& tl, uint64_t seed) {
  ScenarioPlan plan;
  PlanarPath path(0.0, 0.0, 0.0, 0.5);
  path.Drive(tl.duration_s + 2.0);
  HandheldSpec spec;
  spec.look_yaw = [](double t) { return 0.12 * std::sin(2.0 * M_PI * t / 9.0); };
  plan.camera = HandheldCamera([&](double t) { return path.At(t); }, spec, tl, seed);
  const double d = tl.duration_s + 2.0;
  plan.movers.push_back(PathMover(BodyClass::kCar, kCarExtent,
                                  PlanarPath(20.0, 22.0, -M_PI / 2, 7.0).Drive(d), tl,
                                  cv::Scalar(0.15, 0.2, 0.75)));
  plan.movers.push_back(PathMover(BodyClass::kCar, kCarExtent,
                                  PlanarPath(24.0, -30.0, M_PI / 2, 5.0).Drive(d), tl,
                                  cv::Scalar(0.7, 0.45, 0.15)));
  plan.movers.push_back(PathMover(BodyClass::kPerson, kPersonExtent,
                                  PlanarPath(9.0, -7.0, M_PI / 2, 1.3).Drive(d), tl));
  plan.movers.push_back(PathMover(BodyClass::kPerson, kPersonExtent,
                                  PlanarPath(11.5, 6.0, -M_PI / 2, 1.1).Drive(d), tl));
  plan.movers.push_back(PathMover(BodyClass::kRobot, kRobotExtent,
                                  PlanarPath(14.0, -4.0, M_PI / 2, 0.8).Drive(d, 0.0, -0.1), tl,
                                  cv::Scalar(0.8, 0.8, 0.8)));
  return plan;
}

ScenarioPlan FollowingPlan(const Timeline& tl, uint64_t seed) {
  ScenarioPlan plan;
  const double d = tl.duration_s + 2.0;
  PlanarPath path(0.0, 0.0, 0.0, 1.2);
  path.Drive(d);
  // Vibration rotates the camera about its own centre only: its translation stays on
  // the line y = 0, z = h, so everything moving along x keeps inside its epipolar plane.
  plan.base_from_cam = ForwardCameraMount(Eigen::Vector3d(0.2, 0.0, 0.8), 0.05);
  const PoseTrack base = path.ToTrack(tl.start, tl.begin, tl.stop, 0.0);
  const SmoothNoise3 vibration(seed * 5 + 1, 0.002, 1.0, 6.0);
  plan.camera = PoseTrack::Sample(
      [&](int64_t utime) {
        return base.WorldFromBody(utime) * plan.base_from_cam *
               Rigid3d(Eigen::Matrix3d(ExpSO3(vibration.At(tl.Seconds(utime)))),
                       Eigen::Vector3d::Zero());
      },
      tl.begin, tl.stop);
  PlanarPath leader(5.5, 0.0, 0.0, 1.2);
  leader.RampTo(1.5, 3.0).RampTo(1.0, 4.0).RampTo(1.3, 3.0).Drive(std::max(0.0, d - 10.0));
  plan.movers.push_back(PathMover(BodyClass::kPerson, kPersonExtent, leader, tl));
  plan.movers.push_back(PathMover(BodyClass::kRobot, kRobotExtent,
                                  PlanarPath(6.0, -2.5, 0.0, 1.0).Drive(d), tl,
                                  cv::Scalar(0.2, 0.6, 0.9)));
  plan.movers.push_back(PathMover(BodyClass::kCar, kCarExtent,
                                  PlanarPath(-8.0, 4.0, 0.0, 3.0).Drive(d), tl,
                                  cv::Scalar(0.75, 0.75, 0.72)));
  return plan;
}

ScenarioPlan PreviouslyStaticPlan(const Timeline& tl, uint64_t seed) {
  ScenarioPlan plan;
  const double d = tl.duration_s + 2.0;
  PlanarPath path(0.0, 0.0, 0.0, 0.8);
  path.Drive(d);
  HandheldSpec spec;
  spec.look_yaw = [](double t) { return M_PI / 2 + 0.1 * std::sin(2.0 * M_PI * t / 8.0); };
  plan.camera = HandheldCamera([&](double t) { return path.At(t); }, spec, tl, seed);
  const double car_start = std::max(1.0, 0.35 * tl.duration_s);
  const double person_start = std::max(1.5, 0.6 * tl.duration_s);
  PlanarPath car(6.0, 9.0, 0.0, 0.0);
  car.Wait(car_start).RampTo(2.0, 2.5).Drive(d);
  PlanarPath person(5.0, 6.0, 0.0, 0.0);
  person.Wait(person_start).RampTo(1.2, 1.0).Drive(d);
  plan.movers.push_back(
      PathMover(BodyClass::kCar, kCarExtent, car, tl, cv::Scalar(0.2, 0.55, 0.2)));
  plan.movers.push_back(PathMover(BodyClass::kPerson, kPersonExtent, person, tl));
  return plan;
}

ScenarioPlan MultiPlan(const Timeline& tl, uint64_t seed) {
  ScenarioPlan plan;
  HandheldSpec spec;
  spec.height = 1.6;
  spec.pitch_down = 0.14;
  spec.pitch_amplitude = 0.02;
  spec.bob_amplitude = 0.0;
  auto head = [](double t) {
    PlanarPath::State s;
    s.x = 0.3 * std::sin(2.0 * M_PI * t / 14.0);
    s.y = 0.6 * std::sin(2.0 * M_PI * t / 10.0);
    s.yaw = 0.1 * std::sin(2.0 * M_PI * t / 8.0);
    s.speed = 0.3;
    return s;
  };
  plan.camera = HandheldCamera(head, spec, tl, seed);
  plan.movers.push_back(EllipseMover(BodyClass::kCar, kCarExtent, {7.8, -1.5}, 1.5, 3.5, 2.5, 0.0,
                                     1, tl, cv::Scalar(0.1, 0.1, 0.7)));
  plan.movers.push_back(EllipseMover(BodyClass::kCar, kCarExtent, {13.5, 2.5}, 1.5, 4.0, 3.0, 1.0,
                                     -1, tl, cv::Scalar(0.75, 0.6, 0.2)));
  plan.movers.push_back(
      EllipseMover(BodyClass::kPerson, kPersonExtent, {3.6, 1.45}, 0.8, 0.8, 1.1, 0.5, 1, tl));
  plan.movers.push_back(
      EllipseMover(BodyClass::kPerson, kPersonExtent, {4.2, -1.6}, 0.3, 1.3, 1.0, 2.0, -1, tl));
  plan.movers.push_back(
      EllipseMover(BodyClass::kPerson, kPersonExtent, {2.5, -0.4}, 0.45, 0.45, 0.8, 4.0, 1, tl));
  plan.clutter_per_m2 = 1.0 / 120.0;
  return plan;
}

ScenarioPlan RobotOdometryPlan(const Timeline& tl, uint64_t seed) {
  ScenarioPlan plan;
  const double d = tl.duration_s + 2.0;
  PlanarPath path(0.0, 0.0, 0.0, 0.0);
  path.RampTo(1.0, 2.0).Drive(1.5).Turn(M_PI / 3, 0.35).Drive(2.0).Turn(-M_PI / 4, 0.3).Drive(d);
  plan.base = RobotBase(path, tl, seed, 0.003, 0.002);
  plan.base_from_cam = ForwardCameraMount(Eigen::Vector3d(0.25, 0.0, 0.55), 0.1);
  plan.camera = CameraOnBase(*plan.base, plan.base_from_cam, tl);
  plan.movers.push_back(PathMover(BodyClass::kPerson, kPersonExtent,
                                  PlanarPath(12.0, -5.6, M_PI / 2, 1.2).Drive(d), tl));
  plan.movers.push_back(PathMover(BodyClass::kCar, kCarExtent,
                                  PlanarPath(20.0, -25.0, M_PI / 2, 6.0).Drive(d), tl,
                                  cv::Scalar(0.6, 0.2, 0.5)));
  plan.movers.push_back(PathMover(BodyClass::kRobot, kRobotExtent,
                                  PlanarPath(11.0, 12.0, -M_PI / 2, 0.5).Drive(d), tl,
                                  cv::Scalar(0.3, 0.8, 0.8)));
  return plan;
}

ScenarioPlan RotationOnlyPlan(const Timeline& tl, uint64_t seed) {
  ScenarioPlan plan;
  const SmoothNoise3 tremor(seed * 7 + 1, 0.002, 0.5, 4.0);
  plan.camera = PoseTrack::Sample(
      [&](int64_t utime) {
        const double t = tl.Seconds(utime);
        const double yaw = 0.6 * std::sin(2.0 * M_PI * t / 9.0);
        const double pitch = 0.08 + 0.08 * std::sin(2.0 * M_PI * t / 6.0 + 1.0);
        return PlanarPose(0.0, 0.0, 1.5, yaw) * ForwardCameraMount(Eigen::Vector3d::Zero(), pitch) *
               Rigid3d(Eigen::Matrix3d(ExpSO3(tremor.At(t))), Eigen::Vector3d::Zero());
      },
      tl.begin, tl.stop);
  const double d = tl.duration_s + 2.0;
  plan.movers.push_back(PathMover(BodyClass::kPerson, kPersonExtent,
                                  PlanarPath(7.0, 4.0, -M_PI / 2, 1.0).Drive(d), tl));
  plan.movers.push_back(PathMover(BodyClass::kCar, kCarExtent,
                                  PlanarPath(16.0, -30.0, M_PI / 2, 5.0).Drive(d), tl,
                                  cv::Scalar(0.3, 0.3, 0.3)));
  return plan;
}

ScenarioPlan DrivingPlan(const Timeline& tl, uint64_t seed) {
  ScenarioPlan plan;
  const double d = tl.duration_s + 2.0;
  // A car-mounted camera: smooth forward motion at 6 m/s with a gentle lane curve, small
  // suspension pitch / roll.
  PlanarPath path(0.0, 0.0, 0.0, 6.0);
  path.Drive(3.0).Drive(4.0, 0.0, 0.03).Drive(d, 0.0, -0.02);
  const PoseTrack base = RobotBase(path, tl, seed, 0.002, 0.003);
  plan.base_from_cam = ForwardCameraMount(Eigen::Vector3d(1.5, 0.0, 1.3), 0.04);
  plan.camera = CameraOnBase(base, plan.base_from_cam, tl);
  // Its lane follows the camera's path; the oncoming lane is 3.5 m to the left.
  PlanarPath ahead(18.0, 0.0, 0.0, 5.5);
  ahead.Drive(3.0).Drive(4.0, 0.0, 0.03).Drive(d, 0.0, -0.02);
  plan.movers.push_back(
      PathMover(BodyClass::kCar, kCarExtent, ahead, tl, cv::Scalar(0.2, 0.2, 0.6)));
  plan.movers.push_back(PathMover(BodyClass::kCar, kCarExtent,
                                  PlanarPath(75.0, 5.5, M_PI, 8.0).Drive(d), tl,
                                  cv::Scalar(0.7, 0.7, 0.7)));
  plan.movers.push_back(PathMover(BodyClass::kPerson, kPersonExtent,
                                  PlanarPath(40.0, -9.0, M_PI / 2, 1.4).Drive(d), tl));
  plan.movers.push_back(
      PathMover(BodyClass::kPerson, kPersonExtent, PlanarPath(25.0, 8.5, 0.0, 1.2).Drive(d), tl));
  plan.building_margin_m = 12.0;
  return plan;
}

using PlanFn = ScenarioPlan (*)(const Timeline&, uint64_t);

struct ScenarioEntry {
  const char* name;
  PlanFn plan;
  const char* description;
};

const std::vector<ScenarioEntry>& Registry() {
  static const std::vector<ScenarioEntry> entries = {
      {"static", StaticPlan, "hand-held walk through a static town square, no movers"},
      {"crossing", CrossingPlan,
       "hand-held walk; 2 cars, 2 people and a robot cross, enter / leave the view, occlude each "
       "other"},
      {"following", FollowingPlan,
       "robot camera follows a walking person on the same line (degenerate: motion in the epipolar "
       "plane)"},
      {"previously_static", PreviouslyStaticPlan,
       "hand-held sideways walk; a parked car and a standing person start moving part-way"},
      {"multi", MultiPlan,
       "5 movers (2 cars, 3 people) near a slowly moving hand-held camera, >= 25 % of the image"},
      {"robot_odometry", RobotOdometryPlan,
       "camera on a ground robot with noisy 50 Hz wheel odometry and extrinsic base_from_cam"},
      {"rotation_only", RotationOnlyPlan,
       "camera rotating about its centre (no translation); a person and a car move"},
      {"driving", DrivingPlan,
       "car-mounted camera at 6 m/s down a street: a car ahead, an oncoming car, a crossing and a "
       "walking person"},
  };
  return entries;
}

// ---------------------------------------------------------------- static world

struct Corridor {
  std::vector<Eigen::Vector2d> points;
  double half_width = 1.0;  // (m)
};

Corridor CorridorOf(const PoseTrack& track, const Timeline& tl, double half_width) {
  Corridor c;
  c.half_width = half_width;
  const int64_t step = 50000;  // 0.05 s
  for (int64_t t = tl.start; t <= tl.end + step; t += step) {
    c.points.push_back(track.WorldFromBody(t).translation.head<2>());
  }
  return c;
}

bool Intersects(const Eigen::AlignedBox2d& rect, const std::vector<Corridor>& corridors) {
  for (const Corridor& c : corridors) {
    for (const auto& p : c.points) {
      if (rect.exteriorDistance(p) < c.half_width) {
        return true;
      }
    }
  }
  return false;
}

class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}
  double Uniform(double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(engine_);
  }
  bool Chance(double p) { return Uniform(0.0, 1.0) < p; }

 private:
  std::mt19937_64 engine_;
};

void BuildStaticWorld(const ScenarioPlan& plan, const Timeline& tl, SceneBuilder* builder,
                      SceneBody* world, Rng* rng) {
  // The action area: the camera path, with the building rows `building_margin_m` away.
  Eigen::AlignedBox2d area;
  for (int64_t t = tl.start; t <= tl.end + 100000; t += 100000) {
    area.extend(plan.camera.WorldFromBody(t).translation.head<2>());
  }
  area.min() -= Eigen::Vector2d::Constant(plan.building_margin_m);
  area.max() += Eigen::Vector2d::Constant(plan.building_margin_m);

  std::vector<Corridor> building_keep_out{CorridorOf(plan.camera, tl, 3.0)};
  std::vector<Corridor> clutter_keep_out{CorridorOf(plan.camera, tl, 4.5)};
  for (const MoverSpec& m : plan.movers) {
    const double half = 0.5 * std::max(m.extent.x(), m.extent.y());
    building_keep_out.push_back(CorridorOf(m.track, tl, half + 1.0));
    clutter_keep_out.push_back(CorridorOf(m.track, tl, half + 0.8));
  }

  // Ground: 10 m tiles well beyond the buildings, each with its own texture.
  const double tile = 10.0;
  const double gx0 = std::floor((area.min().x() - 40.0) / tile) * tile;
  const double gy0 = std::floor((area.min().y() - 40.0) / tile) * tile;
  const int nx = static_cast<int>(std::ceil((area.max().x() + 40.0 - gx0) / tile));
  const int ny = static_cast<int>(std::ceil((area.max().y() + 40.0 - gy0) / tile));
  for (int ix = 0; ix < nx; ++ix) {
    for (int iy = 0; iy < ny; ++iy) {
      const double x = gx0 + ix * tile, y = gy0 + iy * tile;
      const double r = rng->Uniform(0.0, 1.0);
      const TextureStyle style = r < 0.45
                                     ? TextureStyle::kAsphalt
                                     : (r < 0.85 ? TextureStyle::kPaving : TextureStyle::kGrass);
      builder->AddGroundTile(world, x, y, x + tile, y + tile, style);
    }
  }

  // Buildings: rows along the four sides of the area, pushed outwards where a
  // trajectory passes, dropped where that does not help (a cross street).
  const Rigid3d identity;
  auto add_building = [&](Eigen::AlignedBox2d footprint, const Eigen::Vector2d& outward) {
    for (int attempt = 0; attempt < 4; ++attempt) {
      if (!Intersects(footprint, building_keep_out)) {
        const double height = rng->Uniform(5.0, 16.0);
        const Eigen::Vector2d c = footprint.center();
        const Eigen::Vector2d size = footprint.sizes();
        builder->AddBox(world, identity, Eigen::Vector3d(c.x(), c.y(), 0.5 * height),
                        Eigen::Vector3d(size.x(), size.y(), height), 0.0, TextureStyle::kFacade,
                        false);
        return;
      }
      footprint.translate(6.0 * outward);
    }
  };
  struct Side {
    Eigen::Vector2d start, direction, outward;
    double length;
  };
  const Eigen::Vector2d lo = area.min(), hi = area.max();
  const Side sides[4] = {
      {{lo.x() - 10.0, hi.y()}, {1, 0}, {0, 1}, hi.x() - lo.x() + 20.0},
      {{lo.x() - 10.0, lo.y()}, {1, 0}, {0, -1}, hi.x() - lo.x() + 20.0},
      {{hi.x(), lo.y()}, {0, 1}, {1, 0}, hi.y() - lo.y()},
      {{lo.x(), lo.y()}, {0, 1}, {-1, 0}, hi.y() - lo.y()},
  };
  for (const Side& side : sides) {
    double s = rng->Uniform(0.0, 3.0);
    while (s < side.length) {
      const double width = std::min(rng->Uniform(6.0, 16.0), side.length - s);
      const double depth = rng->Uniform(6.0, 12.0);
      const double setback = rng->Uniform(0.0, 2.0);
      if (width > 2.0) {
        const Eigen::Vector2d a = side.start + side.direction * s + side.outward * setback;
        const Eigen::Vector2d b = a + side.direction * width + side.outward * depth;
        Eigen::AlignedBox2d footprint(a.cwiseMin(b), a.cwiseMax(b));
        add_building(footprint, side.outward);
      }
      s += width + (rng->Chance(0.2) ? rng->Uniform(4.0, 8.0) : rng->Uniform(0.0, 2.5));
    }
  }

  // Clutter: crates, bins, benches, pillars, kiosks, low walls and parked cars.
  const double free_area = area.volume();
  const int wanted = std::min(plan.max_clutter, static_cast<int>(free_area * plan.clutter_per_m2));
  std::vector<Eigen::AlignedBox2d> placed;
  int tries = 0;
  while (static_cast<int>(placed.size()) < wanted && tries++ < 40 * std::max(1, wanted)) {
    const double kind = rng->Uniform(0.0, 1.0);
    Eigen::Vector3d size;
    TextureStyle style = TextureStyle::kConcrete;
    cv::Scalar tint(-1, -1, -1);
    if (kind < 0.25) {
      size =
          Eigen::Vector3d(rng->Uniform(0.5, 1.2), rng->Uniform(0.5, 1.2), rng->Uniform(0.4, 1.1));
      style = TextureStyle::kCrate;
    } else if (kind < 0.4) {
      size = Eigen::Vector3d(0.6, 0.6, rng->Uniform(0.8, 1.2));
    } else if (kind < 0.5) {
      size = Eigen::Vector3d(1.8, 0.5, 0.45);
      style = TextureStyle::kCrate;
    } else if (kind < 0.62) {
      const double w = rng->Uniform(0.25, 0.45);
      size = Eigen::Vector3d(w, w, rng->Uniform(2.5, 4.0));
    } else if (kind < 0.72) {
      size =
          Eigen::Vector3d(rng->Uniform(2.0, 3.0), rng->Uniform(1.8, 2.5), rng->Uniform(2.3, 2.8));
      style = TextureStyle::kFacade;
    } else if (kind < 0.86) {
      size = Eigen::Vector3d(rng->Uniform(3.0, 6.0), 0.3, rng->Uniform(0.7, 1.2));
    } else {
      size = kCarExtent;
      style = TextureStyle::kVehicle;
    }
    const double yaw = rng->Uniform(0.0, M_PI);
    const Eigen::Vector2d c(rng->Uniform(area.min().x(), area.max().x()),
                            rng->Uniform(area.min().y(), area.max().y()));
    const double r = 0.5 * std::hypot(size.x(), size.y());
    const Eigen::AlignedBox2d bound(c - Eigen::Vector2d::Constant(r),
                                    c + Eigen::Vector2d::Constant(r));
    if (Intersects(bound, clutter_keep_out)) {
      continue;
    }
    bool overlaps = false;
    for (const auto& p : placed) {
      if (p.intersects(bound)) {
        overlaps = true;
      }
    }
    if (overlaps) {
      continue;
    }
    placed.push_back(bound);
    builder->AddBox(world, identity, Eigen::Vector3d(c.x(), c.y(), 0.5 * size.z()), size, yaw,
                    style, false, tint);
  }
}

TextureStyle StyleFor(BodyClass c) {
  switch (c) {
    case BodyClass::kCar:
      return TextureStyle::kVehicle;
    case BodyClass::kPerson:
      return TextureStyle::kClothing;
    case BodyClass::kRobot:
      return TextureStyle::kVehicle;
    case BodyClass::kBox:
      return TextureStyle::kCrate;
    case BodyClass::kStatic:
      return TextureStyle::kConcrete;
  }
  return TextureStyle::kConcrete;
}

}  // namespace

std::vector<std::string> ScenarioNames() {
  std::vector<std::string> names;
  for (const auto& e : Registry()) {
    names.emplace_back(e.name);
  }
  return names;
}

std::string ScenarioDescription(const std::string& name) {
  for (const auto& e : Registry()) {
    if (name == e.name) {
      return e.description;
    }
  }
  return "";
}

Status BuildScenario(const SimOptions& options, Scene* scene) {
  const ScenarioEntry* entry = nullptr;
  for (const auto& e : Registry()) {
    if (options.scenario == e.name) {
      entry = &e;
    }
  }
  if (!entry) {
    std::string known;
    for (const auto& n : ScenarioNames()) {
      known += (known.empty() ? "" : ", ") + n;
    }
    return Status::Error("unknown scenario '" + options.scenario + "' (known: " + known + ")");
  }
  Timeline tl;
  tl.start = options.FrameUtime(0);
  tl.end = options.FrameUtime(options.num_frames - 1);
  tl.begin = tl.start - 1000000;
  tl.stop = tl.end + 1000000;
  tl.duration_s = 1e-6 * static_cast<double>(tl.end - tl.start);
  const uint64_t seed = static_cast<uint64_t>(options.seed);

  ScenarioPlan plan = entry->plan(tl, seed);
  *scene = Scene();
  scene->scenario = entry->name;
  scene->camera = plan.camera;
  scene->base = plan.base;
  scene->base_from_cam = plan.base_from_cam;

  std::vector<Eigen::Vector3d> camera_positions;
  for (int64_t t = tl.start; t <= tl.end + 100000; t += 100000) {
    camera_positions.push_back(plan.camera.WorldFromBody(t).translation);
  }
  const double fx = options.camera.Intrinsics().fx;
  SceneBuilder builder(scene, camera_positions, options.texel_m * 525.0 / fx,
                       options.lod_distance_m, options.max_texture_px,
                       seed * 0x2545F4914F6CDD1DULL + 17);
  Rng rng(seed * 0x9E3779B97F4A7C15ULL + 3);

  SceneBody world;
  world.id = 0;
  world.name = "static";
  world.body_class = BodyClass::kStatic;
  world.track = PoseTrack::Constant(Rigid3d());
  BuildStaticWorld(plan, tl, &builder, &world, &rng);
  scene->bodies.push_back(std::move(world));

  int id = 1;
  for (MoverSpec& m : plan.movers) {
    SceneBody body;
    body.id = id++;
    body.body_class = m.body_class;
    body.name = BodyClassName(m.body_class);
    body.extent = m.extent;
    body.track = std::move(m.track);
    builder.AddBox(&body, body.track.WorldFromBody(tl.start), Eigen::Vector3d::Zero(), m.extent,
                   0.0, StyleFor(m.body_class), false, m.tint);
    scene->bodies.push_back(std::move(body));
  }
  builder.GenerateTextures(
      static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 4u)));
  size_t texture_bytes = 0;
  for (const auto& t : scene->textures) {
    texture_bytes += t.total() * t.elemSize();
  }
  MBSLAM_LOG(DEBUG) << "scenario " << scene->scenario << ": " << scene->bodies.size() << " bodies, "
                    << scene->bodies[0].quads.size() << " static quads, " << scene->textures.size()
                    << " textures (" << texture_bytes / (1 << 20) << " MiB)";
  return Status::Ok();
}

}  // namespace sim
}  // namespace mbslam
