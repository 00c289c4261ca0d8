#include "services/perception/tracking/orb_features.h"

#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "services/perception/tracking/test_images.h"

namespace mbslam {
namespace {

OrbDescriptor Bits(std::initializer_list<int> set) {
  OrbDescriptor d;
  for (int b : set) d.bits[static_cast<size_t>(b / 8)] |= static_cast<uint8_t>(1u << (b % 8));
  return d;
}

TEST(OrbFeatures, HammingDistanceCountsDifferingBits) {
  EXPECT_EQ(HammingDistance(OrbDescriptor(), OrbDescriptor()), 0);
  EXPECT_EQ(HammingDistance(Bits({0, 9, 63, 64, 255}), OrbDescriptor()), 5);
  EXPECT_EQ(HammingDistance(Bits({0, 9, 63}), Bits({9, 63, 200})), 2);
  OrbDescriptor all;
  all.bits.fill(0xff);
  EXPECT_EQ(HammingDistance(all, OrbDescriptor()), 256);
  // Odd lengths use the byte tail.
  const uint8_t a[3] = {0xff, 0x01, 0x80}, b[3] = {0x0f, 0x00, 0x80};
  EXPECT_EQ(HammingDistance(a, b, 3), 5);
}

TEST(OrbFeatures, MatchOrbIsOneToOneWithTheRatioTest) {
  // Train: four distinct descriptors. Queries: near copies of 0 and 1, a second near
  // copy of 1 (farther: loses the claim), and one halfway between 2 and 3 (ambiguous).
  std::vector<OrbDescriptor> train = {Bits({0, 1, 2, 3, 4, 5, 6, 7, 8, 9}),
                                      Bits({100, 101, 102, 103, 104, 105}),
                                      Bits({200, 201, 202, 203}), Bits({200, 201, 202, 210})};
  std::vector<OrbDescriptor> query = {Bits({0, 1, 2, 3, 4, 5, 6, 7, 8}),
                                      Bits({100, 101, 102, 103, 104}), Bits({100, 101, 102, 103}),
                                      Bits({200, 201, 202})};
  const auto m = MatchOrb(query, train, 50, 0.8);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0], std::make_pair(0, 0));
  EXPECT_EQ(m[1], std::make_pair(1, 1));
  // A query as near to two train descriptors (here both equal to it) is ambiguous.
  EXPECT_TRUE(MatchOrb({Bits({1, 2})}, {Bits({1, 2}), Bits({1, 2})}, 50, 1.0).empty());
  // The distance limit alone.
  EXPECT_TRUE(MatchOrb(query, train, 0, 1.0).empty());
  EXPECT_TRUE(MatchOrb({}, train, 50, 0.8).empty());
  EXPECT_TRUE(MatchOrb(query, {}, 50, 0.8).empty());
}

TEST(OrbFeatures, MatchOrbWithinRadiusComparesOnlyTheTrainPointsNearEachQuery) {
  const OrbDescriptor a = Bits({0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
  const OrbDescriptor b = Bits({100, 101, 102, 103, 104, 105});
  using V = Eigen::Vector2f;
  // Train: a at (100, 100), a copy of a far away at (400, 100), b at (110, 100).
  const std::vector<V> train_uv = {V(100, 100), V(400, 100), V(110, 100)};
  const std::vector<OrbDescriptor> train = {a, a, b};
  // A query like a near (100, 100): the far copy is outside the radius, so it is not
  // ambiguous (global matching finds it ambiguous).
  const OrbDescriptor qa = Bits({0, 1, 2, 3, 4, 5, 6, 7, 8});
  EXPECT_EQ(MatchOrbWithinRadius({V(104, 100)}, {qa}, train_uv, train, 20.0, 50, 0.8),
            (std::vector<std::pair<int, int>>{{0, 0}}));
  EXPECT_TRUE(MatchOrb({qa}, train, 50, 0.8).empty());
  // Near the far copy, the query takes it.
  EXPECT_EQ(MatchOrbWithinRadius({V(390, 95)}, {qa}, train_uv, train, 20.0, 50, 0.8),
            (std::vector<std::pair<int, int>>{{0, 1}}));
  // Beyond the radius of every train point: no match (the radius is a Euclidean one:
  // (85, 115) is 21.2 px from (100, 100), in a neighbouring cell).
  EXPECT_TRUE(MatchOrbWithinRadius({V(250, 100)}, {qa}, train_uv, train, 20.0, 50, 0.8).empty());
  EXPECT_TRUE(MatchOrbWithinRadius({V(85, 115)}, {qa}, train_uv, train, 20.0, 50, 0.8).empty());
  // The ratio test among the points in the radius: 5 bits against 6 fails at 0.8.
  const std::vector<V> two_uv = {V(100, 100), V(105, 100)};
  const std::vector<OrbDescriptor> two = {
      Bits({0, 1, 2, 3, 4, 5, 6, 7, 8, 20, 21, 22, 23, 24}),
      Bits({0, 1, 2, 3, 4, 5, 6, 7, 8, 30, 31, 32, 33, 34, 35})};
  EXPECT_TRUE(MatchOrbWithinRadius({V(102, 100)}, {qa}, two_uv, two, 20.0, 50, 0.8).empty());
  EXPECT_EQ(MatchOrbWithinRadius({V(102, 100)}, {qa}, two_uv, two, 20.0, 50, 1.0).size(), 1u);
  // One to one: two queries on the same train point, the nearer in bits keeps it,
  // whichever comes first.
  const OrbDescriptor qa_far = Bits({0, 1, 2, 3, 4, 5, 6});
  EXPECT_EQ(MatchOrbWithinRadius({V(100, 100), V(101, 100)}, {qa_far, qa}, train_uv, train, 20.0,
                                 50, 0.8),
            (std::vector<std::pair<int, int>>{{1, 0}}));
  EXPECT_EQ(MatchOrbWithinRadius({V(100, 100), V(101, 100)}, {qa, qa_far}, train_uv, train, 20.0,
                                 50, 0.8),
            (std::vector<std::pair<int, int>>{{0, 0}}));
  // Two queries equally near one train point in bits: the first keeps it, in both matchers.
  EXPECT_EQ(
      MatchOrbWithinRadius({V(100, 100), V(101, 100)}, {qa, qa}, train_uv, train, 20.0, 50, 0.8),
      (std::vector<std::pair<int, int>>{{0, 0}}));
  EXPECT_EQ(MatchOrb({qa, qa}, {a, b}, 50, 0.8), (std::vector<std::pair<int, int>>{{0, 0}}));
  // The ratio test's boundary: 4 bits against 5 passes at 0.8 (b1 <= 0.8 b2), in both.
  const OrbDescriptor four = Bits({0, 1, 2, 3, 4, 5, 6, 7, 8, 20, 21, 22, 23});
  const OrbDescriptor five = Bits({0, 1, 2, 3, 4, 5, 6, 7, 8, 30, 31, 32, 33, 34});
  EXPECT_EQ(MatchOrbWithinRadius({V(102, 100)}, {qa}, two_uv, {four, five}, 20.0, 50, 0.8).size(),
            1u);
  EXPECT_EQ(MatchOrb({qa}, {four, five}, 50, 0.8).size(), 1u);
  // The cells cover the radius: 19 px apart across a cell boundary, and at negative
  // coordinates.
  EXPECT_EQ(MatchOrbWithinRadius({V(100, 100)}, {qa}, {V(81, 100)}, {a}, 20.0, 50, 0.8).size(), 1u);
  EXPECT_EQ(MatchOrbWithinRadius({V(-1, 0)}, {qa}, {V(-20.5, 0)}, {a}, 20.0, 50, 0.8).size(), 1u);
  EXPECT_EQ(MatchOrbWithinRadius({V(-1, -1)}, {qa}, {V(-19, -1)}, {a}, 20.0, 50, 0.8).size(), 1u);
  // The distance limit, a query without a position, and degenerate radii.
  EXPECT_TRUE(MatchOrbWithinRadius({V(104, 100)}, {qa}, train_uv, train, 20.0, 0, 0.8).empty());
  EXPECT_TRUE(MatchOrbWithinRadius({V(NAN, 100)}, {qa}, train_uv, train, 20.0, 50, 0.8).empty());
  EXPECT_TRUE(MatchOrbWithinRadius({V(104, 100)}, {qa}, train_uv, train, 0.0, 50, 0.8).empty());
  EXPECT_TRUE(MatchOrbWithinRadius({V(104, 100)}, {qa}, {}, {}, 20.0, 50, 0.8).empty());
  EXPECT_TRUE(
      MatchOrbWithinRadius({V(104, 100)}, {qa}, train_uv, train, INFINITY, 50, 0.8).empty());
  EXPECT_TRUE(
      MatchOrbWithinRadius({V(3e9f, 100)}, {qa}, {V(3e9f, 100)}, {a}, 20.0, 50, 0.8).empty());
}

TEST(OrbFeatures, GivenPointsAreDescribedAsDetectedOnes) {
  const cv::Mat image = testing_images::Texture(320, 240, 7);
  std::vector<Eigen::Vector2f> corners;
  std::vector<OrbDescriptor> detected;
  DetectOrb(image, 300, 10, &corners, &detected);
  ASSERT_GE(corners.size(), 150u);
  for (const Eigen::Vector2f& c : corners) {
    EXPECT_GE(std::min(c.x(), c.y()), 31.0f - 1e-3f);  // ORB's edge threshold
  }
  std::vector<OrbDescriptor> described;
  std::vector<uint8_t> valid;
  DescribeOrbAt(image, corners, &described, &valid);
  ASSERT_EQ(described.size(), corners.size());
  int same = 0, valid_count = 0;
  for (size_t i = 0; i < corners.size(); ++i) {
    if (!valid[i]) continue;
    ++valid_count;
    same += HammingDistance(described[i], detected[i]) <= 8;
  }
  EXPECT_GE(valid_count, static_cast<int>(corners.size()) * 9 / 10);
  EXPECT_GE(same, valid_count * 9 / 10) << same << " of " << valid_count;
}

TEST(OrbFeatures, MatchesAcrossATurnedAndShiftedView) {
  // The second view turns the texture by 25 deg about a point and shifts it: the
  // points described in the first view are found among the second's detected corners.
  const cv::Mat first = testing_images::Texture(400, 300, 11);
  const cv::Mat turn = cv::getRotationMatrix2D(cv::Point2f(190, 160), 25.0, 1.0);
  cv::Mat second;
  cv::Mat shift = turn.clone();
  shift.at<double>(0, 2) += 12.0;
  shift.at<double>(1, 2) -= 7.0;
  cv::warpAffine(first, second, shift, first.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  std::vector<Eigen::Vector2f> corners, corners2;
  std::vector<OrbDescriptor> unused, detected2;
  DetectOrb(first, 400, 10, &corners, &unused);
  std::vector<OrbDescriptor> described;
  std::vector<uint8_t> valid;
  DescribeOrbAt(first, corners, &described, &valid);
  DetectOrb(second, 600, 10, &corners2, &detected2);
  const auto matches = MatchOrb(detected2, described, 50, 0.8);
  int right = 0;
  for (const auto& [q, t] : matches) {
    const Eigen::Vector2f& p = corners[static_cast<size_t>(t)];
    const Eigen::Vector2d expected(
        shift.at<double>(0, 0) * p.x() + shift.at<double>(0, 1) * p.y() + shift.at<double>(0, 2),
        shift.at<double>(1, 0) * p.x() + shift.at<double>(1, 1) * p.y() + shift.at<double>(1, 2));
    right += (corners2[static_cast<size_t>(q)].cast<double>() - expected).norm() < 2.0;
  }
  EXPECT_GE(right, 60) << matches.size() << " matches";
  EXPECT_GE(right, static_cast<int>(matches.size()) * 8 / 10) << matches.size() << " matches";
  // Unrelated texture: few matches get through the ratio test.
  const cv::Mat other = testing_images::Texture(400, 300, 12);
  std::vector<Eigen::Vector2f> corners3;
  std::vector<OrbDescriptor> detected3;
  DetectOrb(other, 600, 10, &corners3, &detected3);
  EXPECT_LT(MatchOrb(detected3, described, 50, 0.8).size(), matches.size() / 5);
}

TEST(OrbFeatures, BorderPointsAndBadImagesAreNotDescribed) {
  const cv::Mat image = testing_images::Texture(200, 160, 3);
  const std::vector<Eigen::Vector2f> points = {{100, 80}, {5, 80}, {100, 150}, {std::nanf(""), 50}};
  std::vector<OrbDescriptor> d;
  std::vector<uint8_t> valid;
  DescribeOrbAt(image, points, &d, &valid);
  ASSERT_EQ(valid.size(), 4u);
  EXPECT_EQ(valid[0], 1);
  EXPECT_EQ(valid[1], 0);
  EXPECT_EQ(valid[2], 0);
  EXPECT_EQ(valid[3], 0);
  cv::Mat colour;
  cv::cvtColor(image, colour, cv::COLOR_GRAY2BGR);
  DescribeOrbAt(colour, points, &d, &valid);
  EXPECT_EQ(valid, std::vector<uint8_t>(4, 0));
  std::vector<Eigen::Vector2f> corners;
  DetectOrb(colour, 100, 10, &corners, &d);
  EXPECT_TRUE(corners.empty());
  DetectOrb(cv::Mat(), 100, 10, &corners, &d);
  EXPECT_TRUE(corners.empty());
}

}  // namespace
}  // namespace mbslam
