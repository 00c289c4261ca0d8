#include "drivers/dds_output_bridge/dds_participant.h"

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

#include <memory>

namespace mbslam {

namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::IPLocator;
using eprosima::fastrtps::rtps::Locator_t;

namespace {

Status Ipv4Locator(const std::string& address, const std::string& what, Locator_t* locator) {
  locator->kind = LOCATOR_KIND_UDPv4;
  if (!IPLocator::setIPv4(*locator, address)) {
    return Status::Error(what + ": '" + address + "' is not an IPv4 address");
  }
  return Status::Ok();
}

Status BuildQos(const DdsOutputOptions& options, const std::string& name,
                dds::DomainParticipantQos* qos) {
  *qos = dds::PARTICIPANT_QOS_DEFAULT;
  qos->name(name);
  qos->transport().use_builtin_transports = false;
  if (options.transport == "shm") {
    qos->transport().user_transports.push_back(
        std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
    return Status::Ok();
  }
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  for (const std::string& iface : options.interfaces) udp->interfaceWhiteList.push_back(iface);
  udp->maxInitialPeersRange = static_cast<uint32_t>(options.max_initial_peers_range);
  qos->transport().user_transports.push_back(udp);

  auto& builtin = qos->wire_protocol().builtin;
  builtin.metatrafficMulticastLocatorList.clear();
  builtin.initialPeersList.clear();
  for (const std::string& peer : options.initial_peers) {
    Locator_t locator;
    MBSLAM_RETURN_IF_ERROR(Ipv4Locator(peer, "dds.initial_peers", &locator));
    builtin.initialPeersList.push_back(
        locator);  // port 0: the well-known ports of each participant id
  }
  Locator_t local;
  MBSLAM_RETURN_IF_ERROR(Ipv4Locator(options.interfaces.front(), "dds.interfaces", &local));
  builtin.metatrafficUnicastLocatorList.clear();
  builtin.metatrafficUnicastLocatorList.push_back(local);  // port 0: the well-known port
  qos->wire_protocol().default_unicast_locator_list.clear();
  qos->wire_protocol().default_unicast_locator_list.push_back(local);
  qos->wire_protocol().default_multicast_locator_list.clear();
  return Status::Ok();
}

}  // namespace

Status CreateDdsParticipant(const DdsOutputOptions& options, const std::string& name,
                            dds::DomainParticipant** participant) {
  *participant = nullptr;
  if (!options.Check()) return Status::Error("dds options: " + LastOptionError());
  dds::DomainParticipantQos qos;
  MBSLAM_RETURN_IF_ERROR(BuildQos(options, name, &qos));
  *participant = dds::DomainParticipantFactory::get_instance()->create_participant(
      static_cast<dds::DomainId_t>(options.domain_id), qos);
  if (*participant == nullptr) {
    return Status::Error("Fast DDS: cannot create a participant in domain " +
                         std::to_string(options.domain_id) + " (" + options.transport + ")");
  }
  return Status::Ok();
}

void DeleteDdsParticipant(dds::DomainParticipant* participant) {
  if (participant == nullptr) return;
  participant->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant);
}

}  // namespace mbslam
