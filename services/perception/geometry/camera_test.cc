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

// Issue 9: a calibration file with a NaN, infinite, zero or negative focal length is
// rejected with an error that names the problem.
TEST(Camera, YamlWithBadFocalLengthIsRejectedClearly) {
  auto yaml = [](const std::string& fx) {
    return "image_width: 640\nimage_height: 480\ncamera_matrix: {rows: 3, cols: 3, data: [" + fx +
           ", 0, 320, 0, 500, 240, 0, 0, 1]}\n";
  };
  CameraIntrinsics c;
  ASSERT_TRUE(ParseCameraIntrinsicsYaml(yaml("500"), &c).ok());
  for (const std::string fx : {"nan", "NaN", "inf", "-inf", "1e999"}) {
    const Status s = ParseCameraIntrinsicsYaml(yaml(fx), &c);
    EXPECT_FALSE(s.ok()) << fx;
    EXPECT_NE(s.message().find("finite"), std::string::npos) << fx << ": " << s.message();
  }
  for (const std::string fx : {"0", "-500", "-0"}) {
    const Status s = ParseCameraIntrinsicsYaml(yaml(fx), &c);
    EXPECT_FALSE(s.ok()) << fx;
    EXPECT_NE(s.message().find("focal lengths must be positive"), std::string::npos)
        << fx << ": " << s.message();
  }
  EXPECT_FALSE(ParseCameraIntrinsicsYaml(yaml(".nan"), &c).ok());
  EXPECT_DOUBLE_EQ(c.fx, 500.0);  // unchanged by the failures
}

// Regression (fuzz_calibration_yaml, issue 9): a camera name that is not UTF-8 was
// written back by CameraIntrinsicsToYaml as U+FFFD; such a file is an error.
TEST(Camera, YamlMustBeUtf8) {
  const std::string body =
      "image_width: 640\nimage_height: 480\ncamera_matrix: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n";
  CameraIntrinsics c;
  ASSERT_TRUE(ParseCameraIntrinsicsYaml("camera_name: caf\xc3\xa9\n" + body, &c).ok());
  CameraIntrinsics back;
  ASSERT_TRUE(ParseCameraIntrinsicsYaml(CameraIntrinsicsToYaml(c), &back).ok());
  EXPECT_EQ(back.name, c.name);
  const Status s = ParseCameraIntrinsicsYaml("camera_name: davis_8\xfe" "4x480\n" + body, &c);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("not UTF-8"), std::string::npos) << s.message();
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
