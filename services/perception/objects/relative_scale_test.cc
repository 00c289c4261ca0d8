#include "services/perception/objects/relative_scale.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "services/perception/objects/random.h"

namespace mbslam {
namespace {

TEST(RelativeScale, RatioAndFirstOrderSigma) {
  const std::optional<RelativeScaleEstimate> e = RelativeScale(10.0, 2.0, 1.0, 0.1);
  ASSERT_TRUE(e);
  EXPECT_DOUBLE_EQ(e->scale, 5.0);
  EXPECT_NEAR(e->sigma, 5.0 * std::sqrt(0.01 + 0.0025), 1e-12);
  EXPECT_NEAR(e->relative_sigma(), std::sqrt(0.0125), 1e-12);
  EXPECT_TRUE(e->IsReliable(0.2));
  EXPECT_FALSE(e->IsReliable(0.1));
  EXPECT_FALSE(RelativeScale(0.0, 2.0, 1.0));
  EXPECT_FALSE(RelativeScale(10.0, -1.0, 1.0));
  EXPECT_FALSE(RelativeScale(10.0, 2.0, -1.0));
  EXPECT_FALSE(RelativeScale(NAN, 2.0, 1.0));
  EXPECT_FALSE(RelativeScale(10.0, 2.0, INFINITY));
}

// The first-order sigma matches the spread of the ratio for small relative errors.
TEST(RelativeScale, SigmaMatchesMonteCarlo) {
  ParticleRng rng(5);
  const double d_bot = 12.0, d_sfm = 3.0, s_bot = 0.6, s_sfm = 0.06;
  double sum = 0.0, sum_sq = 0.0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double s = rng.Normal(d_bot, s_bot) / rng.Normal(d_sfm, s_sfm);
    sum += s;
    sum_sq += s * s;
  }
  const double mean = sum / n;
  const double sigma = std::sqrt(sum_sq / n - mean * mean);
  const RelativeScaleEstimate e = *RelativeScale(d_bot, d_sfm, s_bot, s_sfm);
  EXPECT_NEAR(e.scale, mean, 0.01 * mean);
  EXPECT_NEAR(e.sigma, sigma, 0.03 * sigma);
}

// The one-parameter family of eq. 6.2: the true scale gives the true object pose and map.
TEST(RelativeScale, RescalesObjectPosesAndPointsIntoTheWorld) {
  const Rigid3d world_from_obj(Eigen::Matrix3d(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ())),
                               Eigen::Vector3d(12.0, -2.0, 0.8));
  const Rigid3d world_from_cam(
      Eigen::Matrix3d(Eigen::AngleAxisd(-0.3, Eigen::Vector3d(0.2, 1.0, 0.1).normalized())),
      Eigen::Vector3d(1.0, 0.5, 1.4));
  const Rigid3d cam_from_world = world_from_cam.Inverse();
  const double s = 2.5;  // world units per object map unit
  const Rigid3d cam_from_obj_true = cam_from_world * world_from_obj;
  const Rigid3d cam_from_obj_sfm(cam_from_obj_true.rotation, cam_from_obj_true.translation / s);

  const Rigid3d recovered = WorldFromObject(cam_from_world, cam_from_obj_sfm, s);
  EXPECT_LT(TranslationDistance(recovered, world_from_obj), 1e-9);
  EXPECT_LT(RotationDistance(recovered, world_from_obj), 1e-9);
  // t_wo(s) = R_cw^T (s t_co - t_cw) (eq. 6.2).
  const Eigen::Vector3d t_wo = cam_from_world.RotationMatrix().transpose() *
                               (s * cam_from_obj_sfm.translation - cam_from_world.translation);
  EXPECT_LT((t_wo - world_from_obj.translation).norm(), 1e-9);
  // A wrong scale moves the object along the viewing ray of its origin.
  const Rigid3d wrong = WorldFromObject(cam_from_world, cam_from_obj_sfm, 2.0 * s);
  const Eigen::Vector3d a = (cam_from_world * wrong.translation).normalized();
  const Eigen::Vector3d b = (cam_from_world * world_from_obj.translation).normalized();
  EXPECT_LT((a - b).norm(), 1e-9);

  const std::vector<Eigen::Vector3d> points_true = {{0.5, 0.2, 0.1}, {-1.0, 0.3, 0.7}, {0, 0, 0}};
  std::vector<Eigen::Vector3d> points_sfm;
  for (const Eigen::Vector3d& p : points_true) points_sfm.push_back(p / s);
  const std::vector<Eigen::Vector3d> in_world =
      ObjectPointsInWorld(points_sfm, cam_from_world, cam_from_obj_sfm, s);
  ASSERT_EQ(in_world.size(), points_true.size());
  for (size_t i = 0; i < points_true.size(); ++i) {
    EXPECT_LT((in_world[i] - world_from_obj * points_true[i]).norm(), 1e-9);
  }

  std::vector<Rigid3d> trajectory;
  ASSERT_TRUE(ObjectTrajectoryInWorld({cam_from_world, cam_from_world},
                                      {cam_from_obj_sfm, cam_from_obj_sfm}, s, &trajectory)
                  .ok());
  ASSERT_EQ(trajectory.size(), 2u);
  EXPECT_LT(TranslationDistance(trajectory[1], world_from_obj), 1e-9);
  EXPECT_FALSE(ObjectTrajectoryInWorld({cam_from_world}, {}, s, &trajectory).ok());
  EXPECT_FALSE(
      ObjectTrajectoryInWorld({cam_from_world}, {cam_from_obj_sfm}, 0.0, &trajectory).ok());
}

}  // namespace
}  // namespace mbslam
