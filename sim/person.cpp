#include "sim/person.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "core/json_file.h"
#include "sim/scene_fields.h"

namespace costar::sim {

namespace {

using fields::fail;
using fields::json;
using fields::numberIn;
using fields::numbers;
using fields::object;
using fields::onlyKnownFields;
using fields::required;
using fields::shown;
using fields::stringField;
using fields::whole;

constexpr double kMinHeight = 0.03;   // a target's height above the table, m
constexpr double kTurnSeconds = 0.4;  // the palm turning up or down

Eigen::Vector3d point(const json& value, const std::string& field) {
  const std::vector<double> xyz = numbers(value, field, 3, 3, "a point [x, y, z] (m)");
  return {xyz[0], xyz[1], xyz[2]};
}

void checkTarget(const Eigen::Vector3d& target, const Eigen::Vector3d& shoulder, const std::string& field) {
  const double distance = (target - shoulder).norm();
  if (distance > kPersonReach) {
    fail(field, "lies " + fields::written(std::round(distance * 1000) / 1000) +
                    " m from the shoulder; a person's arm reaches " + fields::written(kPersonReach) + " m");
  }
  // Everywhere, not only over the table: the simulator's table top is an endless plane.
  if (target.z() < kMinHeight) {
    fail(field, "lies " + fields::written(target.z()) + " m above the table top's height; the hand keeps at least " +
                    fields::written(kMinHeight) + " m above it");
  }
}

PersonStep parseStep(const json& value, const std::string& field, const Eigen::Vector3d& shoulder) {
  object(value, field);
  const std::string kind =
      stringField(required(value, "do", field, "what the hand does: \"reach\", \"gesture\" ..."), field + ".do");
  PersonStep step;
  const auto speed = [&] {
    if (value.contains("speed")) {
      step.speed = numberIn(value.at("speed"), field + ".speed", 0.05, kPersonMaxSpeed, "m/s");
    }
  };
  const auto seconds = [&] {
    step.seconds =
        numberIn(required(value, "seconds", field, "how long, s"), field + ".seconds", 0.05, 600.0, "seconds");
  };
  if (kind == "reach") {
    onlyKnownFields(value, field, {"do", "to", "speed"});
    step.kind = PersonStep::Kind::kReach;
    step.to = point(required(value, "to", field, "[x, y, z] in m"), field + ".to");
    checkTarget(step.to, shoulder, field + ".to");
    speed();
  } else if (kind == "reach_random") {
    onlyKnownFields(value, field, {"do", "min", "max", "speed"});
    step.kind = PersonStep::Kind::kReachRandom;
    step.box_min = point(required(value, "min", field, "[x, y, z] in m"), field + ".min");
    step.box_max = point(required(value, "max", field, "[x, y, z] in m"), field + ".max");
    if ((step.box_max - step.box_min).minCoeff() < 0.0) {
      fail(field + ".max", "must not be below min in any coordinate, not " + shown(value.at("max")));
    }
    if (step.box_min.z() < kMinHeight) {
      fail(field + ".min",
           "z must be at least " + fields::written(kMinHeight) + " m above the table, not " + shown(value.at("min")));
    }
    speed();
  } else if (kind == "withdraw") {
    onlyKnownFields(value, field, {"do", "speed"});
    step.kind = PersonStep::Kind::kWithdraw;
    speed();
  } else if (kind == "leave" || kind == "enter") {
    onlyKnownFields(value, field, {"do", "speed"});
    step.kind = kind == "leave" ? PersonStep::Kind::kLeave : PersonStep::Kind::kEnter;
    step.speed = 1.0;
    speed();
  } else if (kind == "gesture" || kind == "take" || kind == "wait" || kind == "close" || kind == "open") {
    onlyKnownFields(value, field, {"do", "seconds"});
    step.kind = kind == "gesture" ? PersonStep::Kind::kGesture
                : kind == "take"  ? PersonStep::Kind::kTake
                : kind == "wait"  ? PersonStep::Kind::kWait
                : kind == "close" ? PersonStep::Kind::kClose
                                  : PersonStep::Kind::kOpen;
    seconds();
  } else {
    fail(field + ".do", "unknown step '" + kind +
                            "' (known: reach, reach_random, gesture, take, wait, close, open, withdraw, leave, enter)");
  }
  return step;
}

/// Minimum-jerk progress from 0 to 1 over [0, 1].
double minimumJerk(double s) {
  s = std::clamp(s, 0.0, 1.0);
  return s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
}

double minimumJerkRate(double s) {
  if (s <= 0.0 || s >= 1.0) {
    return 0.0;
  }
  return 30.0 * s * s * (1.0 - s) * (1.0 - s);
}

const char* stepName(PersonStep::Kind kind) {
  switch (kind) {
    case PersonStep::Kind::kReach:
      return "reach";
    case PersonStep::Kind::kReachRandom:
      return "reach_random";
    case PersonStep::Kind::kGesture:
      return "gesture";
    case PersonStep::Kind::kTake:
      return "take";
    case PersonStep::Kind::kWait:
      return "wait";
    case PersonStep::Kind::kClose:
      return "close";
    case PersonStep::Kind::kOpen:
      return "open";
    case PersonStep::Kind::kWithdraw:
      return "withdraw";
    case PersonStep::Kind::kLeave:
      return "leave";
    case PersonStep::Kind::kEnter:
      return "enter";
  }
  return "wait";
}

/// The hand's frame with its fingers along the horizontal direction from the shoulder to the
/// wrist, palm down or up.
Eigen::Quaterniond handFrame(const Eigen::Vector3d& shoulder, const Eigen::Vector3d& wrist, bool palm_up) {
  Eigen::Vector3d heading = wrist - shoulder;
  heading.z() = 0.0;
  if (heading.norm() < 1e-6) {
    heading = Eigen::Vector3d(0, -1, 0);
  }
  heading.normalize();
  const Eigen::Vector3d z = palm_up ? Eigen::Vector3d(0, 0, -1) : Eigen::Vector3d(0, 0, 1);
  Eigen::Matrix3d r;
  r.col(0) = heading;
  r.col(2) = z;
  r.col(1) = z.cross(heading);
  return Eigen::Quaterniond(r);
}

/// One script's steps, checked against where the person is (away or at the table).
std::vector<PersonStep> parseScript(const json& script, const std::string& field, const PersonSpec& spec) {
  if (!script.is_array() || script.empty() || script.size() > 1000) {
    fail(field, "must be a list of 1 to 1000 steps, not " + shown(script));
  }
  std::vector<PersonStep> steps;
  bool away = spec.starts_away;
  for (std::size_t i = 0; i < script.size(); ++i) {
    const std::string item = field + "[" + std::to_string(i) + "]";
    steps.push_back(parseStep(script[i], item, spec.shoulder));
    const PersonStep::Kind kind = steps.back().kind;
    if (away && kind != PersonStep::Kind::kEnter && kind != PersonStep::Kind::kWait &&
        kind != PersonStep::Kind::kOpen && kind != PersonStep::Kind::kClose) {
      fail(item + ".do", std::string("the person is away: only \"enter\", \"wait\", \"open\" or \"close\", not \"") +
                             stepName(kind) + "\"");
    }
    if (!away && kind == PersonStep::Kind::kEnter) {
      fail(item + ".do", "the person is already at the table");
    }
    away = kind == PersonStep::Kind::kLeave || (away && kind != PersonStep::Kind::kEnter);
  }
  if (spec.repeat && away != spec.starts_away) {
    fail(field, std::string("a repeating script must end ") + (spec.starts_away ? "away" : "at the table") +
                    ", where it starts");
  }
  return steps;
}

}  // namespace

Eigen::Vector3d PersonSpec::awayOffset() const {
  return Eigen::Vector3d(0.0, shoulder.y() >= 0.0 ? kLeaveDistance : -kLeaveDistance, 0.0);
}

Eigen::Vector3d PersonSpec::restPosition() const {
  if (rest) {
    return *rest;
  }
  Eigen::Vector3d toward(0.0, -shoulder.y(), 0.0);
  toward = toward.norm() > 1e-6 ? toward.normalized() : Eigen::Vector3d(1, 0, 0);
  return shoulder + 0.1 * toward + Eigen::Vector3d(0, 0, -std::min(0.35, shoulder.z() - 0.05));
}

PersonSpec parsePerson(const std::string& json_text, const std::string& field) {
  const json value = core::parseJson(json_text);
  object(value, field);
  onlyKnownFields(value, field, {"shoulder", "rest", "seed", "repeat", "start", "script", "scripts"});
  PersonSpec spec;
  spec.source = json_text;
  if (value.contains("shoulder")) {
    spec.shoulder = point(value.at("shoulder"), field + ".shoulder");
    if (spec.shoulder.z() < 0.1 || spec.shoulder.z() > 1.0) {
      fail(field + ".shoulder", "z must be from 0.1 to 1 m above the table, not " + shown(value.at("shoulder")));
    }
  }
  if (value.contains("rest")) {
    spec.rest = point(value.at("rest"), field + ".rest");
  }
  checkTarget(spec.restPosition(), spec.shoulder, field + (value.contains("rest") ? ".rest" : ".shoulder"));
  if (value.contains("seed")) {
    spec.seed = whole(value.at("seed"), field + ".seed", 0, std::numeric_limits<std::uint64_t>::max());
  }
  if (value.contains("repeat")) {
    if (!value.at("repeat").is_boolean()) {
      fail(field + ".repeat", "must be true or false, not " + shown(value.at("repeat")));
    }
    spec.repeat = value.at("repeat").get<bool>();
  }
  if (value.contains("start")) {
    const std::string start = stringField(value.at("start"), field + ".start");
    if (start != "present" && start != "away") {
      fail(field + ".start", "must be \"present\" or \"away\", not " + shown(value.at("start")));
    }
    spec.starts_away = start == "away";
  }
  if (value.contains("script") == value.contains("scripts")) {
    fail(field + ".script",
         value.contains("script")
             ? "give \"script\" or \"scripts\", not both"
             : "missing: a list of steps: [{\"do\": \"reach\", ...}, ...] (or \"scripts\": a list of them)");
  }
  std::vector<std::pair<const json*, std::string>> scripts;
  if (value.contains("script")) {
    scripts.emplace_back(&value.at("script"), field + ".script");
  } else {
    const json& list = value.at("scripts");
    if (!list.is_array() || list.empty() || list.size() > 100) {
      fail(field + ".scripts", "must be a list of 1 to 100 scripts (each a list of steps), not " + shown(list));
    }
    for (std::size_t i = 0; i < list.size(); ++i) {
      scripts.emplace_back(&list[i], field + ".scripts[" + std::to_string(i) + "]");
    }
  }
  for (const auto& [script, name] : scripts) {
    spec.scripts.push_back(parseScript(*script, name, spec));
  }
  return spec;
}

Eigen::Vector3d elbowPosition(const Eigen::Vector3d& shoulder, const Eigen::Vector3d& wrist) {
  const double a = kUpperArmLength;
  const double b = kForearmLength;
  Eigen::Vector3d axis = wrist - shoulder;
  const double d = std::clamp(axis.norm(), std::abs(a - b) + 1e-3, a + b - 1e-6);
  axis = axis.norm() > 1e-9 ? axis.normalized() : Eigen::Vector3d(0, 0, -1);
  const double along = (a * a - b * b + d * d) / (2.0 * d);
  const double across = std::sqrt(std::max(0.0, a * a - along * along));
  Eigen::Vector3d down = Eigen::Vector3d(0, 0, -1) + axis * axis.z();  // the part of "down" across the axis
  if (down.norm() < 1e-6) {
    down = axis.unitOrthogonal();
  }
  return shoulder + along * axis + across * down.normalized();
}

PersonMotion::PersonMotion(const PersonSpec& spec, std::uint64_t seed, double horizon) : shoulder_(spec.shoulder) {
  std::mt19937_64 random(spec.seed.value_or(seed));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector3d rest = spec.restPosition();
  const Eigen::Vector3d away = spec.awayOffset();
  Eigen::Vector3d offset = spec.starts_away ? away : Eigen::Vector3d::Zero();
  Eigen::Vector3d at = rest + offset;
  bool palm_up = false;
  double closure = 0.0;
  double t = 0.0;
  bool first_pass = true;
  // One of several scripts drawn first (a single script draws nothing: its random reaches are
  // what they were before scripts could be mixed).
  if (spec.scripts.size() > 1) {
    script_index_ = std::uniform_int_distribution<std::size_t>(0, spec.scripts.size() - 1)(random);
  }
  const std::vector<PersonStep>& script = spec.scripts.at(script_index_);
  while (true) {
    for (const PersonStep& step : script) {
      Segment segment;
      segment.start = t;
      segment.from = at;
      segment.to = at;
      segment.palm_up_from = palm_up;
      segment.palm_up_to = palm_up;
      segment.closure_from = closure;
      segment.closure_to = closure;
      segment.offset_from = offset;
      segment.offset_to = offset;
      segment.kind = step.kind;
      double seconds = step.seconds;
      switch (step.kind) {
        case PersonStep::Kind::kReach:
        case PersonStep::Kind::kReachRandom:
        case PersonStep::Kind::kWithdraw: {
          double speed = step.speed;
          Eigen::Vector3d target = step.to;
          if (step.kind == PersonStep::Kind::kWithdraw) {
            target = rest;
          } else if (step.kind == PersonStep::Kind::kReachRandom) {
            for (int i = 0; i < 3; ++i) {
              target[i] = step.box_min[i] + unit(random) * (step.box_max[i] - step.box_min[i]);
            }
            speed *= 0.5 + 0.5 * unit(random);
            const Eigen::Vector3d out = target - spec.shoulder;
            if (out.norm() > kPersonReach) {
              target = spec.shoulder + out * (kPersonReach / out.norm());
            }
            target.z() = std::max(target.z(), kMinHeight);
          }
          // Minimum jerk: the peak speed is 1.875 times the mean.
          const double distance = (target - at).norm();
          // An open hand turns palm down as it goes; a closed one keeps what it holds upright.
          const bool turn = palm_up && closure < 0.5;
          seconds = std::max(1.875 * distance / speed, turn ? kTurnSeconds : 0.05);
          segment.to = target;
          segment.palm_up_to = palm_up && !turn;
          segment.turn_seconds = turn ? kTurnSeconds : 0.0;
          at = target;
          palm_up = segment.palm_up_to;
          break;
        }
        case PersonStep::Kind::kLeave:
        case PersonStep::Kind::kEnter: {
          // The person walks straight away from the table (or back), the hand at rest.
          offset = step.kind == PersonStep::Kind::kLeave ? away : Eigen::Vector3d::Zero();
          segment.offset_to = offset;
          segment.to = rest + offset;
          // As on a reach: an open hand turns palm down as it goes, a closed one keeps what it
          // holds upright (it turned over at once, flinging the part it carried).
          const bool turn = palm_up && closure < 0.5;
          segment.palm_up_to = palm_up && !turn;
          segment.turn_seconds = turn ? kTurnSeconds : 0.0;
          palm_up = segment.palm_up_to;
          const double distance = std::max((segment.to - segment.from).norm(), away.norm());
          seconds = 1.875 * distance / step.speed;
          at = segment.to;
          break;
        }
        case PersonStep::Kind::kGesture:
        case PersonStep::Kind::kTake:
          segment.palm_up_to = true;
          segment.turn_seconds = palm_up ? 0.0 : kTurnSeconds;
          seconds += segment.turn_seconds;
          palm_up = true;
          break;
        case PersonStep::Kind::kClose:
          segment.closure_to = 1.0;
          closure = 1.0;
          break;
        case PersonStep::Kind::kOpen:
          segment.closure_to = 0.0;
          closure = 0.0;
          break;
        case PersonStep::Kind::kWait:
          break;
      }
      segment.end = t + seconds;
      t = segment.end;
      segments_.push_back(segment);
    }
    if (first_pass) {
      duration_ = t;
      first_pass = false;
    }
    if (!spec.repeat || t >= horizon || t <= 0.0) {
      break;
    }
  }
}

PersonPose PersonMotion::at(double t) const {
  PersonPose pose;
  const auto found = std::upper_bound(segments_.begin(), segments_.end(), t,
                                      [](double time, const Segment& segment) { return time < segment.end; });
  const Segment& segment = found == segments_.end() ? segments_.back() : *found;
  const double length = segment.end - segment.start;
  const double s = length > 0.0 ? std::clamp((t - segment.start) / length, 0.0, 1.0) : 1.0;
  const bool moving = segment.from != segment.to;
  pose.wrist = segment.from + minimumJerk(s) * (segment.to - segment.from);
  if (moving && length > 0.0 && found != segments_.end()) {
    pose.velocity = minimumJerkRate(s) / length * (segment.to - segment.from);
  }
  double turned = 1.0;
  if (segment.turn_seconds > 0.0) {
    turned = minimumJerk((t - segment.start) / segment.turn_seconds);
  }
  const Eigen::Vector3d shoulder =
      shoulder_ + segment.offset_from + minimumJerk(s) * (segment.offset_to - segment.offset_from);
  const Eigen::Quaterniond from = handFrame(shoulder, pose.wrist, segment.palm_up_from);
  const Eigen::Quaterniond to = handFrame(shoulder, pose.wrist, segment.palm_up_to);
  pose.hand = from.slerp(turned, to);
  pose.palm_up = turned >= 0.5 ? segment.palm_up_to : segment.palm_up_from;
  pose.closure = segment.closure_from + minimumJerk(s) * (segment.closure_to - segment.closure_from);
  pose.offset = segment.offset_from + minimumJerk(s) * (segment.offset_to - segment.offset_from);
  pose.shoulder = shoulder_ + pose.offset;
  pose.elbow = elbowPosition(pose.shoulder, pose.wrist);
  pose.step = found == segments_.end() ? "done" : stepName(segment.kind);
  pose.offering = found != segments_.end() &&
                  (segment.kind == PersonStep::Kind::kGesture || segment.kind == PersonStep::Kind::kTake) &&
                  turned >= 1.0 && pose.closure < 0.2;
  return pose;
}

PersonMotion::StepAt PersonMotion::stepAt(double t) const {
  const auto found = std::upper_bound(segments_.begin(), segments_.end(), t,
                                      [](double time, const Segment& segment) { return time < segment.end; });
  const Segment& segment = found == segments_.end() ? segments_.back() : *found;
  return {found == segments_.end() ? PersonStep::Kind::kWait : segment.kind, segment.end,
          t >= segment.start + segment.turn_seconds};
}

}  // namespace costar::sim
