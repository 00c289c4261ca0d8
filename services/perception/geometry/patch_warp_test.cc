#include "services/perception/geometry/patch_warp.h"

#include <gtest/gtest.h>

#include <Eigen/SVD>

namespace mbslam {
namespace {

CameraIntrinsics Pinhole() {
  CameraIntrinsics c;
  c.width = 640;
  c.height = 480;
  c.fx = 500;
  c.fy = 500;
  c.cx = 319.5;
  c.cy = 239.5;
  return c;
}

TEST(PatchWarp, SamePoseIsIdentity) {
  const CameraIntrinsics K = Pinhole();
  const Rigid3d pose(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized())),
                     Eigen::Vector3d(0.2, -0.1, 0.5));
  const Eigen::Vector2d uv(400.0, 100.0);
  const Eigen::Vector3d point = pose.Inverse() * (4.0 * K.PixelToNormalized(uv).homogeneous());
  const auto a = PlaneInducedAffineWarp(K, pose, pose, uv, point, Eigen::Vector3d(0.3, 0.2, 1.0));
  ASSERT_TRUE(a.has_value());
  EXPECT_TRUE(a->isApprox(Eigen::Matrix2d::Identity(), 1e-6)) << *a;
}

TEST(PatchWarp, FrontoParallelPlaneScalesByDepthRatio) {
  // Camera moves 1 m forward towards a wall 4 m away: a patch at the principal point grows
  // by 4 / 3 in both directions.
  const CameraIntrinsics K = Pinhole();
  const Rigid3d ref = Rigid3d::Identity();
  const Rigid3d cur(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, -1.0));
  const auto a = PlaneInducedAffineWarp(K, ref, cur, Eigen::Vector2d(319.5, 239.5), Eigen::Vector3d(0, 0, 4),
                                        Eigen::Vector3d(0, 0, -1));
  ASSERT_TRUE(a.has_value());
  EXPECT_NEAR((*a)(0, 0), 4.0 / 3.0, 1e-6);
  EXPECT_NEAR((*a)(1, 1), 4.0 / 3.0, 1e-6);
  EXPECT_NEAR((*a)(0, 1), 0.0, 1e-9);
  EXPECT_NEAR((*a)(1, 0), 0.0, 1e-9);
}

TEST(PatchWarp, GroundPatchStretchesVerticallyBySquareOfDepthRatio) {
  // Camera 1 m above the ground (y down), a ground point 4 m ahead, the camera moves 1 m
  // forward: horizontal scale 4/3, vertical (4/3)^2, no shear at the image's centre column.
  const CameraIntrinsics K = Pinhole();
  const Rigid3d ref = Rigid3d::Identity();
  const Rigid3d cur(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, -1.0));
  const Eigen::Vector3d point(0.0, 1.0, 4.0);
  const Eigen::Vector2d uv = K.Project(point);
  const auto a = PlaneInducedAffineWarp(K, ref, cur, uv, point, Eigen::Vector3d(0, -1, 0), 0.01);
  ASSERT_TRUE(a.has_value());
  EXPECT_NEAR((*a)(0, 0), 4.0 / 3.0, 1e-3);
  EXPECT_NEAR((*a)(1, 1), 16.0 / 9.0, 1e-3);
  EXPECT_NEAR((*a)(0, 1), 0.0, 1e-6);
  EXPECT_NEAR((*a)(1, 0), 0.0, 1e-6);
}

TEST(PatchWarp, MatchesTheExactTransferOfANeighbouringPixel) {
  // Against a rotating, translating camera with distortion: the warp predicts where a
  // pixel 3 px away lands, up to second order.
  CameraIntrinsics K = Pinhole();
  K.model = DistortionModel::kRadTan;
  K.distortion = {-0.2, 0.05, 0.001, -0.001};
  const Rigid3d ref(Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY())), Eigen::Vector3d(0.1, 0, 0));
  const Rigid3d cur(Eigen::Quaterniond(Eigen::AngleAxisd(-0.2, Eigen::Vector3d(1, 1, 0).normalized())),
                    Eigen::Vector3d(-0.3, 0.1, -0.4));
  const Eigen::Vector3d normal = Eigen::Vector3d(0.2, -1.0, 0.3).normalized();
  const Eigen::Vector2d uv(250.0, 330.0);
  const Rigid3d world_from_ref = ref.Inverse();
  const Eigen::Vector3d point = world_from_ref * (5.0 * K.PixelToNormalized(uv).homogeneous());
  const auto a = PlaneInducedAffineWarp(K, ref, cur, uv, point, normal);
  ASSERT_TRUE(a.has_value());
  const Eigen::Vector2d offset(3.0, -2.0);
  // Exact: the neighbour's ray on the plane, projected.
  const Eigen::Vector3d ray = world_from_ref.rotation * K.Unproject(uv + offset);
  const double lambda = normal.dot(point - world_from_ref.translation) / normal.dot(ray);
  const Eigen::Vector2d exact = K.Project(cur * (world_from_ref.translation + lambda * ray));
  const Eigen::Vector2d centre = K.Project(cur * point);
  EXPECT_LT((centre + *a * offset - exact).norm(), 0.05);
  EXPECT_GT((*a - Eigen::Matrix2d::Identity()).norm(), 0.05);  // a real warp
}

TEST(PatchWarp, RefusesGrazingPlanesAndPointsBehindTheCamera) {
  const CameraIntrinsics K = Pinhole();
  const Rigid3d ref = Rigid3d::Identity();
  // The plane contains the viewing ray.
  EXPECT_FALSE(PlaneInducedAffineWarp(K, ref, ref, Eigen::Vector2d(319.5, 239.5), Eigen::Vector3d(0, 0, 4),
                                      Eigen::Vector3d(1, 0, 0))
                   .has_value());
  // The current camera has passed the point.
  const Rigid3d passed(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, -5.0));
  EXPECT_FALSE(PlaneInducedAffineWarp(K, ref, passed, Eigen::Vector2d(319.5, 239.5), Eigen::Vector3d(0, 0, 4),
                                      Eigen::Vector3d(0, 0, -1))
                   .has_value());
}

TEST(PatchWarp, SingularValuesOfTwoByTwo) {
  const Eigen::Matrix2d m = (Eigen::Matrix2d() << 1.3, -0.4, 0.7, 0.2).finished();
  const Eigen::Vector2d expected = Eigen::JacobiSVD<Eigen::Matrix2d>(m).singularValues();
  EXPECT_TRUE(SingularValues2x2(m).isApprox(expected, 1e-12)) << SingularValues2x2(m).transpose();
  EXPECT_TRUE(SingularValues2x2(Eigen::Matrix2d(Eigen::Matrix2d::Zero())).isZero());
  const Eigen::Matrix2f r = Eigen::Rotation2Df(0.4f).toRotationMatrix() * 1.5f;
  EXPECT_TRUE(SingularValues2x2(r).isApprox(Eigen::Vector2f(1.5f, 1.5f), 1e-5f));
}

}  // namespace
}  // namespace mbslam
