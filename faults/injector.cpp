#include "faults/injector.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <random>

namespace costar::faults {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string injected(const FaultRecord& record) { return " (injected: " + record.spec.text + ")"; }

/// A driver's reading under fault `fault`: `read()`'s until the fault is due, then a failure
/// (`failure`, naming the fault), the last good reading again (hang: same values, same stamp),
/// or a fresh reading with `spoil` applied (nan).
template <class Reading, class Read, class Spoil>
Reading readingUnder(Injector& injector, std::size_t fault, Reading& last, const Read& read, const Spoil& spoil,
                     const char* failure) {
  if (!injector.active(fault, false)) {
    last = read();
    return last;
  }
  injector.effect(fault);
  const FaultRecord& record = injector.record(fault);
  switch (record.spec.kind) {
    case FaultKind::kThrow:
      throw std::runtime_error(failure + injected(record));
    case FaultKind::kHang:
      return last;
    default: {
      Reading reading = read();
      spoil(reading);
      return reading;
    }
  }
}

/// The arm's joint encoders: fail, freeze or read NaN once the fault is due. Trajectories
/// still reach the controller.
class FaultyArmDriver final : public arm::ArmDriver {
 public:
  FaultyArmDriver(arm::ArmDriver& inner, Injector& injector, std::size_t fault)
      : inner_(inner), injector_(injector), fault_(fault) {}

  arm::ArmState read() const override {
    return readingUnder(
        injector_, fault_, last_, [this] { return inner_.read(); },
        [](arm::ArmState& state) {
          state.position.fill(kNaN);
          state.velocity.fill(kNaN);
        },
        "arm driver: reading the joint state failed");
  }

  void execute(std::shared_ptr<const arm::JointTrajectory> trajectory, TimePoint start) override {
    injector_.active(fault_, true);
    inner_.execute(std::move(trajectory), start);
  }

  Duration heldBack() const override { return inner_.heldBack(); }

 private:
  arm::ArmDriver& inner_;
  Injector& injector_;
  std::size_t fault_;
  mutable arm::ArmState last_;
};

/// The gripper's finger sensors, likewise; commands still reach the fingers.
class FaultyGripperDriver final : public gripper::GripperDriver {
 public:
  FaultyGripperDriver(gripper::GripperDriver& inner, Injector& injector, std::size_t fault)
      : inner_(inner), injector_(injector), fault_(fault) {}

  gripper::FingerReading read() const override {
    return readingUnder(
        injector_, fault_, last_, [this] { return inner_.read(); },
        [](gripper::FingerReading& reading) { reading.opening = reading.opening_speed = reading.force = kNaN; },
        "gripper driver: reading the fingers failed");
  }
  void command(double opening, double speed, double force) override {
    injector_.active(fault_, true);
    inner_.command(opening, speed, force);
  }
  double maxOpening() const override { return inner_.maxOpening(); }

 private:
  gripper::GripperDriver& inner_;
  Injector& injector_;
  std::size_t fault_;
  mutable gripper::FingerReading last_;
};

/// A 3-finger adaptive gripper's finger sensors, likewise (every finger's position, speed and
/// force); finger and mode commands still reach the gripper.
class FaultyAdaptiveGripperDriver final : public gripper::AdaptiveGripperDriver {
 public:
  FaultyAdaptiveGripperDriver(gripper::AdaptiveGripperDriver& inner, Injector& injector, std::size_t fault)
      : inner_(inner), injector_(injector), fault_(fault) {}

  gripper::AdaptiveGripperReading read() const override {
    return readingUnder(
        injector_, fault_, last_, [this] { return inner_.read(); },
        [](gripper::AdaptiveGripperReading& reading) {
          for (auto& finger : reading.fingers) {
            finger.position = finger.speed = finger.force = kNaN;
          }
        },
        "gripper driver: reading the fingers failed");
  }
  void commandFingers(const std::array<double, gripper::kFingerCount>& positions, double speed, double force) override {
    injector_.active(fault_, true);
    inner_.commandFingers(positions, speed, force);
  }
  void commandMode(gripper::GripperMode mode) override {
    injector_.active(fault_, true);
    inner_.commandMode(mode);
  }

 private:
  gripper::AdaptiveGripperDriver& inner_;
  Injector& injector_;
  std::size_t fault_;
  mutable gripper::AdaptiveGripperReading last_;
};

/// The RGB-D camera: its frames fail, repeat, come empty or all NaN, and its stream's status
/// (what a health monitor sees between frames) says so too.
class FaultyCamera final : public camera::RgbdCamera {
 public:
  FaultyCamera(camera::RgbdCamera& inner, Injector& injector, std::size_t fault)
      : inner_(inner), injector_(injector), fault_(fault) {}
  std::string name() const override { return inner_.name(); }
  const camera::Intrinsics& intrinsics() const override { return inner_.intrinsics(); }
  Duration framePeriod() const override { return inner_.framePeriod(); }

  camera::RgbdFrame capture() override {
    FaultRecord& record = injector_.record(fault_);
    if (!injector_.active(fault_, true) || (record.spec.kind == FaultKind::kDropFrame && record.spent)) {
      last_ = inner_.capture();
      newest_ = std::max(newest_, last_.stamp);
      return last_;
    }
    injector_.effect(fault_);
    switch (record.spec.kind) {
      case FaultKind::kDropFrame: {  // one frame lost on the way, then the stream goes on
        record.spent = true;
        camera::RgbdFrame frame = inner_.capture();
        frame.points.clear();
        frame.rgb = RgbImage();
        return frame;
      }
      case FaultKind::kThrow:
        throw std::runtime_error("camera: capturing a frame failed" + injected(record));
      case FaultKind::kHang:
        return last_;  // the stream stopped: the last frame again, with its old stamp
      case FaultKind::kEmptyFrame: {
        camera::RgbdFrame frame = inner_.capture();
        frame.points.clear();
        frame.rgb = RgbImage();
        return frame;
      }
      default: {
        camera::RgbdFrame frame = inner_.capture();
        std::fill(frame.points.begin(), frame.points.end(),
                  Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
        return frame;
      }
    }
  }

  /// Not counted for op=N (the frames are). A camera that cannot tell stays silent; one frame
  /// lost on the way (drop-frame) does not stop the stream.
  std::optional<camera::StreamStatus> streamStatus() override {
    std::optional<camera::StreamStatus> status = inner_.streamStatus();
    if (!status || !injector_.active(fault_, false) || injector_.record(fault_).spec.kind == FaultKind::kDropFrame) {
      if (status) {
        newest_ = std::max(newest_, status->stamp);
      }
      return status;
    }
    injector_.effect(fault_);
    const FaultRecord& record = injector_.record(fault_);
    switch (record.spec.kind) {
      case FaultKind::kThrow:
        throw std::runtime_error("camera: its stream does not answer" + injected(record));
      case FaultKind::kHang:
        status->stamp = newest_;  // no frame since the fault
        break;
      case FaultKind::kEmptyFrame:
        status->points = status->valid = 0;
        break;
      default:
        status->valid = 0;
        break;
    }
    return status;
  }

 private:
  camera::RgbdCamera& inner_;
  Injector& injector_;
  std::size_t fault_;
  camera::RgbdFrame last_;
  /// The newest stamp seen before the fault (frames and status).
  TimePoint newest_{};
};

/// A component that throws once, stops answering, or dies.
class FaultyComponent final : public component::Component {
 public:
  FaultyComponent(std::shared_ptr<component::Component> inner, Injector& injector, std::size_t fault)
      : inner_(std::move(inner)), injector_(injector), fault_(fault) {}

  const component::ComponentDescription& description() const override { return inner_->description(); }

  component::OperationId start(const std::string& operation, const component::ParamMap& params) override {
    check(true);
    return inner_->start(operation, params);
  }
  component::OperationResult poll(component::OperationId id) override {
    check(false);
    return inner_->poll(id);
  }
  void cancel(component::OperationId id) override {
    if (broken()) {
      fail();
    }
    inner_->cancel(id);
  }
  world::Report report() const override {
    if (broken()) {
      fail();
    }
    return inner_->report();
  }

 private:
  /// Hung or dead: every call fails from now on.
  bool broken() const {
    return injector_.active(fault_, false) && injector_.record(fault_).spec.kind != FaultKind::kThrow;
  }
  /// Before a start (counted for op=N) or a poll.
  void check(bool counts) {
    if (!injector_.active(fault_, counts)) {
      return;
    }
    FaultRecord& record = injector_.record(fault_);
    if (record.spec.kind == FaultKind::kThrow) {
      if (record.spent) {
        return;
      }
      record.spent = true;
      injector_.effect(fault_);
      throw std::runtime_error("the operation threw an exception" + injected(record));
    }
    fail();
  }
  [[noreturn]] void fail() const {
    injector_.effect(fault_);
    const FaultRecord& record = injector_.record(fault_);
    const std::string& name = inner_->description().name;
    if (record.spec.kind == FaultKind::kHang) {
      throw NoAnswer("component '" + name + "' did not answer in time" + injected(record));
    }
    throw std::runtime_error("component '" + name + "' is gone (its process exited)" + injected(record));
  }

  std::shared_ptr<component::Component> inner_;
  Injector& injector_;
  std::size_t fault_;
};

}  // namespace

Injector::Injector(std::vector<FaultSpec> specs, std::uint64_t seed) {
  std::mt19937_64 random(seed);
  for (FaultSpec& spec : specs) {
    FaultRecord record;
    if (spec.when.type == FaultWhen::Type::kTime) {
      record.due = TimePoint(fromSeconds(spec.when.seconds));
    } else if (spec.when.type == FaultWhen::Type::kRandom) {
      record.due = TimePoint(fromSeconds(std::uniform_real_distribution<double>(0.0, spec.when.seconds)(random)));
    }
    record.spec = std::move(spec);
    records_.push_back(std::move(record));
  }
}

std::shared_ptr<Injector> Injector::fromText(const std::vector<std::string>& specs, std::uint64_t seed) {
  std::vector<FaultSpec> parsed;
  for (const std::string& text : specs) {
    parsed.push_back(parseFault(text));
  }
  return std::make_shared<Injector>(std::move(parsed), seed);
}

TimePoint Injector::now() const { return clock_ != nullptr ? clock_->now() : TimePoint{}; }

bool Injector::active(std::size_t index, bool counts) {
  FaultRecord& record = records_[index];
  if (record.activated) {
    return true;
  }
  if (counts) {
    ++record.calls;
  }
  const bool due = record.due ? now() >= *record.due : record.calls >= record.spec.when.operation;
  if (due) {
    record.activated = record.due ? *record.due : now();
  }
  return due;
}

void Injector::effect(std::size_t index) {
  if (!records_[index].first_effect) {
    records_[index].first_effect = now();
  }
}

std::vector<std::size_t> Injector::faultsOn(std::string_view target) const {
  std::vector<std::size_t> found;
  for (std::size_t i = 0; i < records_.size(); ++i) {
    if (records_[i].spec.target == target) {
      found.push_back(i);
    }
  }
  return found;
}

template <class Faulty, class Interface>
Interface& Injector::chain(Interface& inner, const char* target, std::vector<std::unique_ptr<Interface>>& wrappers) {
  wrapped_targets_.push_back(target);
  Interface* outer = &inner;
  for (const std::size_t fault : faultsOn(target)) {
    wrappers.push_back(std::make_unique<Faulty>(*outer, *this, fault));
    outer = wrappers.back().get();
  }
  return *outer;
}

arm::ArmDriver& Injector::wrap(arm::ArmDriver& driver) {
  return chain<FaultyArmDriver>(driver, "arm-driver", arm_wrappers_);
}

gripper::GripperDriver& Injector::wrap(gripper::GripperDriver& driver) {
  return chain<FaultyGripperDriver>(driver, "gripper-driver", gripper_wrappers_);
}

gripper::AdaptiveGripperDriver& Injector::wrap(gripper::AdaptiveGripperDriver& driver) {
  return chain<FaultyAdaptiveGripperDriver>(driver, "gripper-driver", adaptive_wrappers_);
}

camera::RgbdCamera& Injector::wrap(camera::RgbdCamera& camera) {
  return chain<FaultyCamera>(camera, "camera", camera_wrappers_);
}

std::shared_ptr<component::Component> Injector::wrap(std::shared_ptr<component::Component> component) {
  const std::string name = component->description().name;
  wrapped_targets_.push_back(name);
  for (const std::size_t fault : faultsOn(name)) {
    component = std::make_shared<FaultyComponent>(std::move(component), *this, fault);
  }
  return component;
}

std::string Injector::summary() const {
  std::string text;
  char line[160];
  for (const FaultRecord& record : records_) {
    if (!record.activated) {
      std::snprintf(line, sizeof line, "fault %s: never became due%s\n", record.spec.text.c_str(),
                    record.due ? (" (due at " + std::to_string(toSeconds(*record.due)) + " s)").c_str() : "");
    } else if (!record.first_effect) {
      std::snprintf(line, sizeof line, "fault %s: due at %.3f s, took no effect (the target was not used again)\n",
                    record.spec.text.c_str(), toSeconds(*record.activated));
    } else {
      std::snprintf(line, sizeof line, "fault %s: due at %.3f s, took effect at %.3f s\n", record.spec.text.c_str(),
                    toSeconds(*record.activated), toSeconds(*record.first_effect));
    }
    text += line;
  }
  return text;
}

void Injector::checkTargets() const {
  for (const FaultRecord& record : records_) {
    if (std::find(wrapped_targets_.begin(), wrapped_targets_.end(), record.spec.target) == wrapped_targets_.end()) {
      std::string known;
      for (const std::string& target : wrapped_targets_) {
        known += (known.empty() ? "" : ", ") + target;
      }
      throw FaultSpecError("fault '" + record.spec.text + "': this workcell has no '" + record.spec.target +
                           "' (it has: " + (known.empty() ? "nothing that can fail" : known) + ")");
    }
  }
}

}  // namespace costar::faults
