#include "drivers/dds_output_bridge/ros2_perception_test_reader.h"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

#include "common/util/time.h"
#include "drivers/dds_output_bridge/dds_participant.h"
#include "geometry_msgs/msg/dds_/PoseArray_PubSubTypes.h"
#include "geometry_msgs/msg/dds_/PoseStamped_PubSubTypes.h"
#include "visualization_msgs/msg/dds_/MarkerArray_PubSubTypes.h"

namespace mbslam {

namespace dds = eprosima::fastdds::dds;

namespace {

template <typename Msg, typename PubSubType>
struct TopicReader : public dds::DataReaderListener {
  dds::TypeSupport type{new PubSubType()};
  dds::DataReader* reader = nullptr;
  std::atomic<int> matched{0};
  mutable std::mutex mutex;
  std::vector<Msg> samples;

  bool enabled() const { return reader != nullptr; }

  void on_data_available(dds::DataReader* r) override {
    Msg msg;
    dds::SampleInfo info;
    while (r->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      std::lock_guard<std::mutex> lock(mutex);
      samples.push_back(msg);
    }
  }
  void on_subscription_matched(dds::DataReader*,
                               const dds::SubscriptionMatchedStatus& status) override {
    matched = status.current_count;
  }

  Status Create(dds::DomainParticipant* participant, dds::Subscriber* subscriber,
                const std::string& name) {
    if (name.empty()) return Status::Ok();
    if (type.register_type(participant) != ReturnCode_t::RETCODE_OK) {
      return Status::Error("Fast DDS: cannot register " + type.get_type_name());
    }
    dds::Topic* topic =
        participant->create_topic(name, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    if (topic == nullptr) return Status::Error("Fast DDS: cannot create topic " + name);
    dds::DataReaderQos qos = dds::DATAREADER_QOS_DEFAULT;
    qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
    qos.history().kind = dds::KEEP_ALL_HISTORY_QOS;
    reader = subscriber->create_datareader(topic, qos, this);
    if (reader == nullptr) return Status::Error("Fast DDS: cannot create a reader on " + name);
    return Status::Ok();
  }

  size_t count() const {
    std::lock_guard<std::mutex> lock(mutex);
    return samples.size();
  }
  std::vector<Msg> copy() const {
    std::lock_guard<std::mutex> lock(mutex);
    return samples;
  }
};

}  // namespace

struct Ros2PerceptionTestReader::Impl {
  dds::DomainParticipant* participant = nullptr;
  dds::Subscriber* subscriber = nullptr;
  TopicReader<geometry_msgs::msg::dds_::PoseStamped_,
              geometry_msgs::msg::dds_::PoseStamped_PubSubType>
      camera_pose;
  TopicReader<visualization_msgs::msg::dds_::MarkerArray_,
              visualization_msgs::msg::dds_::MarkerArray_PubSubType>
      objects;
  TopicReader<geometry_msgs::msg::dds_::PoseArray_, geometry_msgs::msg::dds_::PoseArray_PubSubType>
      object_poses;

  ~Impl() { DeleteDdsParticipant(participant); }

  int min_matched() const {
    int n = -1;
    const int counts[] = {camera_pose.enabled() ? camera_pose.matched.load() : -1,
                          objects.enabled() ? objects.matched.load() : -1,
                          object_poses.enabled() ? object_poses.matched.load() : -1};
    for (int c : counts) {
      if (c >= 0) n = n < 0 ? c : std::min(n, c);
    }
    return std::max(n, 0);
  }
};

Ros2PerceptionTestReader::Ros2PerceptionTestReader(std::unique_ptr<Impl> impl)
    : impl_(std::move(impl)) {}
Ros2PerceptionTestReader::~Ros2PerceptionTestReader() = default;

std::unique_ptr<Ros2PerceptionTestReader> Ros2PerceptionTestReader::Create(
    const DdsOutputOptions& dds_options, const Ros2TopicOptions& topics, Status* status) {
  auto impl = std::make_unique<Impl>();
  *status =
      CreateDdsParticipant(dds_options, "mbslam_ros2_perception_test_reader", &impl->participant);
  if (!status->ok()) return nullptr;
  impl->subscriber = impl->participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (impl->subscriber == nullptr) {
    *status = Status::Error("Fast DDS: cannot create a subscriber");
    return nullptr;
  }
  *status = impl->camera_pose.Create(impl->participant, impl->subscriber,
                                     Ros2DdsTopicName(topics.prefix, topics.camera_pose));
  if (status->ok()) {
    *status = impl->objects.Create(impl->participant, impl->subscriber,
                                   Ros2DdsTopicName(topics.prefix, topics.objects));
  }
  if (status->ok()) {
    *status = impl->object_poses.Create(impl->participant, impl->subscriber,
                                        Ros2DdsTopicName(topics.prefix, topics.object_poses));
  }
  if (!status->ok()) return nullptr;
  return std::unique_ptr<Ros2PerceptionTestReader>(new Ros2PerceptionTestReader(std::move(impl)));
}

bool Ros2PerceptionTestReader::WaitForWriters(int count, int64_t timeout_us) const {
  const int64_t deadline = MonotonicUtime() + timeout_us;
  while (impl_->min_matched() < count) {
    if (MonotonicUtime() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

bool Ros2PerceptionTestReader::WaitForSamples(size_t camera_poses, size_t objects,
                                              size_t object_poses, int64_t timeout_us) const {
  const int64_t deadline = MonotonicUtime() + timeout_us;
  while (impl_->camera_pose.count() < camera_poses || impl_->objects.count() < objects ||
         impl_->object_poses.count() < object_poses) {
    if (MonotonicUtime() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

std::vector<geometry_msgs::msg::dds_::PoseStamped_> Ros2PerceptionTestReader::camera_poses() const {
  return impl_->camera_pose.copy();
}
std::vector<visualization_msgs::msg::dds_::MarkerArray_> Ros2PerceptionTestReader::objects() const {
  return impl_->objects.copy();
}
std::vector<geometry_msgs::msg::dds_::PoseArray_> Ros2PerceptionTestReader::object_poses() const {
  return impl_->object_poses.copy();
}

std::string Ros2PerceptionTestReader::type_names() const {
  return impl_->camera_pose.type.get_type_name() + " " + impl_->objects.type.get_type_name() + " " +
         impl_->object_poses.type.get_type_name();
}

}  // namespace mbslam
