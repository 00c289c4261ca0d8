#include "tools/eval/reconstruction_metrics.h"

#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace mbslam {
namespace eval {
namespace {

TEST(ReconstructionMetricsTest, BoxSurfaceDistance) {
  const Eigen::Vector3d e(4.0, 2.0, 1.0);
  EXPECT_NEAR(BoxSurfaceDistance(Eigen::Vector3d(2.0, 0.0, 0.0), e), 0.0, 1e-12);
  EXPECT_NEAR(BoxSurfaceDistance(Eigen::Vector3d(3.0, 0.0, 0.0), e), 1.0, 1e-12);
  EXPECT_NEAR(BoxSurfaceDistance(Eigen::Vector3d(0.0, 0.0, 0.0), e), 0.5, 1e-12) << "inside: nearest face";
  EXPECT_NEAR(BoxSurfaceDistance(Eigen::Vector3d(3.0, 2.0, 0.0), e), std::sqrt(2.0), 1e-12) << "outside a corner edge";
}

// A reconstruction that is the truth seen through a similarity scores zero, and is matched
// to its own body, not to another one moving differently.
TEST(ReconstructionMetricsTest, ExactReconstructionThroughASimilarityScoresZero) {
  std::map<int, BodyTruth> truth;
  Trajectory cam;
  for (int id : {1, 2}) {
    BodyTruth b;
    b.id = id;
    b.name = id == 1 ? "car" : "person";
    b.extent = id == 1 ? Eigen::Vector3d(4.2, 1.8, 1.5) : Eigen::Vector3d(0.4, 0.5, 1.75);
    truth[id] = b;
  }
  const Sim3d map_from_body{0.2, Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
                            Eigen::Vector3d(1.0, -2.0, 0.5)};
  ReconstructionEstimate est;
  est.object_id = 5;
  est.map_id = 2;
  for (int k = 0; k < 30; ++k) {
    const int64_t t = 1000000 + k * 33333;
    const Rigid3d world_from_cam(Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * k, Eigen::Vector3d::UnitZ())),
                                 Eigen::Vector3d(0.3 * k, 0.0, 1.5));
    cam.push_back({t, world_from_cam});
    const Rigid3d world_from_car(Eigen::Quaterniond::Identity(), Eigen::Vector3d(10.0 - 0.2 * k, 8.0, 0.75));
    const Rigid3d world_from_person(Eigen::Quaterniond::Identity(), Eigen::Vector3d(4.0, 5.0 + 0.05 * k, 0.9));
    truth[1].poses.push_back({t, world_from_car});
    truth[2].poses.push_back({t, world_from_person});
    est.obj_from_cam.push_back({t, map_from_body * (world_from_car.Inverse() * world_from_cam)});
  }
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(2.1, 0.3, 0.2), Eigen::Vector3d(-1.0, 0.9, -0.4),
                                   Eigen::Vector3d(0.5, -0.2, 0.75)}) {
    est.points.push_back(map_from_body * p);
  }
  ReconstructionResult r;
  ASSERT_TRUE(EvaluateReconstruction(est, truth, cam, 20000, 10, &r).ok());
  EXPECT_EQ(r.gt_id, 1);
  EXPECT_EQ(r.samples, 30);
  EXPECT_NEAR(r.scale, 5.0, 1e-6);
  EXPECT_LT(r.trajectory_err_rel_path, 1e-6);
  EXPECT_LT(r.shape_err_rel, 1e-6);
  EXPECT_DOUBLE_EQ(r.share_within_2pct, 1.0);
  // A point 0.42 m off the surface is 10 % of the car's 4.2 m.
  est.points = {map_from_body * Eigen::Vector3d(2.52, 0.0, 0.0)};
  ASSERT_TRUE(EvaluateReconstruction(est, truth, cam, 20000, 10, &r).ok());
  EXPECT_NEAR(r.shape_err_rel, 0.1, 1e-6);
  EXPECT_FALSE(r.shape_translated) << "one point: not fitted (a shift puts up to three on any surface)";
  EXPECT_NEAR(r.shape_translated_err_rel, 0.1, 1e-6);
  // Too few common images: refused.
  est.obj_from_cam.resize(5);
  EXPECT_FALSE(EvaluateReconstruction(est, truth, cam, 20000, 10, &r).ok());
}

TEST(ReconstructionMetricsTest, BoxSignedDistanceIsNegativeInside) {
  const Eigen::Vector3d e(4.0, 2.0, 1.0);
  EXPECT_NEAR(BoxSignedDistance(Eigen::Vector3d(0.0, 0.0, 0.0), e), -0.5, 1e-12);
  EXPECT_NEAR(BoxSignedDistance(Eigen::Vector3d(3.0, 0.0, 0.0), e), 1.0, 1e-12);
  EXPECT_NEAR(BoxSignedDistance(Eigen::Vector3d(1.5, 0.0, 0.0), e), -0.5, 1e-12);
}

// Points on three faces of a box, shifted: the fit shifts them back onto the surface by
// the opposite translation; a bump or a turn (which a shift cannot undo) stays.
TEST(ReconstructionMetricsTest, TranslationFitUndoesAShiftButNotAShapeError) {
  const Eigen::Vector3d e(0.5, 0.6, 1.8);
  std::vector<Eigen::Vector3d> surface;
  for (int i = -2; i <= 2; ++i) {
    for (int j = -4; j <= 4; ++j) {
      surface.emplace_back(0.25, 0.12 * i, 0.2 * j);   // front face (+x)
      surface.emplace_back(0.1 * i, -0.3, 0.2 * j);    // side face (-y)
    }
    surface.emplace_back(0.1 * i, 0.1 * i, 0.9);       // top face
  }
  const Eigen::Vector3d offset(0.03, -0.02, 0.04);
  std::vector<Eigen::Vector3d> pts;
  for (const Eigen::Vector3d& p : surface) pts.push_back(p + offset);
  const Eigen::Vector3d shift = FitTranslationToBoxSurface(e, &pts);
  EXPECT_LT((shift + offset).norm(), 1e-4);
  for (size_t i = 0; i < pts.size(); ++i) {
    EXPECT_LT(BoxSurfaceDistance(pts[i], e), 1e-4);
    EXPECT_LT((pts[i] - (surface[i] + offset + shift)).norm(), 1e-12) << "the points moved by the returned shift";
  }
  const auto rms = [&](const std::vector<Eigen::Vector3d>& q) {
    double sum2 = 0.0;
    for (const Eigen::Vector3d& p : q) sum2 += std::pow(BoxSurfaceDistance(p, e), 2);
    return std::sqrt(sum2 / static_cast<double>(q.size()));
  };
  // A bump of 0.1 m on six points of the front face is a shape error no shift removes.
  std::vector<Eigen::Vector3d> bumped = surface;
  for (int k = 0; k < 6; ++k) bumped[2 * k] += Eigen::Vector3d(0.1, 0.0, 0.0);
  FitTranslationToBoxSurface(e, &bumped);
  EXPECT_GT(rms(bumped), 0.01);
  // Nor a turn of 3 deg about the vertical axis (it moves the far points by 5 cm).
  std::vector<Eigen::Vector3d> turned;
  const Eigen::AngleAxisd turn(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ());
  for (const Eigen::Vector3d& p : surface) turned.push_back(turn * p);
  FitTranslationToBoxSurface(e, &turned);
  EXPECT_GT(rms(turned), 0.005);
  // Three points are not fitted.
  std::vector<Eigen::Vector3d> three = {pts[0] + offset, pts[1] + offset, pts[2] + offset};
  EXPECT_EQ(FitTranslationToBoxSurface(e, &three), Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
