#include "dds/lockstep.h"

#include <condition_variable>
#include <mutex>
#include <optional>
#include <stdexcept>

#include "dds/bus.h"

namespace costar::dds {
namespace {

using SteadyClock = std::chrono::steady_clock;

/// The simulated time of rt/clock, for a host's components.
class FollowedClock final : public Clock {
 public:
  explicit FollowedClock(SimulatorLink& link) : link_(link) {}
  TimePoint now() const override { return TimePoint(std::chrono::nanoseconds(now_ns_.load())); }
  void sleepUntil(TimePoint t) override {
    if (t > now()) {
      link_.reachTime(std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count());
    }
  }
  bool simulated() const override { return true; }
  void set(std::int64_t ns) { now_ns_.store(ns); }

 private:
  SimulatorLink& link_;
  std::atomic<std::int64_t> now_ns_{0};
};

}  // namespace

struct SimulatorLink::State {
  explicit State(const RemoteConfig& config, SimulatorLink& link) : bus(config), clock(link) {}

  Bus bus;
  FollowedClock clock;
  dds_entity_t request_writer = 0, reply_reader = 0, clock_reader = 0;
  dds_entity_t waitset = 0, reply_condition = 0, clock_condition = 0;
  std::uint64_t executor = 0;
  std::uint64_t host_id = 0;
  std::uint64_t calls = 0;
  std::int64_t latest_clock_ns = -1;
  nlohmann::json prepared = nlohmann::json::array();  // answered ahead by the executor
  std::uint32_t prepared_used = 0;

  void readClock() {
    Bus::takeAll<rosgraph_msgs_msg_dds__Clock_>(clock_reader, [this](const rosgraph_msgs_msg_dds__Clock_& message) {
      const std::int64_t ns = static_cast<std::int64_t>(message.clock.sec) * 1'000'000'000 + message.clock.nanosec;
      latest_clock_ns = std::max(latest_clock_ns, ns);
    });
  }
};

SimulatorLink::SimulatorLink(const RemoteConfig& config) : state_(std::make_unique<State>(config, *this)) {
  State& state = *state_;
  state.request_writer = state.bus.writer(Topic::kDriverRequest);
  state.reply_reader = state.bus.reader(Topic::kDriverReply, nullptr);
  state.clock_reader = state.bus.reader(Topic::kClock, nullptr);
  state.waitset = dds_create_waitset(state.bus.participant());
  state.reply_condition = dds_create_readcondition(state.reply_reader, DDS_ANY_STATE);
  state.clock_condition = dds_create_readcondition(state.clock_reader, DDS_ANY_STATE);
  dds_waitset_attach(state.waitset, state.reply_condition, 0);
  dds_waitset_attach(state.waitset, state.clock_condition, 0);
}

SimulatorLink::~SimulatorLink() = default;

void SimulatorLink::setExecutor(std::uint64_t client) {
  state_->executor = client;
  state_->latest_clock_ns = -1;  // a new run's clock starts again
}
bool SimulatorLink::hasExecutor() const { return state_->executor != 0; }
void SimulatorLink::setHost(std::uint64_t host_id) { state_->host_id = host_id; }
Clock& SimulatorLink::clock() { return state_->clock; }

void SimulatorLink::prepare(const std::string& prepared_json) {
  state_->prepared = prepared_json.empty() ? nlohmann::json::array() : nlohmann::json::parse(prepared_json);
  state_->prepared_used = 0;
}

std::uint64_t SimulatorLink::callsSent() const { return state_->calls; }

std::uint32_t SimulatorLink::preparedUsed() {
  const std::uint32_t used = state_->prepared_used;
  state_->prepared = nlohmann::json::array();
  state_->prepared_used = 0;
  return used;
}

DriverReply SimulatorLink::call(const std::string& driver, const std::string& method, const nlohmann::json& args) {
  State& state = *state_;
  if (state.prepared_used < state.prepared.size()) {
    const nlohmann::json& ahead = state.prepared[state.prepared_used];
    if (ahead.at("driver") == driver && ahead.at("method") == method && ahead.at("args") == args.dump()) {
      ++state.prepared_used;
      if (ahead.contains("error")) {
        throw std::runtime_error(driver + " " + method + ": " + ahead.at("error").get<std::string>());
      }
      return {ahead.at("result"), {}, {}};
    }
    state.prepared = nlohmann::json::array();  // the component asks otherwise this time: ask for the rest
  }
  const std::uint64_t number = ++state.calls;
  const std::string args_json = args.dump();
  costar_msgs_srv_dds__Call_Request_ request{};
  request.client = state.executor;
  request.host_id = state.host_id;
  request.number = number;
  request.target = wire(driver);
  request.method = wire(method);
  request.args_json = wire(args_json);
  request.stamp_ns = state.clock.now().time_since_epoch().count();
  static const std::string kNone;
  request.prepared_json = wire(kNone);
  Bus::write(state.request_writer, &request);
  const auto deadline = SteadyClock::now() + kAnswerTimeout;
  for (;;) {
    std::optional<DriverReply> reply;
    std::string error;
    Bus::takeAll<costar_msgs_srv_dds__Call_Response_>(
        state.reply_reader, [&](const costar_msgs_srv_dds__Call_Response_& answer) {
          if (answer.host_id != state.host_id || answer.client != state.executor || answer.number != number) {
            return;  // another host's, or an answer given up on
          }
          if (!answer.ok) {
            error = answer.error;
            reply.emplace();
            return;
          }
          DriverReply& got = reply.emplace();
          got.result = nlohmann::json::parse(answer.result_json);
          got.floats.assign(answer.floats._buffer, answer.floats._buffer + answer.floats._length);
          got.bytes.assign(answer.bytes._buffer, answer.bytes._buffer + answer.bytes._length);
        });
    if (reply) {
      if (!error.empty()) {
        throw std::runtime_error(driver + " " + method + ": " + error);
      }
      return std::move(*reply);
    }
    const auto now = SteadyClock::now();
    if (now >= deadline) {
      throw std::runtime_error(driver + " " + method +
                               ": the simulator (the executor's process) did not answer within " +
                               std::to_string(kAnswerTimeout.count()) + " s");
    }
    dds_waitset_wait(state.waitset, nullptr, 0, DDS_MSECS(50));
  }
}

void SimulatorLink::reachTime(std::int64_t stamp_ns) {
  State& state = *state_;
  const auto deadline = SteadyClock::now() + kAnswerTimeout;
  for (;;) {
    state.readClock();
    if (state.latest_clock_ns >= stamp_ns) {
      state.clock.set(stamp_ns);
      return;
    }
    if (SteadyClock::now() >= deadline) {
      throw std::runtime_error("rt/clock did not reach " + std::to_string(stamp_ns * 1e-9) + " s within " +
                               std::to_string(kAnswerTimeout.count()) + " s (" +
                               (state.latest_clock_ns < 0
                                    ? std::string("nothing heard from this run")
                                    : "last heard: " + std::to_string(state.latest_clock_ns * 1e-9) + " s") +
                               ")");
    }
    dds_waitset_wait(state.waitset, nullptr, 0, DDS_MSECS(50));
  }
}

}  // namespace costar::dds
