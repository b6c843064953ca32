#include "faults/fault.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <utility>

#include "core/clock.h"

namespace costar::faults {

namespace {

constexpr std::array<std::pair<FaultKind, const char*>, 7> kKinds = {{{FaultKind::kThrow, "throw"},
                                                                      {FaultKind::kHang, "hang"},
                                                                      {FaultKind::kNan, "nan"},
                                                                      {FaultKind::kEmptyFrame, "empty-frame"},
                                                                      {FaultKind::kNanFrame, "nan-frame"},
                                                                      {FaultKind::kDie, "die"},
                                                                      {FaultKind::kDropFrame, "drop-frame"}}};

std::string kindList() {
  std::string list;
  for (const auto& [kind, name] : kKinds) {
    list += (list.empty() ? "" : ", ") + std::string(name);
  }
  return list;
}

/// The kinds a target type accepts.
std::vector<FaultKind> kindsOf(TargetType type) {
  switch (type) {
    case TargetType::kArmDriver:
    case TargetType::kGripperDriver:
      return {FaultKind::kThrow, FaultKind::kHang, FaultKind::kNan};
    case TargetType::kCamera:
      return {FaultKind::kThrow, FaultKind::kHang, FaultKind::kEmptyFrame, FaultKind::kNanFrame, FaultKind::kDropFrame};
    case TargetType::kComponent:
      return {FaultKind::kThrow, FaultKind::kHang, FaultKind::kDie};
  }
  return {};
}

std::optional<double> number(std::string_view text) {
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

std::string_view withoutSeconds(std::string_view text) {
  if (!text.empty() && text.back() == 's') {
    text.remove_suffix(1);
  }
  return text;
}

}  // namespace

const char* toString(FaultKind kind) {
  for (const auto& [k, name] : kKinds) {
    if (k == kind) {
      return name;
    }
  }
  return "?";
}

TargetType targetType(std::string_view target) {
  if (target == "arm-driver") {
    return TargetType::kArmDriver;
  }
  if (target == "gripper-driver") {
    return TargetType::kGripperDriver;
  }
  if (target == "camera") {
    return TargetType::kCamera;
  }
  return TargetType::kComponent;
}

std::string faultGrammar() {
  return "KIND:TARGET@WHEN, e.g. nan:arm-driver@t=2.5s, hang:perception@op=1, die:smartmove@random=8s\n"
         "  TARGET: arm-driver, gripper-driver, camera, or a component's name (arm, gripper, perception, ...)\n"
         "  KIND:   drivers: throw, hang (readings stop updating), nan\n"
         "          camera: throw, hang (the same old frame), empty-frame, nan-frame, drop-frame (one empty frame, "
         "once)\n"
         "          components: throw (the next start or poll, once), hang (stops answering), die\n"
         "  WHEN:   t=SECONDS (clock time), op=N (the target's Nth command, start or frame),\n"
         "          random[=MAXs] (uniform in [0, MAX), default 10 s, drawn from --seed)";
}

FaultSpec parseFault(std::string_view text) {
  // The spec as typed, cut to 60 characters: a message never repeats 400 digits.
  const std::string quoted =
      "fault '" + (text.size() <= 60 ? std::string(text) : std::string(text.substr(0, 57)) + "...") + "'";
  const auto fail = [&quoted](const std::string& problem) -> FaultSpecError {
    return FaultSpecError(quoted + ": " + problem + " (expected " + faultGrammar() + ")");
  };
  const std::size_t colon = text.find(':');
  const std::size_t at = text.find('@');
  if (colon == std::string_view::npos || at == std::string_view::npos || at < colon) {
    throw fail("not of the form KIND:TARGET@WHEN");
  }
  FaultSpec spec;
  spec.text = std::string(text);
  const std::string_view kind = text.substr(0, colon);
  const auto known = std::find_if(kKinds.begin(), kKinds.end(), [&](const auto& k) { return kind == k.second; });
  if (known == kKinds.end()) {
    throw fail("unknown kind '" + std::string(kind) + "' (known: " + kindList() + ")");
  }
  spec.kind = known->first;
  spec.target = std::string(text.substr(colon + 1, at - colon - 1));
  if (spec.target.empty()) {
    throw fail("no target after ':'");
  }
  const TargetType type = targetType(spec.target);
  const std::vector<FaultKind> accepted = kindsOf(type);
  if (std::find(accepted.begin(), accepted.end(), spec.kind) == accepted.end()) {
    std::string list;
    for (const FaultKind k : accepted) {
      list += (list.empty() ? "" : ", ") + std::string(toString(k));
    }
    throw fail("a " + std::string(type == TargetType::kComponent ? "component" : spec.target) + " cannot have a '" +
               std::string(kind) + "' fault (it can: " + list + ")");
  }
  const std::string_view when = text.substr(at + 1);
  if (when.starts_with("t=")) {
    const auto seconds = number(withoutSeconds(when.substr(2)));
    if (!seconds || *seconds < 0 || *seconds > kMaxDurationSeconds) {
      throw fail("t= needs a time in seconds from 0 to 1e9, e.g. t=2.5s");
    }
    spec.when = {FaultWhen::Type::kTime, *seconds, 1};
  } else if (when.starts_with("op=")) {
    const auto n = number(when.substr(3));
    if (!n || *n < 1 || *n != std::floor(*n) || *n > 1e6) {
      throw fail("op= needs a whole number >= 1, e.g. op=2");
    }
    spec.when = {FaultWhen::Type::kOperation, 0.0, static_cast<int>(*n)};
  } else if (when == "random") {
    spec.when = {FaultWhen::Type::kRandom, 10.0, 1};
  } else if (when.starts_with("random=")) {
    const auto seconds = number(withoutSeconds(when.substr(7)));
    if (!seconds || *seconds <= 0 || *seconds > kMaxDurationSeconds) {
      throw fail("random= needs a window in seconds above 0 and at most 1e9, e.g. random=8s");
    }
    spec.when = {FaultWhen::Type::kRandom, *seconds, 1};
  } else {
    throw fail("unknown moment '" + std::string(when) + "' (t=SECONDS, op=N, random or random=MAXs)");
  }
  return spec;
}

}  // namespace costar::faults
