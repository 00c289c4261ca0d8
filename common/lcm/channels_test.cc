#include "common/lcm/channels.h"

#include <gtest/gtest.h>

#include "common/config/options_yaml.h"

namespace mbslam {
namespace {

TEST(Channels, DefaultsAreValidAndOverridable) {
  ChannelOptions channels;
  EXPECT_TRUE(channels.Check());
  ASSERT_TRUE(LoadOptionsFromYamlText("camera_image: CAM_LEFT\n", "channels", &channels).ok());
  EXPECT_EQ(channels.camera_image, "CAM_LEFT");
  EXPECT_EQ(channels.odometry, "ODOMETRY");
}

TEST(Channels, BadNamesAreRejected) {
  ChannelOptions channels;
  EXPECT_FALSE(LoadOptionsFromYamlText("camera_image: \"A.*\"\n", "channels", &channels).ok());
  EXPECT_FALSE(LoadOptionsFromYamlText("camera_image: \"\"\n", "channels", &channels).ok());
  EXPECT_FALSE(IsValidChannelName("has space"));
  EXPECT_TRUE(IsValidChannelName("CAMERA_IMAGE"));
}

}  // namespace
}  // namespace mbslam
