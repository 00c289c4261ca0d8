#include "services/perception/geometry/camera.h"

#include <gtest/gtest.h>

namespace mbslam {
namespace {

CameraIntrinsics Make(DistortionModel model, std::vector<double> d) {
  CameraIntrinsics c;
  c.width = 640;
  c.height = 480;
  c.fx = 500;
  c.fy = 505;
  c.cx = 319.5;
  c.cy = 239.5;
  c.model = model;
  c.distortion = std::move(d);
  return c;
}

TEST(Camera, ProjectUnprojectRoundTrip) {
  for (const CameraIntrinsics& c :
       {Make(DistortionModel::kNone, {}),
        Make(DistortionModel::kRadTan, {-0.28, 0.07, 0.0002, -0.0001, 0.0}),
        Make(DistortionModel::kFisheye, {0.01, -0.005, 0.001, -0.0002})}) {
    ASSERT_TRUE(c.Validate().ok()) << c.Validate().message();
    for (double u = 0; u < 640; u += 80) {
      for (double v = 0; v < 480; v += 60) {
        const Eigen::Vector2d uv(u, v);
        const Eigen::Vector3d ray = c.Unproject(uv);
        EXPECT_NEAR(ray.norm(), 1.0, 1e-12);
        EXPECT_LT((c.Project(3.7 * ray) - uv).norm(), 1e-6)
            << DistortionModelName(c.model) << " at " << u << "," << v;
      }
    }
  }
}

TEST(Camera, PinholeMatchesK) {
  const CameraIntrinsics c = Make(DistortionModel::kNone, {});
  const Eigen::Vector3d p(0.3, -0.2, 2.0);
  const Eigen::Vector3d h = c.K() * p;
  EXPECT_LT((c.Project(p) - h.hnormalized()).norm(), 1e-12);
  EXPECT_LT((c.K() * c.KInverse() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST(Camera, ValidationRejectsBadValues) {
  CameraIntrinsics c = Make(DistortionModel::kNone, {});
  c.fx = std::nan("");
  EXPECT_FALSE(c.Validate().ok());
  c = Make(DistortionModel::kRadTan, {0.1, 0.2});
  EXPECT_FALSE(c.Validate().ok());
  c = Make(DistortionModel::kNone, {});
  c.width = 0;
  EXPECT_FALSE(c.Validate().ok());
  c = Make(DistortionModel::kNone, {});
  c.fy = -3;
  EXPECT_FALSE(c.Validate().ok());
}

TEST(Camera, YamlRoundTripAndOpenCvHeader) {
  const CameraIntrinsics c = Make(DistortionModel::kRadTan, {-0.28, 0.07, 0.0002, -0.0001, 0.01});
  CameraIntrinsics back;
  ASSERT_TRUE(ParseCameraIntrinsicsYaml("%YAML:1.0\n" + CameraIntrinsicsToYaml(c), &back).ok());
  EXPECT_EQ(back.width, 640);
  EXPECT_DOUBLE_EQ(back.fy, 505);
  EXPECT_DOUBLE_EQ(back.cx, 319.5);
  ASSERT_EQ(back.distortion.size(), 5u);
  EXPECT_DOUBLE_EQ(back.distortion[4], 0.01);
  EXPECT_EQ(back.model, DistortionModel::kRadTan);

  CameraIntrinsics bad;
  EXPECT_FALSE(ParseCameraIntrinsicsYaml("image_width: 640\n", &bad).ok());
  EXPECT_FALSE(ParseCameraIntrinsicsYaml(
                   "image_width: 640\nimage_height: 480\ncamera_matrix: [1, 0, 1, 0, .nan, 1, 0, 0, 1]\n",
                   &bad)
                   .ok());
  EXPECT_FALSE(ParseCameraIntrinsicsYaml("[", &bad).ok());
}

TEST(Camera, ScaledKeepsPixelCentres) {
  const CameraIntrinsics c = Make(DistortionModel::kNone, {});
  const CameraIntrinsics half = c.Scaled(0.5);
  const Eigen::Vector3d p(0.1, 0.2, 1.0);
  const Eigen::Vector2d full = c.Project(p);
  const Eigen::Vector2d small = half.Project(p);
  EXPECT_LT(((full.array() + 0.5) * 0.5 - 0.5 - small.array()).matrix().norm(), 1e-12);
}

}  // namespace
}  // namespace mbslam
