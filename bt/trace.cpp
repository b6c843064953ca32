#include "bt/trace.h"

#include <nlohmann/json.hpp>

namespace costar::bt {

void JsonLinesTrace::onTransition(TimePoint time, const TreeNode& node, Status from, Status to) {
  nlohmann::json line = {{"t", toSeconds(time)}, {"uid", node.uid()},      {"path", node.path()},
                         {"node", node.id()},    {"from", toString(from)}, {"to", toString(to)}};
  if (to == Status::kFailure) {
    line["reason"] = std::string(node.failureReason());
    line["origin"] = node.failureOrigin().path();
  }
  out_ << line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << '\n';
}

JsonLinesFileTrace::JsonLinesFileTrace(std::filesystem::path file)
    : file_(std::move(file), AppendingFile::Mode::kTruncate) {}

void JsonLinesFileTrace::onTransition(TimePoint time, const TreeNode& node, Status from, Status to) {
  lines_.onTransition(time, node, from, to);
  pending_ = true;
}

void JsonLinesFileTrace::flush() {
  if (!pending_) {
    return;
  }
  pending_ = false;
  const std::string text = buffer_.str();
  buffer_.str({});
  if (!error_.empty()) {
    return;
  }
  try {
    file_.append(text);
  } catch (const std::exception& e) {
    error_ = e.what();
  }
}

void JsonLinesFileTrace::close() {
  flush();
  if (!error_.empty()) {
    return;
  }
  try {
    file_.close();
  } catch (const std::exception& e) {
    error_ = e.what();
  }
}

}  // namespace costar::bt
