#include "dds/host.h"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <chrono>
#include <condition_variable>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>

#include "component/description.h"
#include "dds/bus.h"
#include "dds/report_json.h"

namespace costar::dds {
namespace {

using SteadyClock = std::chrono::steady_clock;
using GoalKey = std::pair<std::uint64_t, std::uint64_t>;  // (client, number)

/// How often running operations are polled.
constexpr std::chrono::milliseconds kPollPeriod{1};
/// How often each component's report is read (and published when it changed).
constexpr std::chrono::milliseconds kReportPeriod{20};

std::uint64_t randomId() {
  std::random_device device;
  return (static_cast<std::uint64_t>(device()) << 32U) ^ device() ^ static_cast<std::uint64_t>(::getpid());
}

std::string hostName() {
  char name[256] = {};
  return ::gethostname(name, sizeof(name) - 1) == 0 ? std::string(name) : std::string("unknown");
}

}  // namespace

struct ComponentHost::State {
  struct Running {
    component::Component* component;
    component::OperationId id;
    std::string operation;
    std::string last_sent;  // the feedback last published (reason and data), to send changes only
  };

  explicit State(const RemoteConfig& config) : bus(config) {}

  Bus bus;
  std::uint64_t id = randomId();
  std::map<std::string, std::shared_ptr<component::Component>, std::less<>> components;
  std::vector<std::string> names;
  std::map<GoalKey, Running> running;
  struct SentReport {
    std::string json;
    std::uint64_t number = 0;
  };
  std::map<std::string, SentReport, std::less<>> last_reports;
  /// Cancels that came before their goal (the two travel on different topics, in no set
  /// order): the goal is then never started. Bounded: the oldest are dropped.
  std::set<GoalKey> cancelled_early;
  static constexpr std::size_t kCancelledEarlyLimit = 1024;
  dds_entity_t goal_reader = 0, cancel_reader = 0, call_reader = 0, call_reply_writer = 0;
  std::optional<ComponentHost::Lockstep> lockstep;
  std::uint64_t executor = 0;  // lockstep: the executor of the present run
  dds_entity_t reply_writer = 0, feedback_writer = 0, result_writer = 0;
  dds_entity_t description_writer = 0, report_writer = 0, heartbeat_writer = 0;
  std::uint64_t heartbeats = 0;

  void sendStatus(dds_entity_t writer, const GoalKey& goal, const std::string& component, std::uint8_t status,
                  const std::string& reason, const std::string& data_json) const {
    costar_msgs_action_dds__Operation_Status_ message{};
    message.goal_id = {goal.first, goal.second};
    message.component = wire(component);
    message.host_id = id;
    message.status = status;
    message.reason = wire(reason);
    message.data_json = wire(data_json);
    const auto report = last_reports.find(component);
    message.report_number = report == last_reports.end() ? 0 : report->second.number;
    Bus::write(writer, &message);
  }

  void reply(const GoalKey& goal, const std::string& component, bool accepted, const std::string& reason) const {
    costar_msgs_action_dds__Operation_SendGoal_Response_ message{};
    message.goal_id = {goal.first, goal.second};
    message.component = wire(component);
    message.host_id = id;
    message.accepted = accepted;
    message.reason = wire(reason);
    Bus::write(reply_writer, &message);
  }

  void startGoal(const costar_msgs_action_dds__Operation_SendGoal_Request_& goal) {
    const auto found = components.find(goal.component);
    if (found == components.end()) {
      return;  // another host's component
    }
    const GoalKey key{goal.goal_id.client, goal.goal_id.number};
    if (cancelled_early.erase(key) > 0) {
      sendStatus(result_writer, key, found->first, costar_msgs_action_dds__STATUS_CANCELED, "cancelled", "null");
      return;
    }
    component::Component& component = *found->second;
    const std::string operation = goal.operation;
    try {
      const component::OperationSpec* spec = component.description().operation(operation);
      if (spec == nullptr) {
        throw std::invalid_argument(component.description().name + " has no operation '" + operation + "'");
      }
      const auto params = component::paramsFromJson(spec->params, nlohmann::json::parse(goal.params_json));
      const component::OperationId started = component.start(operation, params);
      running.emplace(key, Running{&component, started, operation, {}});
      reply(key, found->first, true, {});
    } catch (const std::exception& error) {
      reply(key, found->first, false, error.what());
    }
  }

  void cancelGoal(const costar_msgs_action_dds__Operation_CancelGoal_Request_& cancel) {
    const GoalKey key{cancel.goal_id.client, cancel.goal_id.number};
    const auto it = running.find(key);
    if (it == running.end()) {
      if (components.contains(std::string_view(cancel.component))) {
        cancelled_early.insert(key);
        if (cancelled_early.size() > kCancelledEarlyLimit) {
          cancelled_early.erase(cancelled_early.begin());
        }
      }
      return;
    }
    it->second.component->cancel(it->second.id);
    sendStatus(result_writer, it->first, it->second.component->description().name,
               costar_msgs_action_dds__STATUS_CANCELED, "cancelled", "null");
    running.erase(it);
  }

  void pollRunning() {
    for (auto it = running.begin(); it != running.end();) {
      Running& goal = it->second;
      const std::string& name = goal.component->description().name;
      component::OperationResult result;
      try {
        result = goal.component->poll(goal.id);
      } catch (const std::exception& error) {
        result = component::OperationResult::failure(name + ": " + goal.operation + " failed: " + error.what());
      }
      const std::string data = result.data.dump();
      if (result.state == component::OperationState::kRunning) {
        if (result.reason + '\n' + data != goal.last_sent) {
          goal.last_sent = result.reason + '\n' + data;
          sendStatus(feedback_writer, it->first, name, costar_msgs_action_dds__STATUS_EXECUTING, result.reason, data);
        }
        ++it;
        continue;
      }
      // Its effect first: the report as the operation left it, then its end.
      publishReport(name, *goal.component);
      const bool success = result.state == component::OperationState::kSuccess;
      sendStatus(result_writer, it->first, name,
                 success ? costar_msgs_action_dds__STATUS_SUCCEEDED : costar_msgs_action_dds__STATUS_ABORTED,
                 result.reason, data);
      it = running.erase(it);
    }
  }

  void publishReports() {
    for (const auto& [name, component] : components) {
      publishReport(name, *component);
    }
  }

  /// Publishes the component's report when it changed since the last one sent.
  void publishReport(const std::string& name, const component::Component& component) {
    {
      std::string text;
      try {
        text = toJson(component.report()).dump();
      } catch (const std::exception& error) {
        // A report that cannot be read is a component that cannot be trusted: the proxy's
        // report() throws with this reason, which stops the executor's cell.
        text = nlohmann::json{{"error", name + ": " + error.what()}}.dump();
      }
      SentReport& last = last_reports[name];
      if (text == last.json) {
        return;
      }
      last.json = text;
      ++last.number;
      costar_msgs_msg_dds__ComponentReport_ message{};
      message.component = wire(name);
      message.host_id = id;
      message.number = last.number;
      message.report_json = wire(text);
      Bus::write(report_writer, &message);
    }
  }

  /// A component's report as JSON, or {"error": why} when it throws.
  static nlohmann::json reportOf(const std::string& name, const component::Component& component) {
    try {
      return toJson(component.report());
    } catch (const std::exception& failure) {
      return {{"error", name + ": " + failure.what()}};
    }
  }

  /// Answers a lockstep call of an executor.
  void answerCall(const costar_msgs_srv_dds__Call_Request_& request) {
    if (!components.contains(std::string_view(request.target)) || (request.host_id != 0 && request.host_id != id)) {
      return;  // another host's component
    }
    nlohmann::json result;
    std::string error;
    try {
      if (!lockstep) {
        throw std::runtime_error("this host does not run in lockstep with a simulated clock");
      }
      if (request.client != executor) {
        // A new run: its components start afresh, as they would in its own process.
        std::vector<std::shared_ptr<component::Component>> fresh = lockstep->new_run(request.client);
        for (auto& component : fresh) {
          const std::string name = component->description().name;
          if (!components.contains(name)) {
            throw std::logic_error("ComponentHost: new_run made a component '" + name + "' not served");
          }
          components[name] = std::move(component);
        }
        executor = request.client;
      }
      lockstep->reach_time(request.stamp_ns);
      if (lockstep->prepare) {
        lockstep->prepare(request.prepared_json);
      }
      component::Component& component = *components.find(std::string_view(request.target))->second;
      const std::string method = request.method;
      const nlohmann::json args = nlohmann::json::parse(request.args_json);
      if (method == "start") {
        const std::string operation = args.at("operation").get<std::string>();
        const component::OperationSpec* spec = component.description().operation(operation);
        if (spec == nullptr) {
          throw std::invalid_argument(component.description().name + " has no operation '" + operation + "'");
        }
        const auto params = component::paramsFromJson(spec->params, args.at("params"));
        result = {{"id", component.start(operation, params)}};
      } else if (method == "poll") {
        try {
          result = component::toJson(component.poll(args.at("id").get<component::OperationId>()));
        } catch (const std::exception& failure) {
          result = component::toJson(
              component::OperationResult::failure(std::string(request.target) + ": " + failure.what()));
        }
      } else if (method == "cancel") {
        component.cancel(args.at("id").get<component::OperationId>());
        result = nlohmann::json::object();
      } else if (method == "report") {
        result = reportOf(request.target, component);
      } else if (method == "reports") {
        // Every component's of this host, the one asked first: one call a tick for all of them.
        result = {{request.target, reportOf(request.target, component)}};
        for (const std::string& name : names) {
          if (name != request.target) {
            result[name] = reportOf(name, *components.find(name)->second);
          }
        }
      } else {
        throw std::invalid_argument("unknown call '" + method + "'");
      }
    } catch (const std::exception& failure) {
      error = failure.what();
    }
    const std::string result_json = result.dump();
    costar_msgs_srv_dds__Call_Response_ message{};
    message.client = request.client;
    message.host_id = id;
    message.number = request.number;
    message.prepared_used = lockstep && lockstep->prepared_used ? lockstep->prepared_used() : 0;
    message.ok = error.empty();
    message.error = wire(error);
    message.result_json = wire(result_json);
    Bus::write(call_reply_writer, &message);
  }

  void heartbeat() {
    static const std::string kHostName = hostName();
    std::vector<char*> listed;
    for (const auto& name : names) {
      listed.push_back(wire(name));
    }
    costar_msgs_msg_dds__HostHeartbeat_ message{};
    message.host_id = id;
    message.pid = static_cast<std::int32_t>(::getpid());
    message.hostname = wire(kHostName);
    message.components._length = message.components._maximum = static_cast<std::uint32_t>(listed.size());
    message.components._buffer = listed.data();
    message.components._release = false;
    message.sequence_number = heartbeats++;
    Bus::write(heartbeat_writer, &message);
  }
};

ComponentHost::ComponentHost(const RemoteConfig& config, std::vector<std::shared_ptr<component::Component>> components,
                             std::optional<Lockstep> lockstep) {
  if (components.empty()) {
    throw std::invalid_argument("a component host needs at least one component to serve");
  }
  state_ = std::make_unique<State>(config);
  state_->lockstep = std::move(lockstep);
  for (auto& component : components) {
    const std::string name = component->description().name;
    if (!state_->components.emplace(name, std::move(component)).second) {
      throw std::invalid_argument("component '" + name + "' given twice to one host");
    }
    state_->names.push_back(name);
  }
  Bus& bus = state_->bus;
  state_->reply_writer = bus.writer(Topic::kSendGoalReply);
  state_->feedback_writer = bus.writer(Topic::kFeedback);
  state_->result_writer = bus.writer(Topic::kResult);
  state_->description_writer = bus.writer(Topic::kDescription);
  state_->report_writer = bus.writer(Topic::kReport);
  state_->heartbeat_writer = bus.writer(Topic::kHeartbeat);
  state_->goal_reader = bus.reader(Topic::kSendGoalRequest, nullptr);
  state_->cancel_reader = bus.reader(Topic::kCancelGoalRequest, nullptr);
  state_->call_reader = bus.reader(Topic::kCallRequest, nullptr);
  state_->call_reply_writer = bus.writer(Topic::kCallReply);
  for (const auto& [name, component] : state_->components) {
    const std::string description = component::toJson(component->description()).dump();
    costar_msgs_msg_dds__ComponentDescription_ message{};
    message.component = wire(name);
    message.host_id = state_->id;
    message.description_json = wire(description);
    Bus::write(state_->description_writer, &message);
  }
  if (!state_->lockstep) {
    state_->publishReports();  // in lockstep, reports are read by the executor's calls
  }
  state_->heartbeat();
}

ComponentHost::~ComponentHost() = default;

std::uint64_t ComponentHost::id() const { return state_->id; }

void ComponentHost::serve(const std::atomic<bool>& stop, const std::function<void()>& each_cycle) {
  State& state = *state_;
  const dds_entity_t waitset = dds_create_waitset(state.bus.participant());
  const dds_entity_t goals = dds_create_readcondition(state.goal_reader, DDS_ANY_STATE);
  const dds_entity_t cancels = dds_create_readcondition(state.cancel_reader, DDS_ANY_STATE);
  const dds_entity_t calls = dds_create_readcondition(state.call_reader, DDS_ANY_STATE);
  dds_waitset_attach(waitset, goals, 0);
  dds_waitset_attach(waitset, cancels, 0);
  dds_waitset_attach(waitset, calls, 0);
  // The heartbeat, from its own thread: an operation's step may take longer than kHostTimeout.
  std::atomic<bool> serving{true};
  std::mutex beat_mutex;
  std::condition_variable beat_wake;
  std::thread beat([&] {
    std::unique_lock lock(beat_mutex);
    while (serving.load()) {
      try {
        state.heartbeat();
      } catch (const std::exception& error) {
        spdlog::error("component host: {}", error.what());
      }
      beat_wake.wait_for(lock, kHeartbeatPeriod);
    }
  });
  auto next_report = SteadyClock::now() + kReportPeriod;
  while (!stop.load()) {
    // Sleep until a goal, cancel or call arrives, the next poll of running operations or the
    // next report, whichever is first (at most a heartbeat period, to notice `stop`).
    const auto now = SteadyClock::now();
    auto wake = std::min(now + kHeartbeatPeriod, next_report);
    if (!state.running.empty()) {
      wake = std::min(wake, now + kPollPeriod);
    }
    const auto wait = std::max(std::chrono::nanoseconds(0), wake - now);
    dds_waitset_wait(waitset, nullptr, 0, static_cast<dds_duration_t>(wait.count()));
    try {
      if (each_cycle) {
        each_cycle();
      }
      Bus::takeAll<costar_msgs_action_dds__Operation_SendGoal_Request_>(
          state.goal_reader, [&](const auto& goal) { state.startGoal(goal); });
      Bus::takeAll<costar_msgs_action_dds__Operation_CancelGoal_Request_>(
          state.cancel_reader, [&](const auto& cancel) { state.cancelGoal(cancel); });
      Bus::takeAll<costar_msgs_srv_dds__Call_Request_>(state.call_reader,
                                                       [&](const auto& call) { state.answerCall(call); });
      state.pollRunning();
      if (SteadyClock::now() >= next_report) {
        if (!state.lockstep) {
          state.publishReports();
        }
        next_report = SteadyClock::now() + kReportPeriod;
      }
    } catch (const std::exception& error) {
      spdlog::error("component host: {}", error.what());
    }
  }
  for (auto& [key, goal] : state.running) {
    goal.component->cancel(goal.id);
  }
  state.running.clear();
  {
    std::lock_guard lock(beat_mutex);
    serving = false;
  }
  beat_wake.notify_all();
  beat.join();
  dds_delete(waitset);
  dds_delete(goals);
  dds_delete(cancels);
  dds_delete(calls);
}

}  // namespace costar::dds
