#include "dds/bus.h"

#include <iterator>
#include <stdexcept>

namespace costar::dds {
namespace {

struct TopicInfo {
  const char* name;
  const dds_topic_descriptor_t* descriptor;
  bool durable;
  /// Only the newest sample counts (the clock).
  bool latest_only = false;
};

const TopicInfo& info(Topic topic) {
  static const TopicInfo kTopics[] = {
      {"rq/costar/operation/_action/send_goalRequest", &costar_msgs_action_dds__Operation_SendGoal_Request__desc,
       false},
      {"rr/costar/operation/_action/send_goalReply", &costar_msgs_action_dds__Operation_SendGoal_Response__desc, false},
      {"rq/costar/operation/_action/cancel_goalRequest", &costar_msgs_action_dds__Operation_CancelGoal_Request__desc,
       false},
      {"rt/costar/operation/_action/feedback", &costar_msgs_action_dds__Operation_Status__desc, false},
      {"rt/costar/operation/_action/result", &costar_msgs_action_dds__Operation_Status__desc, false},
      {"rt/costar/component_description", &costar_msgs_msg_dds__ComponentDescription__desc, true},
      {"rt/costar/component_report", &costar_msgs_msg_dds__ComponentReport__desc, true},
      {"rt/costar/host_heartbeat", &costar_msgs_msg_dds__HostHeartbeat__desc, false},
      {"rq/costar/component/callRequest", &costar_msgs_srv_dds__Call_Request__desc, false},
      {"rr/costar/component/callReply", &costar_msgs_srv_dds__Call_Response__desc, false},
      {"rq/costar/sim/driverRequest", &costar_msgs_srv_dds__Call_Request__desc, false},
      {"rr/costar/sim/driverReply", &costar_msgs_srv_dds__Call_Response__desc, false},
      {"rt/clock", &rosgraph_msgs_msg_dds__Clock__desc, false, true},
      {"rt/joint_states", &sensor_msgs_msg_dds__JointState__desc, false, true},
      {"rt/wrench", &geometry_msgs_msg_dds__WrenchStamped__desc, false, true},
      {"rt/camera/color/image_raw", &sensor_msgs_msg_dds__Image__desc, false, true},
      {"rt/camera/depth/image_raw", &sensor_msgs_msg_dds__Image__desc, false, true},
  };
  static_assert(std::size(kTopics) == kTopicCount);
  return kTopics[static_cast<int>(topic)];
}

dds_entity_t check(dds_entity_t entity, const std::string& what) {
  if (entity < 0) {
    throw std::runtime_error("DDS: cannot create " + what + ": " + dds_strretcode(entity));
  }
  return entity;
}

/// Reliable; durable topics keep the last sample per key (a component's description and
/// report), the others keep everything until it is delivered (goals, results).
dds_qos_t* topicQos(const TopicInfo& topic) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
  if (topic.durable) {
    dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  } else if (topic.latest_only) {
    // The newest only, kept for a reader that joins later (a host that starts mid-run).
    dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  } else {
    dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
  }
  return qos;
}

}  // namespace

const char* topicName(Topic topic) { return info(topic).name; }

Bus::Bus(const RemoteConfig& config) : config_(config) {
  // The interface is fixed when the domain is created: loopback with multicast on it, or the
  // named interface. A second Bus in the same process and domain uses the domain as it is.
  const bool loopback = config.network_interface == "lo";
  std::string xml = "<General><Interfaces><NetworkInterface name=\"" + config.network_interface + "\" multicast=\"" +
                    (loopback ? "true" : "default") + "\"/></Interfaces>";
  if (loopback) {
    // Loopback carries 64 kB datagrams: a camera frame (4.6 MB) crosses in 71 pieces instead
    // of 3,400 (DDS's default fragment is 1,344 bytes, for an Ethernet network's packets).
    xml += "<MaxMessageSize>65500B</MaxMessageSize><FragmentSize>65000B</FragmentSize>";
  }
  // A socket buffer that holds a frame's pieces as they arrive (up to what the system allows),
  // and a writer whose unacknowledged data may reach 64 MiB before a write waits: replies go to
  // every host through one writer, and a frame that a killed host never acknowledges would
  // otherwise hold up the replies to the live ones for a second (the default starts at 30 kB),
  // until DDS's own lease of the dead host ends.
  xml +=
      "</General><Internal><SocketReceiveBufferSize min=\"default\" max=\"4MiB\"/><Watermarks>"
      "<WhcHigh>64MiB</WhcHigh><WhcHighInit>64MiB</WhcHighInit><WhcAdaptive>false</WhcAdaptive></Watermarks>"
      "</Internal>";
  const dds_entity_t domain = dds_create_domain(config.domain, xml.c_str());
  if (domain < 0 && domain != DDS_RETCODE_PRECONDITION_NOT_MET) {
    throw std::runtime_error("DDS: cannot join domain " + std::to_string(config.domain) + " on interface '" +
                             config.network_interface + "': " + dds_strretcode(domain));
  }
  participant_ = check(dds_create_participant(config.domain, nullptr, nullptr),
                       "a participant in domain " + std::to_string(config.domain));
  dds_qos_t* qos = dds_create_qos();
  dds_qset_partition1(qos, config.partition.c_str());
  publisher_ = dds_create_publisher(participant_, qos, nullptr);
  subscriber_ = dds_create_subscriber(participant_, qos, nullptr);
  dds_delete_qos(qos);
  if (publisher_ < 0 || subscriber_ < 0) {
    dds_delete(participant_);
    throw std::runtime_error("DDS: cannot use partition '" + config.partition + "'");
  }
}

Bus::~Bus() { dds_delete(participant_); }

dds_entity_t Bus::topic(Topic which) {
  dds_entity_t& slot = topics_[static_cast<int>(which)];
  if (slot == 0) {
    const TopicInfo& topic = info(which);
    dds_qos_t* qos = topicQos(topic);
    slot = dds_create_topic(participant_, topic.descriptor, topic.name, qos, nullptr);
    dds_delete_qos(qos);
    check(slot, std::string("topic ") + topic.name);
  }
  return slot;
}

dds_entity_t Bus::writer(Topic which) {
  dds_qos_t* qos = topicQos(info(which));
  const dds_entity_t writer = dds_create_writer(publisher_, topic(which), qos, nullptr);
  dds_delete_qos(qos);
  return check(writer, std::string("a writer of ") + topicName(which));
}

dds_entity_t Bus::reader(Topic which, const dds_listener_t* listener) {
  dds_qos_t* qos = topicQos(info(which));
  const dds_entity_t reader = dds_create_reader(subscriber_, topic(which), qos, listener);
  dds_delete_qos(qos);
  return check(reader, std::string("a reader of ") + topicName(which));
}

void Bus::write(dds_entity_t writer, const void* sample) {
  const dds_return_t rc = dds_write(writer, sample);
  if (rc != DDS_RETCODE_OK) {
    throw std::runtime_error(std::string("DDS: write failed: ") + dds_strretcode(rc));
  }
}

}  // namespace costar::dds
