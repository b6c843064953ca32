#include "bt/node.h"

#include <algorithm>

namespace costar::bt {

const char* toString(Status status) {
  switch (status) {
    case Status::kIdle:
      return "IDLE";
    case Status::kRunning:
      return "RUNNING";
    case Status::kSuccess:
      return "SUCCESS";
    case Status::kFailure:
      return "FAILURE";
    case Status::kSkipped:
      return "SKIPPED";
  }
  return "?";
}

void TreeContext::addObserver(TreeObserver* observer) {
  if (std::find(observers_.begin(), observers_.end(), observer) == observers_.end()) {
    observers_.push_back(observer);
  }
}

void TreeContext::removeObserver(TreeObserver* observer) { std::erase(observers_, observer); }

void TreeContext::notify(const TreeNode& node, Status from, Status to) {
  const TimePoint time = now();
  for (TreeObserver* observer : observers_) {
    observer->onTransition(time, node, from, to);
  }
}

TreeNode::TreeNode(std::string id, std::string name) : id_(std::move(id)), name_(std::move(name)) {}

Status TreeNode::tick() {
  context_->countNodeTick();
  const Status status = onTick();
  setStatus(status == Status::kSkipped ? Status::kIdle : status);  // a skipped node did not run
  return status;
}

void TreeNode::halt() {
  if (status_ == Status::kRunning) {
    onHalt();
  }
  setStatus(Status::kIdle);
}

void TreeNode::reset() {
  halt();
  onReset();
  for (TreeNode* child : children()) {
    child->reset();
  }
}

Status TreeNode::fail(std::string_view reason) {
  reason_.assign(reason);
  reason_view_ = reason_;
  failure_origin_ = this;
  return Status::kFailure;
}

Status TreeNode::failFrom(const TreeNode& child) {
  failure_origin_ = child.failure_origin_;
  return Status::kFailure;
}

void TreeNode::setStatus(Status status) {
  if (status == status_) {
    return;
  }
  const Status from = status_;
  status_ = status;
  if (context_ != nullptr && context_->observed()) {
    context_->notify(*this, from, status);
  }
}

std::string TreeNode::pathSegment(std::size_t index_in_parent) const {
  if (!name_.empty()) {
    return id_ + " \"" + name_ + "\"";
  }
  return id_ + "[" + std::to_string(index_in_parent + 1) + "]";
}

void ControlNode::haltChildren(std::size_t first) {
  for (std::size_t i = first; i < children_.size(); ++i) {
    children_[i]->halt();
  }
}

}  // namespace costar::bt
