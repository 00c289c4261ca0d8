#include "services/perception/perception_service.h"

#include <gtest/gtest.h>

#include <string>

namespace mbslam {
namespace {

// Regression (issue 9): when Create() failed after the service object existed (LCM URL
// that does not open, calibration file that does not load), its destructor called
// Finish() on the missing pipeline and the process died with SIGSEGV instead of
// printing the error.
TEST(PerceptionService, FailedCreateIsAnErrorNotACrash) {
  PerceptionOptions options;
  options.service.lcm_url = "udpm://300.0.0.1:7667?ttl=0";  // not an address: no socket
  Status status;
  EXPECT_EQ(PerceptionService::Create(options, &status), nullptr);
  EXPECT_FALSE(status.ok());

  Status bus_status;
  auto bus = LcmBus::Create("memq://", &bus_status);
  ASSERT_TRUE(bus);
  options = PerceptionOptions();
  options.input.calibration_file = "/nonexistent/calibration.yaml";
  EXPECT_EQ(PerceptionService::Create(options, &status, bus.get()), nullptr);
  EXPECT_NE(status.message().find("calibration.yaml"), std::string::npos) << status.message();
}

}  // namespace
}  // namespace mbslam
