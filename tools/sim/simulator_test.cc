// Ground-truth consistency of every scenario (issue 3, "what it must show" 1): projecting
// the ground-truth 3D points of each body with the ground-truth poses lands on rendered
// pixels of the same body id, the rendered surfaces pass through those points where they
// project (sub-pixel), and depth maps and masks agree with a ray cast into the geometry.

#include "tools/sim/simulator.h"

#include <gtest/gtest.h>

#include "tools/sim/gt_check.h"
#include "tools/sim/scenarios.h"

namespace mbslam {
namespace sim {
namespace {

SimOptions SmallOptions(const std::string& scenario) {
  SimOptions o;
  o.scenario = scenario;
  o.camera.width = 320;
  o.camera.height = 240;
  return o;
}

class ScenarioGroundTruth : public ::testing::TestWithParam<std::string> {};

TEST_P(ScenarioGroundTruth, ProjectionsMasksAndDepthAgree) {
  Status status;
  auto sim = Simulator::Create(SmallOptions(GetParam()), &status);
  ASSERT_TRUE(sim) << status.message();
  GtCheckOptions options;
  options.pixel_stride = 3;
  GtCheckReport report;
  SimFrame frame;
  const int n = 4;
  for (int i = 0; i < n; ++i) {
    const int k = i * (sim->num_frames() - 1) / (n - 1);
    ASSERT_TRUE(sim->RenderFrame(k, &frame, RenderRequest{false, true}).ok());
    ASSERT_TRUE(CheckFrameGroundTruth(*sim, frame, options, &report).ok());
  }
  SCOPED_TRACE(report.ToJson());
  // Enough evidence, on the static world and (where there are movers) on moving bodies.
  EXPECT_GT(report.samples_visible, 500);
  if (!sim->MovingBodyIds().empty()) {
    EXPECT_GT(report.samples_visible_moving, 100);
  }
  EXPECT_GT(report.reprojection_samples, 200);
  // Every visible sample lies on a pixel of its body (within the half pixel a silhouette
  // can fall between a projection and the nearest pixel centre).
  EXPECT_EQ(report.label_failures, 0);
  EXPECT_LE(report.label_max_px, 0.5);
  // The rendered surface meets each sample where the ground truth projects it.
  EXPECT_LE(report.reprojection_max_px, 0.05);
  EXPECT_LE(report.surface_max_distance_m, 1e-3);
  // Masks and depth at pixel centres agree with ray casts; the only mismatches allowed
  // are pixel centres lying on a silhouette (within 0.02 px).
  EXPECT_EQ(report.pixel_label_mismatches, report.pixel_label_mismatches_on_edges);
  EXPECT_LE(report.pixel_label_mismatches, report.pixels / 2000);
  EXPECT_LE(report.depth_max_rel_error, 2e-4);
  EXPECT_LE(report.depth_max_error_px, 0.05);
  EXPECT_LE(report.pixel_backprojection_max_px, 0.01);
}

INSTANTIATE_TEST_SUITE_P(AllScenarios, ScenarioGroundTruth, ::testing::ValuesIn(ScenarioNames()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

TEST(Simulator, DeterministicAndOrderIndependent) {
  SimOptions o = SmallOptions("crossing");
  o.camera.width = 160;
  o.camera.height = 120;
  o.num_frames = 20;
  o.image.noise_sigma = 2.0;
  Status status;
  auto a = Simulator::Create(o, &status);
  ASSERT_TRUE(a) << status.message();
  auto b = Simulator::Create(o, &status);
  ASSERT_TRUE(b) << status.message();
  SimFrame fa, fb, other;
  ASSERT_TRUE(a->RenderFrame(12, &fa).ok());
  ASSERT_TRUE(b->RenderFrame(3, &other).ok());  // a different frame first
  ASSERT_TRUE(b->RenderFrame(12, &fb).ok());
  EXPECT_EQ(cv::norm(fa.image_gray, fb.image_gray, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(fa.image_bgr, fb.image_bgr, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(fa.mask, fb.mask, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(fa.depth, fb.depth, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(fa.image_gray, other.image_gray, cv::NORM_L1), 0.0);
  // A different seed gives a different world.
  o.seed = 2;
  auto c = Simulator::Create(o, &status);
  ASSERT_TRUE(c) << status.message();
  SimFrame fc;
  ASSERT_TRUE(c->RenderFrame(12, &fc).ok());
  EXPECT_GT(cv::norm(fa.image_gray, fc.image_gray, cv::NORM_L1), 0.0);
}

TEST(Simulator, FrameContents) {
  SimOptions o = SmallOptions("multi");
  o.num_frames = 10;
  Status status;
  auto sim = Simulator::Create(o, &status);
  ASSERT_TRUE(sim) << status.message();
  EXPECT_DOUBLE_EQ(sim->intrinsics().fx, 262.5);
  EXPECT_DOUBLE_EQ(sim->intrinsics().cx, 159.5);
  EXPECT_DOUBLE_EQ(sim->intrinsics().cy, 119.5);
  EXPECT_EQ(sim->FrameUtime(3) - sim->FrameUtime(0), 100000);
  SimFrame f;
  ASSERT_TRUE(sim->RenderFrame(5, &f).ok());
  EXPECT_EQ(f.utime, sim->FrameUtime(5));
  EXPECT_EQ(f.image_gray.type(), CV_8UC1);
  EXPECT_EQ(f.image_bgr.type(), CV_8UC3);
  EXPECT_EQ(f.mask.type(), CV_16UC1);
  EXPECT_EQ(f.depth.type(), CV_32FC1);
  EXPECT_EQ(f.image_gray.size(), cv::Size(320, 240));
  ASSERT_EQ(f.bodies.size(), 5u);
  int covered = 0;
  for (const auto& b : f.bodies) {
    EXPECT_GT(b.id, 0);
    EXPECT_GT(b.extent.minCoeff(), 0.3);
    covered += b.pixel_count;
    // The box rests on the ground: its centre is at half its height.
    EXPECT_NEAR(b.world_from_body.translation.z(), 0.5 * b.extent.z(), 1e-9);
  }
  EXPECT_EQ(covered, cv::countNonZero(f.mask));
  EXPECT_FALSE(sim->SurfacePoints(0).empty());
  EXPECT_FALSE(sim->SurfacePoints(1).empty());
  EXPECT_TRUE(sim->SurfacePoints(99).empty());
  // Poses without rendering agree with the rendered frame's.
  SimFrame truth;
  ASSERT_TRUE(sim->FrameTruth(5, &truth).ok());
  EXPECT_LT(TranslationDistance(truth.world_from_cam, f.world_from_cam), 1e-12);
  EXPECT_FALSE(sim->RenderFrame(10, &f).ok());
  EXPECT_FALSE(sim->RenderFrame(-1, &f).ok());
}

TEST(Simulator, RejectsBadOptions) {
  SimOptions o;
  o.scenario = "no_such_scenario";
  Status status;
  EXPECT_FALSE(Simulator::Create(o, &status));
  EXPECT_NE(status.message().find("unknown scenario"), std::string::npos) << status.message();
  o.scenario = "static";
  o.num_frames = 0;
  EXPECT_FALSE(Simulator::Create(o, &status));
}

TEST(Simulator, NoiseAndMotionBlurChangeTheImageOnly) {
  SimOptions o = SmallOptions("crossing");
  o.camera.width = 160;
  o.camera.height = 120;
  o.num_frames = 60;
  Status status;
  auto clean = Simulator::Create(o, &status);
  ASSERT_TRUE(clean) << status.message();
  o.image.noise_sigma = 3.0;
  o.image.motion_blur_samples = 5;
  auto blurred = Simulator::Create(o, &status);
  ASSERT_TRUE(blurred) << status.message();
  SimFrame a, b;
  ASSERT_TRUE(clean->RenderFrame(40, &a).ok());
  ASSERT_TRUE(blurred->RenderFrame(40, &b).ok());
  EXPECT_EQ(cv::norm(a.mask, b.mask, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.depth, b.depth, cv::NORM_INF), 0.0);
  cv::Mat diff;
  cv::absdiff(a.image_gray, b.image_gray, diff);
  EXPECT_GT(cv::mean(diff)[0], 1.0);
  EXPECT_LT(cv::mean(diff)[0], 20.0);
}

}  // namespace
}  // namespace sim
}  // namespace mbslam
