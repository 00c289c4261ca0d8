#include "drivers/odometry_bridge/dds_odometry.h"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <thread>

#include "common/util/bounded_queue.h"
#include "common/util/time.h"
#include "drivers/odometry_bridge/ros2_odometry_conversion.h"
#include "nav_msgs/msg/dds_/Odometry_PubSubTypes.h"

namespace mbslam {

namespace dds = eprosima::fastdds::dds;
using nav_msgs::msg::dds_::Odometry_;
using nav_msgs::msg::dds_::Odometry_PubSubType;

bool DdsOptions::Check() const {
  MBSLAM_CHECK_OPTION_GE(domain_id, 0);
  MBSLAM_CHECK_OPTION_LE(domain_id, 232);
  MBSLAM_CHECK_OPTION(!topic.empty());
  MBSLAM_CHECK_OPTION(transport == "shm" || transport == "udp");
  MBSLAM_CHECK_OPTION(transport != "udp" || !interfaces.empty());
  MBSLAM_CHECK_OPTION_GT(history_depth, 0);
  return true;
}

std::string Ros2TopicToDds(const std::string& topic) {
  if (topic.rfind("rt/", 0) == 0) return topic;
  size_t start = 0;
  while (start < topic.size() && topic[start] == '/') ++start;
  return "rt/" + topic.substr(start);
}

int64_t Ros2StampToUtime(int32_t sec, uint32_t nanosec) {
  return static_cast<int64_t>(sec) * kUsecPerSec + (static_cast<int64_t>(nanosec) + 500) / 1000;
}

void UtimeToRos2Stamp(int64_t utime, int32_t* sec, uint32_t* nanosec) {
  int64_t s = utime / kUsecPerSec;
  int64_t us = utime % kUsecPerSec;
  if (us < 0) {
    us += kUsecPerSec;
    --s;
  }
  *sec = static_cast<int32_t>(s);
  *nanosec = static_cast<uint32_t>(us * 1000);
}

Status FromRos2Odometry(const Odometry_& msg, OdometrySample* sample, bool* renormalised) {
  OdometrySample s;
  s.utime = Ros2StampToUtime(msg.header_().stamp_().sec_(), msg.header_().stamp_().nanosec_());
  s.frame_id = msg.header_().frame_id_();
  s.child_frame_id = msg.child_frame_id_();
  const auto& pose = msg.pose_().pose_();
  s.odom_from_base.translation =
      Eigen::Vector3d(pose.position_().x_(), pose.position_().y_(), pose.position_().z_());
  MBSLAM_RETURN_IF_ERROR(OdometryQuaternion(pose.orientation_().x_(), pose.orientation_().y_(),
                                            pose.orientation_().z_(), pose.orientation_().w_(),
                                            &s.odom_from_base.rotation, renormalised));
  const auto& twist = msg.twist_().twist_();
  s.linear_velocity = Eigen::Vector3d(twist.linear_().x_(), twist.linear_().y_(), twist.linear_().z_());
  s.angular_velocity =
      Eigen::Vector3d(twist.angular_().x_(), twist.angular_().y_(), twist.angular_().z_());
  s.pose_covariance = msg.pose_().covariance_();
  s.twist_covariance = msg.twist_().covariance_();
  MBSLAM_RETURN_IF_ERROR(ValidateOdometrySample(s));
  *sample = s;
  return Status::Ok();
}

void ToRos2Odometry(const OdometrySample& s, Odometry_* msg) {
  int32_t sec = 0;
  uint32_t nanosec = 0;
  UtimeToRos2Stamp(s.utime, &sec, &nanosec);
  msg->header_().stamp_().sec_(sec);
  msg->header_().stamp_().nanosec_(nanosec);
  msg->header_().frame_id_(s.frame_id);
  msg->child_frame_id_(s.child_frame_id);
  auto& pose = msg->pose_().pose_();
  pose.position_().x_(s.odom_from_base.translation.x());
  pose.position_().y_(s.odom_from_base.translation.y());
  pose.position_().z_(s.odom_from_base.translation.z());
  pose.orientation_().x_(s.odom_from_base.rotation.x());
  pose.orientation_().y_(s.odom_from_base.rotation.y());
  pose.orientation_().z_(s.odom_from_base.rotation.z());
  pose.orientation_().w_(s.odom_from_base.rotation.w());
  auto& twist = msg->twist_().twist_();
  twist.linear_().x_(s.linear_velocity.x());
  twist.linear_().y_(s.linear_velocity.y());
  twist.linear_().z_(s.linear_velocity.z());
  twist.angular_().x_(s.angular_velocity.x());
  twist.angular_().y_(s.angular_velocity.y());
  twist.angular_().z_(s.angular_velocity.z());
  msg->pose_().covariance_(s.pose_covariance);
  msg->twist_().covariance_(s.twist_covariance);
}

namespace {

Status BuildParticipantQos(const DdsOptions& options, const std::string& name,
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
  qos->transport().user_transports.push_back(udp);
  auto& builtin = qos->wire_protocol().builtin;
  // Unicast discovery only: no multicast locators at all, peers listed explicitly.
  builtin.metatrafficMulticastLocatorList.clear();
  builtin.initialPeersList.clear();
  for (const std::string& peer : options.initial_peers) {
    eprosima::fastrtps::rtps::Locator_t locator;
    locator.kind = LOCATOR_KIND_UDPv4;
    if (!eprosima::fastrtps::rtps::IPLocator::setIPv4(locator, peer)) {
      return Status::Error("dds.initial_peers: '" + peer + "' is not an IPv4 address");
    }
    builtin.initialPeersList.push_back(locator);
  }
  eprosima::fastrtps::rtps::Locator_t meta;
  meta.kind = LOCATOR_KIND_UDPv4;
  if (!eprosima::fastrtps::rtps::IPLocator::setIPv4(meta, options.interfaces.front())) {
    return Status::Error("dds.interfaces: '" + options.interfaces.front() + "' is not an IPv4 address");
  }
  builtin.metatrafficUnicastLocatorList.clear();
  builtin.metatrafficUnicastLocatorList.push_back(meta);  // port 0: the well-known port
  qos->wire_protocol().default_unicast_locator_list.clear();
  qos->wire_protocol().default_unicast_locator_list.push_back(meta);
  qos->wire_protocol().default_multicast_locator_list.clear();
  return Status::Ok();
}

// Participant, registered type and topic, shared by reader and writer.
struct DdsEndpointBase {
  dds::DomainParticipant* participant = nullptr;
  dds::TypeSupport type{new Odometry_PubSubType()};
  dds::Topic* topic = nullptr;
  std::string topic_name;

  Status Init(const DdsOptions& options, const std::string& name) {
    if (!options.Check()) return Status::Error("dds options: " + LastOptionError());
    dds::DomainParticipantQos qos;
    MBSLAM_RETURN_IF_ERROR(BuildParticipantQos(options, name, &qos));
    participant = dds::DomainParticipantFactory::get_instance()->create_participant(
        static_cast<dds::DomainId_t>(options.domain_id), qos);
    if (participant == nullptr) {
      return Status::Error("Fast DDS: cannot create a participant in domain " +
                           std::to_string(options.domain_id) + " (" + options.transport + ")");
    }
    if (type.register_type(participant) != ReturnCode_t::RETCODE_OK) {
      return Status::Error("Fast DDS: cannot register " + type.get_type_name());
    }
    topic_name = Ros2TopicToDds(options.topic);
    topic = participant->create_topic(topic_name, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    if (topic == nullptr) return Status::Error("Fast DDS: cannot create topic " + topic_name);
    return Status::Ok();
  }

  void DeleteParticipant() {
    if (participant == nullptr) return;
    participant->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant);
    participant = nullptr;
  }
};

}  // namespace

struct DdsOdometryReader::Impl : public dds::DataReaderListener {
  DdsEndpointBase base;
  dds::Subscriber* subscriber = nullptr;
  dds::DataReader* reader = nullptr;
  BoundedQueue<OdometrySample> queue{10000, QueueFullPolicy::kDropOldest};
  std::atomic<int64_t> received{0}, rejected{0}, renormalised{0};
  std::atomic<int> matched{0};
  mutable std::mutex mutex;
  std::string last_rejection;
  int64_t next_seq = 0;
  std::string description;

  void on_data_available(dds::DataReader* r) override {
    Odometry_ msg;
    dds::SampleInfo info;
    while (r->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      ++received;
      OdometrySample sample;
      bool renorm = false;
      const Status st = FromRos2Odometry(msg, &sample, &renorm);
      if (!st.ok()) {
        ++rejected;
        std::lock_guard<std::mutex> lock(mutex);
        last_rejection = st.message();
        continue;
      }
      if (renorm) ++renormalised;
      sample.seq = next_seq++;
      queue.Push(std::move(sample));
    }
  }
  void on_subscription_matched(dds::DataReader*, const dds::SubscriptionMatchedStatus& status) override {
    matched = status.current_count;
  }
  ~Impl() override {
    queue.Shutdown();
    base.DeleteParticipant();
  }
};

DdsOdometryReader::DdsOdometryReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
DdsOdometryReader::~DdsOdometryReader() = default;

std::unique_ptr<DdsOdometryReader> DdsOdometryReader::Create(const DdsOptions& options,
                                                             Status* status) {
  auto impl = std::make_unique<Impl>();
  *status = impl->base.Init(options, "mbslam_odometry_bridge");
  if (!status->ok()) return nullptr;
  impl->subscriber = impl->base.participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (impl->subscriber == nullptr) {
    *status = Status::Error("Fast DDS: cannot create a subscriber");
    return nullptr;
  }
  dds::DataReaderQos qos = dds::DATAREADER_QOS_DEFAULT;
  qos.reliability().kind =
      options.reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = options.history_depth;
  impl->reader = impl->subscriber->create_datareader(impl->base.topic, qos, impl.get());
  if (impl->reader == nullptr) {
    *status = Status::Error("Fast DDS: cannot create a reader on " + impl->base.topic_name);
    return nullptr;
  }
  impl->description = "ROS 2 " + impl->base.type.get_type_name() + " on " + impl->base.topic_name +
                      " (domain " + std::to_string(options.domain_id) + ", " + options.transport +
                      (options.reliable ? ", reliable" : ", best effort") + ")";
  return std::unique_ptr<DdsOdometryReader>(new DdsOdometryReader(std::move(impl)));
}

bool DdsOdometryReader::Pop(OdometrySample* sample, int64_t timeout_us) {
  std::optional<OdometrySample> s = impl_->queue.PopFor(timeout_us);
  if (!s) return false;
  *sample = std::move(*s);
  return true;
}

int64_t DdsOdometryReader::received() const { return impl_->received; }
int64_t DdsOdometryReader::rejected() const { return impl_->rejected; }
int64_t DdsOdometryReader::renormalised() const { return impl_->renormalised; }
int64_t DdsOdometryReader::dropped() const { return static_cast<int64_t>(impl_->queue.dropped()); }
int DdsOdometryReader::matched_writers() const { return impl_->matched; }
std::string DdsOdometryReader::last_rejection() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->last_rejection;
}
std::string DdsOdometryReader::description() const { return impl_->description; }

struct DdsOdometryWriter::Impl : public dds::DataWriterListener {
  DdsEndpointBase base;
  dds::Publisher* publisher = nullptr;
  dds::DataWriter* writer = nullptr;
  std::atomic<int> matched{0};

  void on_publication_matched(dds::DataWriter*, const dds::PublicationMatchedStatus& status) override {
    matched = status.current_count;
  }
  ~Impl() override { base.DeleteParticipant(); }
};

DdsOdometryWriter::DdsOdometryWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
DdsOdometryWriter::~DdsOdometryWriter() = default;

std::unique_ptr<DdsOdometryWriter> DdsOdometryWriter::Create(const DdsOptions& options,
                                                             Status* status) {
  auto impl = std::make_unique<Impl>();
  *status = impl->base.Init(options, "mbslam_ros2_odometry_publisher");
  if (!status->ok()) return nullptr;
  impl->publisher = impl->base.participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  if (impl->publisher == nullptr) {
    *status = Status::Error("Fast DDS: cannot create a publisher");
    return nullptr;
  }
  dds::DataWriterQos qos = dds::DATAWRITER_QOS_DEFAULT;
  qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  qos.history().kind = dds::KEEP_ALL_HISTORY_QOS;
  impl->writer = impl->publisher->create_datawriter(impl->base.topic, qos, impl.get());
  if (impl->writer == nullptr) {
    *status = Status::Error("Fast DDS: cannot create a writer on " + impl->base.topic_name);
    return nullptr;
  }
  return std::unique_ptr<DdsOdometryWriter>(new DdsOdometryWriter(std::move(impl)));
}

bool DdsOdometryWriter::WaitForReaders(int count, int64_t timeout_us) {
  const int64_t deadline = MonotonicUtime() + timeout_us;
  while (impl_->matched < count) {
    if (MonotonicUtime() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

Status DdsOdometryWriter::Write(const OdometrySample& sample) {
  Odometry_ msg;
  ToRos2Odometry(sample, &msg);
  if (!impl_->writer->write(&msg)) return Status::Error("Fast DDS: write failed");
  return Status::Ok();
}

bool DdsOdometryWriter::WaitForAcknowledgments(int64_t timeout_us) {
  eprosima::fastrtps::Duration_t timeout(static_cast<int32_t>(timeout_us / kUsecPerSec),
                                         static_cast<uint32_t>((timeout_us % kUsecPerSec) * 1000));
  return impl_->writer->wait_for_acknowledgments(timeout) == ReturnCode_t::RETCODE_OK;
}

}  // namespace mbslam
