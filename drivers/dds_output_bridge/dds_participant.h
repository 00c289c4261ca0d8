#ifndef MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_DDS_PARTICIPANT_H_
#define MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_DDS_PARTICIPANT_H_

// A Fast DDS participant that never uses multicast: shared memory only, or UDPv4 on the
// whitelisted interfaces with unicast discovery through the initial peers (the metatraffic
// and user-data locators are the first interface; no multicast locator at all).

#include <fastdds/dds/domain/DomainParticipant.hpp>

#include <string>

#include "common/util/status.h"
#include "drivers/dds_output_bridge/perception_dds_bridge_options.h"

namespace mbslam {

// Creates the participant (name: what ROS 2 tools show as its name). The caller deletes
// it with DeleteDdsParticipant.
Status CreateDdsParticipant(const DdsOutputOptions& options, const std::string& name,
                            eprosima::fastdds::dds::DomainParticipant** participant);

// Deletes every entity of the participant, then the participant; null is fine.
void DeleteDdsParticipant(eprosima::fastdds::dds::DomainParticipant* participant);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_DDS_PARTICIPANT_H_
