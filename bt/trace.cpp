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

}  // namespace costar::bt
