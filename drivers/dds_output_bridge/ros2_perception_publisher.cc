#include "drivers/dds_output_bridge/ros2_perception_publisher.h"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <thread>

#include "common/util/time.h"
#include "drivers/dds_output_bridge/dds_participant.h"
#include "geometry_msgs/msg/dds_/PoseArray_PubSubTypes.h"
#include "geometry_msgs/msg/dds_/PoseStamped_PubSubTypes.h"
#include "visualization_msgs/msg/dds_/MarkerArray_PubSubTypes.h"

namespace mbslam {

namespace dds = eprosima::fastdds::dds;

namespace {

// One topic: its registered type, the writer and its match count.
struct TopicWriter : public dds::DataWriterListener {
  explicit TopicWriter(eprosima::fastdds::dds::TopicDataType* type_support) : type(type_support) {}

  dds::TypeSupport type;
  std::string topic_name;  // "" = disabled
  dds::DataWriter* writer = nullptr;
  std::atomic<int> matched{0};

  bool enabled() const { return writer != nullptr; }
  void on_publication_matched(dds::DataWriter*,
                              const dds::PublicationMatchedStatus& status) override {
    matched = status.current_count;
  }

  Status Create(dds::DomainParticipant* participant, dds::Publisher* publisher,
                const std::string& name, const dds::DataWriterQos& qos) {
    topic_name = name;
    if (name.empty()) return Status::Ok();
    if (type.register_type(participant) != ReturnCode_t::RETCODE_OK) {
      return Status::Error("Fast DDS: cannot register " + type.get_type_name());
    }
    dds::Topic* topic =
        participant->create_topic(name, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    if (topic == nullptr) return Status::Error("Fast DDS: cannot create topic " + name);
    writer = publisher->create_datawriter(topic, qos, this);
    if (writer == nullptr) return Status::Error("Fast DDS: cannot create a writer on " + name);
    return Status::Ok();
  }

  Status Write(const void* sample) {
    if (!enabled()) return Status::Error("Fast DDS: no writer (topic disabled)");
    if (!writer->write(const_cast<void*>(sample)))
      return Status::Error("Fast DDS: write on " + topic_name + " failed");
    return Status::Ok();
  }
};

}  // namespace

struct Ros2PerceptionPublisher::Impl {
  dds::DomainParticipant* participant = nullptr;
  dds::Publisher* publisher = nullptr;
  TopicWriter camera_pose{new geometry_msgs::msg::dds_::PoseStamped_PubSubType()};
  TopicWriter objects{new visualization_msgs::msg::dds_::MarkerArray_PubSubType()};
  TopicWriter object_poses{new geometry_msgs::msg::dds_::PoseArray_PubSubType()};
  std::string description;

  // Deleting the participant deletes the writers before their listeners go.
  ~Impl() { DeleteDdsParticipant(participant); }

  template <typename F>
  void ForEachEnabled(F f) {
    for (TopicWriter* w : {&camera_pose, &objects, &object_poses}) {
      if (w->enabled()) f(*w);
    }
  }
};

Ros2PerceptionPublisher::Ros2PerceptionPublisher(std::unique_ptr<Impl> impl)
    : impl_(std::move(impl)) {}
Ros2PerceptionPublisher::~Ros2PerceptionPublisher() = default;

std::unique_ptr<Ros2PerceptionPublisher> Ros2PerceptionPublisher::Create(
    const DdsOutputOptions& dds_options, const Ros2TopicOptions& topics, Status* status) {
  if (!topics.Check()) {
    *status = Status::Error("topics: " + LastOptionError());
    return nullptr;
  }
  auto impl = std::make_unique<Impl>();
  *status = CreateDdsParticipant(dds_options, "mbslam_perception_dds_bridge", &impl->participant);
  if (!status->ok()) return nullptr;
  impl->publisher = impl->participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  if (impl->publisher == nullptr) {
    *status = Status::Error("Fast DDS: cannot create a publisher");
    return nullptr;
  }
  dds::DataWriterQos qos = dds::DATAWRITER_QOS_DEFAULT;
  qos.reliability().kind =
      dds_options.reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  qos.durability().kind = dds_options.transient_local ? dds::TRANSIENT_LOCAL_DURABILITY_QOS
                                                      : dds::VOLATILE_DURABILITY_QOS;
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = dds_options.history_depth;
  // Readers acknowledge on heartbeats: Fast DDS's default period (3 s) would make the
  // acknowledgment wait at exit as long; 0.1 s costs nothing on loopback.
  qos.reliable_writer_qos().times.heartbeatPeriod = eprosima::fastrtps::Duration_t(0, 100000000);
  const std::pair<TopicWriter*, std::string> writers[] = {
      {&impl->camera_pose, Ros2DdsTopicName(topics.prefix, topics.camera_pose)},
      {&impl->objects, Ros2DdsTopicName(topics.prefix, topics.objects)},
      {&impl->object_poses, Ros2DdsTopicName(topics.prefix, topics.object_poses)}};
  for (const auto& [writer, name] : writers) {
    *status = writer->Create(impl->participant, impl->publisher, name, qos);
    if (!status->ok()) return nullptr;
  }
  std::string d;
  impl->ForEachEnabled([&d](TopicWriter& w) {
    d += (d.empty() ? "" : ", ") + w.topic_name + " (" + w.type.get_type_name() + ")";
  });
  impl->description = d + "; domain " + std::to_string(dds_options.domain_id) + ", " +
                      dds_options.transport +
                      (dds_options.reliable ? ", reliable" : ", best effort") +
                      (dds_options.transient_local ? ", transient local" : ", volatile");
  return std::unique_ptr<Ros2PerceptionPublisher>(new Ros2PerceptionPublisher(std::move(impl)));
}

bool Ros2PerceptionPublisher::publishes_camera_pose() const { return impl_->camera_pose.enabled(); }
bool Ros2PerceptionPublisher::publishes_objects() const { return impl_->objects.enabled(); }
bool Ros2PerceptionPublisher::publishes_object_poses() const {
  return impl_->object_poses.enabled();
}

Status Ros2PerceptionPublisher::Publish(const geometry_msgs::msg::dds_::PoseStamped_& camera_pose) {
  return impl_->camera_pose.Write(&camera_pose);
}
Status Ros2PerceptionPublisher::Publish(
    const visualization_msgs::msg::dds_::MarkerArray_& objects) {
  return impl_->objects.Write(&objects);
}
Status Ros2PerceptionPublisher::Publish(const geometry_msgs::msg::dds_::PoseArray_& object_poses) {
  return impl_->object_poses.Write(&object_poses);
}

int Ros2PerceptionPublisher::min_matched_readers() const {
  int n = -1;
  impl_->ForEachEnabled(
      [&n](TopicWriter& w) { n = n < 0 ? w.matched.load() : std::min(n, w.matched.load()); });
  return std::max(n, 0);
}

bool Ros2PerceptionPublisher::WaitForReaders(int count, int64_t timeout_us) const {
  const int64_t deadline = MonotonicUtime() + timeout_us;
  while (min_matched_readers() < count) {
    if (MonotonicUtime() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

bool Ros2PerceptionPublisher::WaitForAcknowledgments(int64_t timeout_us) {
  const int64_t deadline = MonotonicUtime() + timeout_us;
  bool all = true;
  impl_->ForEachEnabled([&](TopicWriter& w) {
    const int64_t left = std::max<int64_t>(deadline - MonotonicUtime(), 0);
    const eprosima::fastrtps::Duration_t timeout(
        static_cast<int32_t>(left / kUsecPerSec),
        static_cast<uint32_t>((left % kUsecPerSec) * 1000));
    if (w.writer->wait_for_acknowledgments(timeout) != ReturnCode_t::RETCODE_OK) all = false;
  });
  return all;
}

std::string Ros2PerceptionPublisher::description() const { return impl_->description; }

}  // namespace mbslam
