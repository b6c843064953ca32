#include "dds/remote_component.h"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <condition_variable>
#include <cstdio>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <stdexcept>

#include "component/description.h"
#include "dds/bus.h"
#include "dds/report_json.h"

namespace costar::dds {
namespace {

using SteadyClock = std::chrono::steady_clock;

/// A goal that a live host has not answered in this long is given up.
constexpr std::chrono::seconds kAnswerTimeout{2};

std::uint64_t randomId() {
  std::random_device device;
  return (static_cast<std::uint64_t>(device()) << 32U) ^ device() ^ static_cast<std::uint64_t>(::getpid());
}

std::string seconds(SteadyClock::duration duration) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.2f", std::chrono::duration<double>(duration).count());
  return text;
}

}  // namespace

struct RemoteClient::State {
  struct Host {
    std::int32_t pid = 0;
    std::string hostname;
    std::vector<std::string> components;  // what it serves, from its heartbeat
    SteadyClock::time_point heard;
  };
  struct Served {
    std::string description_json;
    std::uint64_t host_id = 0;
    world::Report report;
    std::uint64_t report_host = 0;  // the host that sent the report held, and its count
    std::uint64_t report_number = 0;
    std::string report_error;
  };
  struct Goal {
    std::string component;
    std::string operation;
    std::uint64_t host_id = 0;
    bool answered = false;
    bool ended = false;
    component::OperationResult latest;
    /// The report the latest state needs (shown once the component's report has it).
    std::uint64_t report_number = 0;
    SteadyClock::time_point sent;
  };

  explicit State(const RemoteConfig& remote) : config(remote), bus(remote) {}

  RemoteConfig config;
  Bus bus;
  std::uint64_t client_id = randomId();
  dds_entity_t goal_writer = 0, cancel_writer = 0;

  mutable std::mutex mutex;
  std::condition_variable heard;
  std::map<std::uint64_t, Host> hosts;
  std::map<std::string, Served, std::less<>> served;
  std::map<component::OperationId, Goal> goals;
  std::set<component::OperationId> cancelling;
  std::set<component::OperationId> cancel_confirmed;
  component::OperationId next_goal = 1;

  // Lockstep (config.lockstep), used from the executor's thread only.
  dds_entity_t call_writer = 0, call_reply_reader = 0, driver_request_reader = 0, driver_reply_writer = 0;
  dds_entity_t clock_writer = 0, joint_state_writer = 0, wrench_writer = 0, waitset = 0;
  dds_entity_t color_image_writer = 0, depth_image_writer = 0;
  DriverServer driver_server;
  std::set<DriverReading> readings;  // answered ahead (dds/lockstep.h)
  std::int64_t clock_ns = 0;
  std::uint64_t calls = 0;
  /// A driver call a host made: driver, method, its arguments as the host wrote them.
  struct DriverCall {
    std::string driver, method, args_json;
  };
  /// The driver calls the last call of each component's method made, in order ("gripper/report").
  std::map<std::string, std::vector<DriverCall>, std::less<>> asked;
  std::vector<DriverCall>* recording = nullptr;  // the present call's, while it waits
  /// The reports of a host's components, asked together by the first of them asked at a time:
  /// the others' are used while the clock and the calls stand where they were.
  struct Reports {
    std::int64_t clock_ns = -1;
    std::uint64_t after_call = 0;
    nlohmann::json by_component;
  };
  std::map<std::uint64_t, Reports> reports;  // by host

  /// The leading readings of `last`, answered now (at the call's simulated time), as the
  /// call's prepared_json; what was answered is appended to `answered`.
  std::string answerAhead(const std::vector<DriverCall>& last, std::vector<DriverCall>& answered) {
    nlohmann::json prepared = nlohmann::json::array();
    for (const DriverCall& call : last) {
      if (!driver_server || !readings.contains({call.driver, call.method})) {
        break;
      }
      nlohmann::json answer = {{"driver", call.driver}, {"method", call.method}, {"args", call.args_json}};
      try {
        DriverReply reply = driver_server(call.driver, call.method, nlohmann::json::parse(call.args_json));
        if (!reply.floats.empty() || !reply.bytes.empty()) {
          break;  // a frame travels as the answer to its own call
        }
        answer["result"] = std::move(reply.result);
      } catch (const std::exception& failure) {
        answer["error"] = failure.what();
      }
      prepared.push_back(std::move(answer));
      answered.push_back(call);
    }
    return prepared.empty() ? std::string() : prepared.dump();
  }

  /// Answers the driver calls of hosts to this executor.
  void serveDrivers() {
    Bus::takeAll<costar_msgs_srv_dds__Call_Request_>(
        driver_request_reader, [this](const costar_msgs_srv_dds__Call_Request_& request) {
          if (request.client != client_id) {
            return;
          }
          if (recording != nullptr) {
            recording->push_back({request.target, request.method, request.args_json});
          }
          DriverReply reply;
          std::string error;
          try {
            if (!driver_server) {
              throw std::runtime_error("this executor has no simulator to call");
            }
            reply = driver_server(request.target, request.method, nlohmann::json::parse(request.args_json));
          } catch (const std::exception& failure) {
            error = failure.what();
          }
          const std::string result = reply.result.dump();
          costar_msgs_srv_dds__Call_Response_ message{};
          message.client = request.client;
          message.host_id = request.host_id;
          message.number = request.number;
          message.ok = error.empty();
          message.error = wire(error);
          message.result_json = wire(result);
          message.floats._buffer = reply.floats.data();
          message.floats._length = message.floats._maximum = static_cast<std::uint32_t>(reply.floats.size());
          message.floats._release = false;
          message.bytes._buffer = reply.bytes.data();
          message.bytes._length = message.bytes._maximum = static_cast<std::uint32_t>(reply.bytes.size());
          message.bytes._release = false;
          // A reply that cannot be sent is the asking host's loss (its call times out and its
          // heartbeat tells whether it lives), never a failure of the component this executor
          // is calling now, which may be another host's.
          if (const dds_return_t rc = dds_write(driver_reply_writer, &message); rc != DDS_RETCODE_OK) {
            spdlog::warn("the reply to {} {} of host {:x} could not be sent: {}", request.target, request.method,
                         request.host_id, dds_strretcode(rc));
          }
        });
  }

  /// Calls `method` of `component` on its host and waits for the answer, serving the hosts'
  /// driver calls meanwhile. @throws std::runtime_error with the host's error, or naming the
  /// component when its host is lost.
  nlohmann::json call(const std::string& component, const std::string& method, const nlohmann::json& args) {
    std::uint64_t host_id = 0;
    {
      std::lock_guard lock(mutex);
      const auto served_by = served.find(component);
      host_id = served_by == served.end() ? 0 : served_by->second.host_id;
      if (std::string reason = lost(component, host_id, SteadyClock::now()); !reason.empty()) {
        throw std::runtime_error(reason);
      }
    }
    const std::uint64_t number = ++calls;
    const std::string args_json = args.dump();
    const std::string key = component + "/" + method;
    std::vector<DriverCall> answered;
    const std::string prepared_json = answerAhead(asked[key], answered);
    costar_msgs_srv_dds__Call_Request_ request{};
    request.client = client_id;
    request.host_id = host_id;
    request.number = number;
    request.target = wire(component);
    request.method = wire(method);
    request.args_json = wire(args_json);
    request.stamp_ns = clock_ns;
    request.prepared_json = wire(prepared_json);
    Bus::write(call_writer, &request);
    std::vector<DriverCall> made;  // the host's driver calls during this one, after those it used
    recording = &made;
    struct StopRecording {
      std::vector<DriverCall>*& recording;
      ~StopRecording() { recording = nullptr; }
    } stop_recording{recording};
    for (;;) {
      std::optional<nlohmann::json> result;
      std::string error;
      std::uint32_t used = 0;
      Bus::takeAll<costar_msgs_srv_dds__Call_Response_>(call_reply_reader,
                                                        [&](const costar_msgs_srv_dds__Call_Response_& reply) {
                                                          if (reply.client != client_id || reply.number != number) {
                                                            return;  // another executor's, or one given up on
                                                          }
                                                          used = reply.prepared_used;
                                                          if (reply.ok) {
                                                            result = nlohmann::json::parse(reply.result_json);
                                                          } else {
                                                            error = reply.error;
                                                            result = nullptr;
                                                          }
                                                        });
      if (result) {
        // What this call asked, for the next one: the readings it used, then the calls it made.
        answered.resize(std::min<std::size_t>(used, answered.size()));
        answered.insert(answered.end(), made.begin(), made.end());
        asked[key] = std::move(answered);
        if (!error.empty()) {
          throw std::runtime_error(error);
        }
        return std::move(*result);
      }
      serveDrivers();
      {
        std::lock_guard lock(mutex);
        if (std::string reason = lost(component, host_id, SteadyClock::now()); !reason.empty()) {
          throw std::runtime_error(reason);
        }
      }
      dds_waitset_wait(waitset, nullptr, 0, DDS_MSECS(20));
    }
  }

  /// Why `component`'s host `host_id` counts as gone, or empty while it answers. Under `mutex`.
  std::string lost(const std::string& component, std::uint64_t host_id, SteadyClock::time_point now) const {
    const auto host = hosts.find(host_id);
    if (host == hosts.end()) {
      return "component '" + component + "' has no host: none was heard on DDS domain " +
             std::to_string(config.domain) + ", partition '" + config.partition + "'";
    }
    if (now - host->second.heard > kHostTimeout) {
      // The host's other components went with it: named too, so that a reason given by the
      // first of them the executor calls still names the one whose operation was running.
      std::string others;
      for (const std::string& name : host->second.components) {
        if (name != component) {
          others += (others.empty() ? "" : ", ") + ("'" + name + "'");
        }
      }
      return "component '" + component + "' stopped answering: its host (pid " + std::to_string(host->second.pid) +
             " on " + host->second.hostname + (others.empty() ? "" : ", which also served " + others) +
             ") has sent nothing for " + seconds(now - host->second.heard) + " s";
    }
    return {};
  }

  // The listeners, on DDS's receive thread.
  void onReply(const costar_msgs_action_dds__Operation_SendGoal_Response_& reply) {
    if (reply.goal_id.client != client_id) {
      return;
    }
    std::lock_guard lock(mutex);
    const auto goal = goals.find(reply.goal_id.number);
    if (goal == goals.end()) {
      return;
    }
    goal->second.answered = true;
    goal->second.host_id = reply.host_id;
    if (!reply.accepted) {
      goal->second.ended = true;
      goal->second.latest = component::OperationResult::failure(std::string(reply.component) + " rejected " +
                                                                goal->second.operation + ": " + reply.reason);
    }
  }

  void onStatus(const costar_msgs_action_dds__Operation_Status_& status, bool final) {
    if (status.goal_id.client != client_id) {
      return;
    }
    std::lock_guard lock(mutex);
    if (cancelling.erase(status.goal_id.number) > 0) {
      if (final) {
        cancel_confirmed.insert(status.goal_id.number);
      } else {
        cancelling.insert(status.goal_id.number);
      }
      return;
    }
    const auto goal = goals.find(status.goal_id.number);
    if (goal == goals.end() || goal->second.ended) {
      return;
    }
    component::OperationResult result;
    try {
      result.data = nlohmann::json::parse(status.data_json);
    } catch (const nlohmann::json::exception& error) {
      result = component::OperationResult::failure(std::string(status.component) +
                                                   ": the host sent a result that is not JSON: " + error.what());
      goal->second.ended = true;
      goal->second.latest = std::move(result);
      return;
    }
    result.reason = status.reason;
    switch (status.status) {
      case costar_msgs_action_dds__STATUS_SUCCEEDED:
        result.state = component::OperationState::kSuccess;
        break;
      case costar_msgs_action_dds__STATUS_ABORTED:
        result.state = component::OperationState::kFailure;
        break;
      case costar_msgs_action_dds__STATUS_CANCELED:
        result.state = component::OperationState::kFailure;
        result.reason = std::string(status.component) + ": " + goal->second.operation + " was cancelled on its host";
        break;
      default:
        result.state = component::OperationState::kRunning;
        break;
    }
    goal->second.answered = true;
    goal->second.host_id = status.host_id;
    goal->second.ended = final;
    goal->second.latest = std::move(result);
    goal->second.report_number = status.report_number;
  }

  void onDescription(const costar_msgs_msg_dds__ComponentDescription_& description) {
    std::lock_guard lock(mutex);
    Served& entry = served[description.component];
    entry.description_json = description.description_json;
    entry.host_id = description.host_id;
    heard.notify_all();
  }

  void onReport(const costar_msgs_msg_dds__ComponentReport_& report) {
    world::Report parsed;
    std::string error;
    try {
      const auto json = nlohmann::json::parse(report.report_json);
      if (json.contains("error")) {
        error = json["error"].get<std::string>();
      } else {
        parsed = reportFromJson(json);
      }
    } catch (const std::exception& failure) {
      error = std::string(report.component) + ": its host sent a report that cannot be read: " + failure.what();
    }
    std::lock_guard lock(mutex);
    Served& entry = served[report.component];
    if (entry.report_host == report.host_id && report.number <= entry.report_number) {
      return;  // an older report of this host than the one held
    }
    entry.report_host = report.host_id;
    entry.report_number = report.number;
    entry.report = std::move(parsed);
    entry.report_error = std::move(error);
  }

  void onHeartbeat(const costar_msgs_msg_dds__HostHeartbeat_& heartbeat) {
    std::lock_guard lock(mutex);
    Host& host = hosts[heartbeat.host_id];
    host.pid = heartbeat.pid;
    host.hostname = heartbeat.hostname;
    host.components.assign(heartbeat.components._buffer, heartbeat.components._buffer + heartbeat.components._length);
    host.heard = SteadyClock::now();
    heard.notify_all();
  }

  template <typename T, void (State::*Handle)(const T&)>
  static void listen(dds_entity_t reader, void* self) {
    Bus::takeAll<T>(reader, [self](const T& sample) { (static_cast<State*>(self)->*Handle)(sample); });
  }
  void onFeedback(const costar_msgs_action_dds__Operation_Status_& status) { onStatus(status, false); }
  void onResult(const costar_msgs_action_dds__Operation_Status_& status) { onStatus(status, true); }
};

RemoteClient::RemoteClient(const RemoteConfig& config) : state_(std::make_unique<State>(config)) {
  State& state = *state_;
  state.goal_writer = state.bus.writer(Topic::kSendGoalRequest);
  state.cancel_writer = state.bus.writer(Topic::kCancelGoalRequest);
  const auto reader = [&](Topic topic, dds_on_data_available_fn on_data) {
    dds_listener_t* listener = dds_create_listener(&state);
    dds_lset_data_available(listener, on_data);
    state.bus.reader(topic, listener);
    dds_delete_listener(listener);
  };
  using S = State;
  reader(Topic::kSendGoalReply, &S::listen<costar_msgs_action_dds__Operation_SendGoal_Response_, &S::onReply>);
  reader(Topic::kFeedback, &S::listen<costar_msgs_action_dds__Operation_Status_, &S::onFeedback>);
  reader(Topic::kResult, &S::listen<costar_msgs_action_dds__Operation_Status_, &S::onResult>);
  reader(Topic::kDescription, &S::listen<costar_msgs_msg_dds__ComponentDescription_, &S::onDescription>);
  reader(Topic::kReport, &S::listen<costar_msgs_msg_dds__ComponentReport_, &S::onReport>);
  reader(Topic::kHeartbeat, &S::listen<costar_msgs_msg_dds__HostHeartbeat_, &S::onHeartbeat>);
  if (config.lockstep) {
    state.call_writer = state.bus.writer(Topic::kCallRequest);
    state.call_reply_reader = state.bus.reader(Topic::kCallReply, nullptr);
    state.driver_request_reader = state.bus.reader(Topic::kDriverRequest, nullptr);
    state.driver_reply_writer = state.bus.writer(Topic::kDriverReply);
    state.clock_writer = state.bus.writer(Topic::kClock);
    state.joint_state_writer = state.bus.writer(Topic::kJointStates);
    state.wrench_writer = state.bus.writer(Topic::kWrench);
    state.color_image_writer = state.bus.writer(Topic::kColorImage);
    state.depth_image_writer = state.bus.writer(Topic::kDepthImage);
    state.waitset = dds_create_waitset(state.bus.participant());
    dds_waitset_attach(state.waitset, dds_create_readcondition(state.call_reply_reader, DDS_ANY_STATE), 0);
    dds_waitset_attach(state.waitset, dds_create_readcondition(state.driver_request_reader, DDS_ANY_STATE), 0);
  }
}

namespace {

builtin_interfaces_msg_dds__Time_ rosTime(TimePoint t) {
  const std::int64_t ns = std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
  return {static_cast<std::int32_t>(ns / 1'000'000'000), static_cast<std::uint32_t>(ns % 1'000'000'000)};
}

template <typename Sequence, typename T>
void view(Sequence& sequence, std::vector<T>& values) {
  sequence._buffer = values.data();
  sequence._length = sequence._maximum = static_cast<std::uint32_t>(values.size());
  sequence._release = false;
}

}  // namespace

void RemoteClient::publishJointState(const JointStateSample& joints) {
  State& state = *state_;
  if (!state.config.lockstep) {
    throw std::logic_error("RemoteClient::publishJointState: only in lockstep");
  }
  std::vector<char*> names;
  for (const std::string& name : joints.names) {
    names.push_back(wire(name));
  }
  std::vector<double> position = joints.position, velocity = joints.velocity, effort = joints.effort;
  static const std::string kNoFrame;
  sensor_msgs_msg_dds__JointState_ message{};
  message.header.stamp = rosTime(joints.stamp);
  message.header.frame_id = wire(kNoFrame);
  view(message.name, names);
  view(message.position, position);
  view(message.velocity, velocity);
  view(message.effort, effort);
  Bus::write(state.joint_state_writer, &message);
}

void RemoteClient::publishWrench(const WrenchSample& wrench) {
  State& state = *state_;
  if (!state.config.lockstep) {
    throw std::logic_error("RemoteClient::publishWrench: only in lockstep");
  }
  geometry_msgs_msg_dds__WrenchStamped_ message{};
  message.header.stamp = rosTime(wrench.stamp);
  message.header.frame_id = wire(wrench.frame_id);
  message.wrench.force = {wrench.force[0], wrench.force[1], wrench.force[2]};
  message.wrench.torque = {wrench.torque[0], wrench.torque[1], wrench.torque[2]};
  Bus::write(state.wrench_writer, &message);
}

void RemoteClient::publishImages(const ImageSample& color, const ImageSample& depth) {
  State& state = *state_;
  if (!state.config.lockstep) {
    throw std::logic_error("RemoteClient::publishImages: only in lockstep");
  }
  const auto publish = [](dds_entity_t writer, const ImageSample& image) {
    if (image.data.empty()) {
      return;
    }
    std::vector<std::uint8_t> data = image.data;
    sensor_msgs_msg_dds__Image_ message{};
    message.header.stamp = rosTime(image.stamp);
    message.header.frame_id = wire(image.frame_id);
    message.height = image.height;
    message.width = image.width;
    message.encoding = wire(image.encoding);
    message.is_bigendian = 0;
    message.step = image.step;
    view(message.data, data);
    Bus::write(writer, &message);
  };
  publish(state.color_image_writer, color);
  publish(state.depth_image_writer, depth);
}

void RemoteClient::setDriverServer(DriverServer server, std::vector<DriverReading> readings) {
  state_->driver_server = std::move(server);
  state_->readings = {readings.begin(), readings.end()};
}

void RemoteClient::publishClock(TimePoint now) {
  State& state = *state_;
  if (!state.config.lockstep) {
    throw std::logic_error("RemoteClient::publishClock: only in lockstep");
  }
  state.clock_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now.time_since_epoch()).count();
  rosgraph_msgs_msg_dds__Clock_ message{};
  message.clock.sec = static_cast<std::int32_t>(state.clock_ns / 1'000'000'000);
  message.clock.nanosec = static_cast<std::uint32_t>(state.clock_ns % 1'000'000'000);
  Bus::write(state.clock_writer, &message);
}

// Deleting the participant first stops the listeners before the state they use goes.
RemoteClient::~RemoteClient() { dds_delete(state_->bus.participant()); }

std::shared_ptr<RemoteClient> RemoteClient::create(const RemoteConfig& config) {
  return std::shared_ptr<RemoteClient>(new RemoteClient(config));
}

std::shared_ptr<RemoteComponent> RemoteClient::connect(const std::string& component,
                                                       std::chrono::milliseconds timeout) {
  State& state = *state_;
  const auto deadline = SteadyClock::now() + timeout;
  const auto matched = [&](dds_entity_t writer) {
    dds_publication_matched_status_t status{};
    return dds_get_publication_matched_status(writer, &status) == DDS_RETCODE_OK && status.current_count > 0;
  };
  std::unique_lock lock(state.mutex);
  for (;;) {
    const auto served = state.served.find(component);
    if (served != state.served.end() && !served->second.description_json.empty() &&
        state.lost(component, served->second.host_id, SteadyClock::now()).empty() && matched(state.goal_writer) &&
        matched(state.cancel_writer) && (!state.config.lockstep || matched(state.call_writer))) {
      try {
        auto description = component::descriptionFromJson(nlohmann::json::parse(served->second.description_json));
        lock.unlock();
        return std::make_shared<RemoteComponent>(shared_from_this(), std::move(description));
      } catch (const std::exception& error) {
        throw std::runtime_error("component '" + component +
                                 "': its host sent a description that cannot be read: " + error.what());
      }
    }
    if (SteadyClock::now() >= deadline) {
      throw std::runtime_error("component '" + component + "': no host serves it on DDS domain " +
                               std::to_string(state.config.domain) + ", partition '" + state.config.partition +
                               "', interface '" + state.config.network_interface + "' (waited " + seconds(timeout) +
                               " s; start one with `costar host " + component + "`)");
    }
    state.heard.wait_for(lock, std::chrono::milliseconds(10));
  }
}

RemoteComponent::RemoteComponent(std::shared_ptr<RemoteClient> client, component::ComponentDescription description)
    : client_(std::move(client)), description_(std::move(description)) {}

component::OperationId RemoteComponent::start(const std::string& operation, const component::ParamMap& params) {
  RemoteClient::State& state = *client_->state_;
  if (state.config.lockstep) {
    const nlohmann::json answer =
        state.call(description_.name, "start", {{"operation", operation}, {"params", component::toJson(params)}});
    return answer.at("id").get<component::OperationId>();
  }
  const std::string params_json = component::toJson(params).dump();
  component::OperationId id = 0;
  {
    std::lock_guard lock(state.mutex);
    const auto served = state.served.find(description_.name);
    const std::uint64_t host_id = served == state.served.end() ? 0 : served->second.host_id;
    if (std::string reason = state.lost(description_.name, host_id, SteadyClock::now()); !reason.empty()) {
      throw std::runtime_error(reason);
    }
    id = state.next_goal++;
    RemoteClient::State::Goal& goal = state.goals[id];
    goal.component = description_.name;
    goal.operation = operation;
    goal.host_id = host_id;
    goal.sent = SteadyClock::now();
  }
  costar_msgs_action_dds__Operation_SendGoal_Request_ message{};
  message.goal_id = {state.client_id, id};
  message.component = wire(description_.name);
  message.operation = wire(operation);
  message.params_json = wire(params_json);
  try {
    Bus::write(state.goal_writer, &message);
  } catch (...) {
    std::lock_guard lock(state.mutex);
    state.goals.erase(id);
    throw;
  }
  return id;
}

component::OperationResult RemoteComponent::poll(component::OperationId id) {
  RemoteClient::State& state = *client_->state_;
  if (state.config.lockstep) {
    try {
      return component::resultFromJson(state.call(description_.name, "poll", {{"id", id}}));
    } catch (const std::exception& error) {
      return component::OperationResult::failure(error.what());
    }
  }
  std::lock_guard lock(state.mutex);
  const auto it = state.goals.find(id);
  if (it == state.goals.end()) {
    throw std::invalid_argument(description_.name + ": unknown operation id " + std::to_string(id));
  }
  const RemoteClient::State::Goal& goal = it->second;
  component::OperationResult result = goal.latest;
  const auto now = SteadyClock::now();
  const auto served = state.served.find(description_.name);
  // An end is shown with the report it left (until then the operation is still running here).
  const bool report_in =
      goal.report_number == 0 || (served != state.served.end() && served->second.report_host == goal.host_id &&
                                  served->second.report_number >= goal.report_number);
  if (!goal.ended || !report_in) {
    if (std::string reason = state.lost(description_.name, goal.host_id, now); !reason.empty()) {
      result = component::OperationResult::failure(reason + "; " + goal.operation + " ended with it");
    } else if (served != state.served.end() && served->second.host_id != goal.host_id) {
      result = component::OperationResult::failure("component '" + description_.name + "': its host was replaced; " +
                                                   goal.operation + " ended with the old one");
    } else if (!goal.answered && now - goal.sent > kAnswerTimeout) {
      result = component::OperationResult::failure("component '" + description_.name + "': its host did not answer " +
                                                   goal.operation + " within " + seconds(kAnswerTimeout) + " s");
    } else {
      return goal.ended ? component::OperationResult::running() : result;
    }
  }
  state.goals.erase(it);
  return result;
}

void RemoteComponent::cancel(component::OperationId id) {
  RemoteClient::State& state = *client_->state_;
  if (state.config.lockstep) {
    try {
      state.call(description_.name, "cancel", {{"id", id}});
    } catch (const std::exception&) {
      // A host that is gone has nothing running any more; cancel() never throws.
    }
    return;
  }
  {
    std::lock_guard lock(state.mutex);
    const auto it = state.goals.find(id);
    if (it == state.goals.end()) {
      return;
    }
    const bool ended = it->second.ended;
    state.goals.erase(it);
    if (ended) {
      return;
    }
    state.cancelling.insert(id);
  }
  costar_msgs_action_dds__Operation_CancelGoal_Request_ message{};
  message.goal_id = {state.client_id, id};
  message.component = wire(description_.name);
  // A cancel that cannot be sent leaves the host's operation to the host's own end (its
  // heartbeat is checked by the next start); cancel() itself never throws.
  dds_write(state.cancel_writer, &message);
}

bool RemoteComponent::cancelConfirmed(component::OperationId id) const {
  const RemoteClient::State& state = *client_->state_;
  std::lock_guard lock(state.mutex);
  return state.cancel_confirmed.contains(id);
}

world::Report RemoteComponent::report() const {
  RemoteClient::State& state = *client_->state_;
  if (state.config.lockstep) {
    // One call a tick for all of a host's components: the registry asks each component's report
    // in turn, with nothing between them that reaches the host (a report changes nothing).
    std::uint64_t host_id = 0;
    {
      std::lock_guard lock(state.mutex);
      const auto served = state.served.find(description_.name);
      host_id = served == state.served.end() ? 0 : served->second.host_id;
    }
    RemoteClient::State::Reports& held = state.reports[host_id];
    if (held.clock_ns != state.clock_ns || held.after_call != state.calls ||
        !held.by_component.contains(description_.name)) {
      held.by_component = state.call(description_.name, "reports", nlohmann::json::object());
      held.clock_ns = state.clock_ns;
      held.after_call = state.calls;
    }
    const nlohmann::json answer = std::move(held.by_component.at(description_.name));
    held.by_component.erase(description_.name);
    if (answer.contains("error")) {
      throw std::runtime_error(answer["error"].get<std::string>());
    }
    return reportFromJson(answer);
  }
  std::lock_guard lock(state.mutex);
  const auto served = state.served.find(description_.name);
  const std::uint64_t host_id = served == state.served.end() ? 0 : served->second.host_id;
  if (std::string reason = state.lost(description_.name, host_id, SteadyClock::now()); !reason.empty()) {
    throw std::runtime_error(reason);
  }
  if (!served->second.report_error.empty()) {
    throw std::runtime_error(served->second.report_error);
  }
  return served->second.report;
}

}  // namespace costar::dds
