#ifndef MBSLAM_TOOLS_SIM_SCENARIOS_H_
#define MBSLAM_TOOLS_SIM_SCENARIOS_H_

// The named, seeded, deterministic scenarios of the simulator.
//
//   static             hand-held walk through a static town square (no movers)
//   crossing           hand-held walk; cars and people cross the view, enter and leave it
//                      and occlude each other; a delivery robot drives a curve
//   following          camera on a robot driving straight behind a walking person (the
//                      degenerate case of thesis sec. 3.5: object motion inside the
//                      epipolar plane); a robot and a car move parallel to the camera
//   previously_static  hand-held sideways walk; a parked car and a standing person start
//                      to move part-way through the sequence
//   multi              5 movers (2 cars, 3 people) close to a slowly moving hand-held
//                      camera, covering >= 25 % of the image on average
//   robot_odometry     camera on a ground robot with wheel odometry (noisy, 50 Hz) and a
//                      camera-robot extrinsic base_from_cam; people and a car move
//   rotation_only      camera rotating about its centre (no translation); a person and a
//                      car move
//   driving            smooth car-like forward motion at 6 m/s down a street: a car ahead
//                      in the same lane, an oncoming car, pedestrians crossing and walking
//
// World frame: z up, ground plane z = 0, metres.

#include <string>
#include <vector>

#include "common/util/status.h"
#include "tools/sim/scene.h"
#include "tools/sim/sim_options.h"

namespace mbslam {
namespace sim {

std::vector<std::string> ScenarioNames();
// One line describing the scenario, empty for an unknown name.
std::string ScenarioDescription(const std::string& name);

// Builds the scene (geometry, textures, trajectories) of options.scenario.
Status BuildScenario(const SimOptions& options, Scene* scene);

}  // namespace sim
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_SIM_SCENARIOS_H_
