#include "smartmove/script.h"

namespace costar::smartmove {

using component::OperationResult;
using component::OperationState;

Script::Script(std::vector<Step> steps, nlohmann::json data) : steps_(std::move(steps)), data_(std::move(data)) {}

void Script::backOff(std::size_t from, std::size_t to, std::vector<Step> backing_off, std::string done_note) {
  back_off_from_ = from;
  back_off_to_ = to;
  back_off_ = std::move(backing_off);
  back_off_note_ = std::move(done_note);
}

OperationResult Script::poll() {
  while (next_ < steps_.size() || current_) {
    if (!current_) {
      try {
        current_ = steps_[next_].start();
      } catch (const std::exception& e) {
        // A step that could not even start (a component that threw, a broken driver) is a
        // fault, not a miss: reported at once, without backing off (the arm stays at rest),
        // as when a poll throws.
        return fail(steps_[next_].what + ": " + e.what(), /*may_back_off=*/false);
      }
    }
    OperationResult result = current_->poll();
    if (result.state == OperationState::kRunning) {
      return OperationResult::running();
    }
    current_.reset();
    const Step& step = steps_[next_++];
    if (result.state == OperationState::kFailure && step.may_fail) {
      notes_ += "; " + step.what + " failed (" + result.reason + ")";
      continue;
    }
    if (result.state == OperationState::kFailure) {
      return fail(step.what + ": " + result.reason);
    }
    if (step.check) {
      if (const std::string problem = step.check(result); !problem.empty()) {
        return fail(step.what + ": " + problem);
      }
    }
  }
  return finish(OperationResult::success(data_));
}

void Script::cancel() {
  if (current_) {
    current_->cancel();
    current_.reset();
  }
}

OperationResult Script::fail(std::string reason, bool may_back_off) {
  const std::size_t failed_step = next_ - 1;  // poll() has moved past it
  if (may_back_off && !failure_ && next_ > 0 && failed_step >= back_off_from_ && failed_step <= back_off_to_ &&
      !back_off_.empty()) {
    failure_ = std::move(reason);
    steps_ = std::move(back_off_);
    back_off_.clear();
    next_ = 0;
    return poll();
  }
  if (failure_) {  // backing off failed too: both reasons
    return finish(OperationResult::failure(*failure_ + "; backing off, " + reason, data_));
  }
  return finish(OperationResult::failure(std::move(reason), data_));
}

OperationResult Script::finish(OperationResult result) {
  if (failure_ && result.state == OperationState::kSuccess) {
    result = OperationResult::failure(*failure_ + " (" + back_off_note_ + notes_ + ")", data_);
  }
  return result;
}

std::optional<std::string> parsePredicates(const component::ParamMap& params,
                                           std::vector<predicator::Pattern>& patterns) {
  try {
    patterns = predicator::parsePredicateList(params.at("predicates").asString());
  } catch (const std::invalid_argument& e) {
    return std::string("predicates: ") + e.what();
  }
  return std::nullopt;
}

std::unique_ptr<component::RunningOperation> failed(std::string reason, nlohmann::json data) {
  return std::make_unique<component::FinishedOperation>(OperationResult::failure(std::move(reason), std::move(data)));
}

component::ParamMap declaredDefaults(const component::Component& component, const std::string& operation) {
  component::ParamMap params;
  if (const component::OperationSpec* spec = component.description().operation(operation)) {
    for (const component::ParamSpec& param : spec->params) {
      if (param.default_value) {
        params[param.name] = *param.default_value;
      }
    }
  }
  return params;
}

}  // namespace costar::smartmove
