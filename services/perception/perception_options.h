#ifndef MBSLAM_SERVICES_PERCEPTION_PERCEPTION_OPTIONS_H_
#define MBSLAM_SERVICES_PERCEPTION_PERCEPTION_OPTIONS_H_

// Every option of perception_service, one section per module. config/perception.yaml
// lists them all with their defaults (a test keeps the two in step).

#include <string>

#include "common/config/options.h"
#include "common/lcm/channels.h"
#include "services/perception/lcm_adapters/input_adapter.h"
#include "services/perception/pipeline/perception_core.h"
#include "services/perception/pipeline/pipeline_options.h"

namespace mbslam {

struct ServiceOptions {
  std::string lcm_url;              // LCM URL; "" = LCM_DEFAULT_URL or LCM's udpm default (ttl=0)
  std::string log_level = "info";   // debug | info | warning | error
  std::string output_dir;           // trajectories, map, occupancy and summary are written here on exit / snapshot; "" = none
  std::string output_log;           // every output message also goes to this LCM log, stamped with message time; "" = none
  bool publish_tracks = true;       // publish the debug PERCEPTION_TRACKS channel
  bool exit_at_end_of_log = true;   // with a file:// URL, stop when the log ends

  bool Check() const {
    MBSLAM_CHECK_OPTION(log_level == "debug" || log_level == "info" || log_level == "warning" ||
                        log_level == "error");
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("lcm_url", &lcm_url, "LCM URL; \"\" = LCM_DEFAULT_URL or LCM's udpm default (ttl=0)");
    v("log_level", &log_level, "debug | info | warning | error");
    v("output_dir", &output_dir, "outputs written here on exit / snapshot request (\"\" = none)");
    v("output_log", &output_log, "LCM log of all outputs, stamped with message time (\"\" = none)");
    v("publish_tracks", &publish_tracks, "publish the debug PERCEPTION_TRACKS channel");
    v("exit_at_end_of_log", &exit_at_end_of_log, "with a file:// URL, stop at the end of the log");
  }
};

struct PerceptionOptions {
  ServiceOptions service;
  ChannelOptions channels;
  PipelineOptions pipeline;
  InputOptions input;
  PreprocessOptions preprocess;
  TrackerOptions tracking;
  SegmentationOptions segmentation;
  PersonDetectorOptions person;
  OdometryOptions odometry;
  SlamOptions slam;
  GroundPlaneOptions ground;
  OccupancyMapOptions occupancy;
  bool occupancy_enabled = true;
  int64_t occupancy_publish_period_us = 1000000;
  int map_publish_every_frames = 15;
  ObjectTrackingOptions objects;
  ObjectReconstructionOptions object_slam;

  CoreOptions core() const {
    CoreOptions c;
    c.preprocess = preprocess;
    c.tracking = tracking;
    c.segmentation = segmentation;
    c.person = person;
    c.odometry = odometry;
    c.slam = slam;
    c.ground = ground;
    c.occupancy = occupancy;
    c.occupancy_enabled = occupancy_enabled;
    c.occupancy_publish_period_us = occupancy_publish_period_us;
    c.map_publish_every_frames = map_publish_every_frames;
    c.objects = objects;
    c.object_slam = object_slam;
    // Lockstep replays must be deterministic: bundle adjustment runs inline there, and
    // stops on its iteration count, not on wall time (a BA cut at 0.2 s under load gave
    // another DAVIS result from the same log).
    if (pipeline.lockstep()) {
      c.slam.background_ba = false;
      c.slam.ba.time_limited = false;
    }
    c.wait_for_person_checks = pipeline.lockstep();
    return c;
  }

  bool Check() const {
    MBSLAM_CHECK_OPTION_SECTION(service);
    MBSLAM_CHECK_OPTION_SECTION(channels);
    MBSLAM_CHECK_OPTION_SECTION(pipeline);
    MBSLAM_CHECK_OPTION_SECTION(input);
    MBSLAM_CHECK_OPTION_SECTION(preprocess);
    MBSLAM_CHECK_OPTION_SECTION(tracking);
    MBSLAM_CHECK_OPTION_SECTION(segmentation);
    MBSLAM_CHECK_OPTION_SECTION(person);
    MBSLAM_CHECK_OPTION_SECTION(odometry);
    MBSLAM_CHECK_OPTION_SECTION(slam);
    MBSLAM_CHECK_OPTION_SECTION(ground);
    MBSLAM_CHECK_OPTION_SECTION(occupancy);
    MBSLAM_CHECK_OPTION_SECTION(objects);
    MBSLAM_CHECK_OPTION_SECTION(object_slam);
    MBSLAM_CHECK_OPTION_GE(occupancy_publish_period_us, 0);
    MBSLAM_CHECK_OPTION_GE(map_publish_every_frames, 1);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("service", &service, "process-level settings");
    v("channels", &channels, "LCM channel names");
    v("pipeline", &pipeline, "threads, queues and the frame-drop policy");
    v("input", &input, "input message handling and calibration");
    v("preprocess", &preprocess, "image pyramid and odometry buffer");
    v("tracking", &tracking, "feature tracking (thesis ch. 2)");
    v("segmentation", &segmentation, "multibody motion segmentation (thesis ch. 3)");
    v("person", &person, "person detection in moving regions (thesis sec. 3.9.4)");
    v("odometry", &odometry, "ego-motion from wheel odometry (thesis sec. 3.8)");
    v("slam", &slam, "static-world keyframe SLAM (thesis ch. 4)");
    v("ground", &ground, "ground plane from the static map (sec. 5.1.1)");
    v("occupancy_enabled", &occupancy_enabled, "build and publish the static-world occupancy map");
    v("occupancy_publish_period_us", &occupancy_publish_period_us,
      "PERCEPTION_OCCUPANCY at most this often, at keyframes (us)");
    v("occupancy", &occupancy, "OctoMap occupancy of the static world (sec. 6.3)");
    v("map_publish_every_frames", &map_publish_every_frames,
      "PERCEPTION_MAP at least this often (frames), and at every keyframe");
    v("objects", &objects, "bearing-only tracking of moving objects, extent, predicted volumes (ch. 5-6)");
    v("object_slam", &object_slam, "reconstruction of moving objects: one SLAM per chosen object (sec. 4.1)");
  }
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PERCEPTION_OPTIONS_H_
