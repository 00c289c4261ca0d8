#ifndef MBSLAM_TOOLS_SIM_SCENE_H_
#define MBSLAM_TOOLS_SIM_SCENE_H_

// The simulator's scene: rigid bodies made of textured rectangles ("quads") in their
// own frame, each with a trajectory world_from_body, and the camera's trajectory
// world_from_cam. Body 0 is the static world (ground, buildings, clutter); bodies 1..N
// are the independently moving objects, whose body id is the value in the mask. A
// moving body's origin is the centre of its box, its x axis points forward.
//
// The same quads feed the OpenGL renderer and a double-precision CPU ray caster, so the
// rendered images can be checked against the geometry.

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "services/perception/geometry/rigid3.h"
#include "tools/sim/pose_track.h"
#include "tools/sim/procedural_texture.h"

namespace mbslam {
namespace sim {

// A textured parallelogram in its body's frame: the points origin + s * edge_u +
// t * edge_v for s, t in [0, 1]. Its front side faces along edge_u x edge_v (only the
// front side is drawn). The texture covers it once, texture row 0 at t = 1.
struct Quad {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();   // corner (m, body frame)
  Eigen::Vector3d edge_u = Eigen::Vector3d::UnitX();  // first edge (m)
  Eigen::Vector3d edge_v = Eigen::Vector3d::UnitY();  // second edge (m)
  int texture = -1;                                   // index into Scene::textures
  double sample_weight = 1.0;  // relative density of ground-truth surface samples (0 = never seen)

  Eigen::Vector3d Normal() const { return edge_u.cross(edge_v).normalized(); }
  double Area() const { return edge_u.cross(edge_v).norm(); }
  Eigen::Vector3d Point(double s, double t) const { return origin + s * edge_u + t * edge_v; }
};

enum class BodyClass { kStatic, kCar, kPerson, kBox, kRobot };
const char* BodyClassName(BodyClass c);

struct SceneBody {
  int id = 0;        // mask value; 0 = static world
  std::string name;  // "static", "car", "person", "box", "robot"
  BodyClass body_class = BodyClass::kStatic;
  Eigen::Vector3d extent =
      Eigen::Vector3d::Zero();  // full box size along body x, y, z (m); 0 for static
  std::vector<Quad> quads;
  PoseTrack track;  // world_from_body over time
};

struct Scene {
  std::string scenario;
  std::vector<SceneBody> bodies;  // bodies[0] is the static world (id 0), then ids 1..N
  std::vector<cv::Mat> textures;  // BGR 8-bit
  PoseTrack camera;               // world_from_cam
  // Robot carrying the camera (robot_odometry): world_from_base and base_from_cam.
  std::optional<PoseTrack> base;
  Rigid3d base_from_cam;
  Eigen::Vector3d light_direction =
      Eigen::Vector3d(0.4, 0.25, 0.88).normalized();  // towards the sun, world
  double ambient = 0.45;  // fraction of light that is not directional [0, 1]

  // Index into `bodies` of the body with this id, or -1.
  int BodyIndex(int id) const;
  // Bounding box of a body's geometry in its own frame.
  Eigen::AlignedBox3d BodyBounds(size_t index) const;
};

// Adds geometry and textures to a scene. The texel size of each surface grows with its
// distance from the camera path (level of detail), so textures stay small without
// becoming blurry where the camera looks from close by.
class SceneBuilder {
 public:
  // camera_positions: samples of the camera path (world, m). base_texel_m: texel size
  // of surfaces within `lod_distance_m` of the camera (m); max_texture_px caps a side.
  SceneBuilder(Scene* scene, std::vector<Eigen::Vector3d> camera_positions, double base_texel_m,
               double lod_distance_m, int max_texture_px, uint64_t seed);

  // A box of size `size` (m) centred at `center_in_body`, yawed by `yaw` about body z.
  // For the static world (body id 0), world_from_body gives the level of detail, and
  // faces never seen from the camera path get a token texture; moving bodies always get
  // the full resolution. `texel_factor` scales the texel size.
  void AddBox(SceneBody* body, const Rigid3d& world_from_body,
              const Eigen::Vector3d& center_in_body, const Eigen::Vector3d& size, double yaw,
              TextureStyle style, bool with_bottom, const cv::Scalar& tint = cv::Scalar(-1, -1, -1),
              double texel_factor = 1.0);
  // A horizontal ground rectangle at z = 0 (static body).
  void AddGroundTile(SceneBody* body, double x0, double y0, double x1, double y1,
                     TextureStyle style);

  uint64_t NextSeed();

  // Textures are generated here, not when geometry is added: call once after adding
  // everything (uses `threads` threads, joined before returning).
  void GenerateTextures(int threads);

 private:
  struct TextureJob {
    TextureStyle style;
    int width;
    int height;
    double texel_m;
    uint64_t seed;
    cv::Scalar tint;
  };
  int AddTexture(const Quad& quad, const Rigid3d& world_from_body, bool is_static,
                 TextureStyle style, const cv::Scalar& tint, double texel_factor);
  double DistanceToCamera(const Eigen::Vector3d& point) const;

  Scene* scene_;
  std::vector<Eigen::Vector3d> camera_positions_;
  double base_texel_m_;
  double lod_distance_m_;
  int max_texture_px_;
  uint64_t seed_;
  double sample_weight_ = 1.0;    // of the quad whose texture was made last
  std::vector<TextureJob> jobs_;  // textures to generate (the last jobs_.size() of the scene's)
};

// Result of casting a ray into the scene.
struct RayHit {
  int body_index = -1;  // index into Scene::bodies, -1 if nothing was hit
  int quad_index = -1;
  double distance = 0.0;  // along the (unit) ray direction (m)
  Eigen::Vector3d point_in_body = Eigen::Vector3d::Zero();
  double edge_distance = 0.0;  // distance of the hit from the quad's border (m)
};

// Double-precision ray casting into a scene (for checks of the rendered images).
class RayCaster {
 public:
  explicit RayCaster(const Scene& scene);

  // The nearest front-facing quad hit by the ray origin + d * direction (direction
  // unit, world frame), with body i at world_from_body[i].
  RayHit Cast(const std::vector<Rigid3d>& world_from_body, const Eigen::Vector3d& origin,
              const Eigen::Vector3d& direction) const;

 private:
  const Scene& scene_;
  std::vector<Eigen::AlignedBox3d> bounds_;  // per body, body frame
};

// Random samples on the front sides of a body's quads (body frame), about
// `points_per_m2` per square metre (times each quad's sample_weight) but at least
// `min_points` and at most `max_points`.
std::vector<Eigen::Vector3d> SampleSurfacePoints(const SceneBody& body, double points_per_m2,
                                                 int min_points, int max_points, uint64_t seed);

}  // namespace sim
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_SIM_SCENE_H_
