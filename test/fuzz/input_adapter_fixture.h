#ifndef MBSLAM_TEST_FUZZ_INPUT_ADAPTER_FIXTURE_H_
#define MBSLAM_TEST_FUZZ_INPUT_ADAPTER_FIXTURE_H_

// The perception service's input side as its fuzz targets run it: the real
// InputAdapter in front of the real PerceptionPipeline (lockstep, so every accepted
// image is decoded in the pipeline's decode thread), with the SLAM core replaced by a
// processor that only checks what reaches it. A fresh fixture per input keeps runs
// reproducible.

#include <cmath>
#include <memory>

#include "services/perception/lcm_adapters/input_adapter.h"
#include "services/perception/pipeline/counters.h"
#include "services/perception/pipeline/frame_processor.h"
#include "services/perception/pipeline/pipeline.h"
#include "services/perception/pipeline/stage_timers.h"
#include "test/fuzz/fuzz_util.h"

namespace mbslam {
namespace fuzz {

// What the core may assume about its inputs.
class CheckingProcessor : public FrameProcessor {
 public:
  void OnOdometry(const OdometrySample& o) override {
    if (!o.odom_from_base.translation.allFinite() ||
        !o.odom_from_base.rotation.coeffs().allFinite() ||
        std::abs(o.odom_from_base.rotation.norm() - 1.0) > 1e-3 || !o.twist_in_base.allFinite() ||
        !o.pose_covariance.allFinite()) {
      Fail("odometry reaching the core is not finite / not a rotation");
    }
  }
  FrameResult ProcessFrame(const ImageFrame& f) override {
    if (f.gray.empty() || !f.intrinsics || f.gray.cols != f.intrinsics->width ||
        f.gray.rows != f.intrinsics->height || !f.intrinsics->Validate().ok()) {
      Fail("image reaching the core has no valid intrinsics of its size");
    }
    return FrameResult();
  }
};

class NullSink : public OutputSink {
 public:
  void OnFrameResult(const FrameResult&) override {}
};

struct InputAdapterFixture {
  InputAdapterFixture() {
    QuietLogs();
    pipeline_options.mode = "lockstep";
    pipeline = std::make_unique<PerceptionPipeline>(pipeline_options, &processor, &sink,
                                                    &counters, &timers);
    Status status;
    adapter = InputAdapter::Create(input_options, pipeline_options, pipeline.get(), &counters,
                                   &status);
    if (!adapter) Fail("InputAdapter::Create failed");
    pipeline->Start();
  }
  ~InputAdapterFixture() { pipeline->Stop(); }

  PipelineOptions pipeline_options;  // the service's defaults but lockstep
  InputOptions input_options;        // the service's defaults
  CheckingProcessor processor;
  NullSink sink;
  Counters counters;
  StageTimers timers;
  std::unique_ptr<PerceptionPipeline> pipeline;
  std::unique_ptr<InputAdapter> adapter;
};

}  // namespace fuzz
}  // namespace mbslam

#endif  // MBSLAM_TEST_FUZZ_INPUT_ADAPTER_FIXTURE_H_
