#pragma once
// Reading and writing task plans in BehaviorTree.CPP v4's XML format, so that plans open in
// Groot2 and other tools of that ecosystem:
//
//   <root BTCPP_format="4" main_tree_to_execute="main">
//     <include path="subtrees/grasp.xml"/>
//     <BehaviorTree ID="main">
//       <Sequence name="pick">
//         <SubTree ID="grasp"/>
//         <Move waypoint="home"/>
//       </Sequence>
//     </BehaviorTree>
//   </root>
//
// Both the compact form (<Sequence/>) and the explicit form (<Control ID="Sequence"/>) are
// read; the compact form is written. Comments and <TreeNodesModel> are not kept on read.

#include <filesystem>
#include <string>
#include <string_view>

#include "bt/plan.h"

namespace costar::bt {

class NodeRegistry;

struct LoadOptions {
  /// Follow <include path=...>. When false, an include is an error (for untrusted text).
  bool follow_includes = true;
  /// Folder that relative includes of text (not files) are resolved against.
  std::filesystem::path base_dir = ".";
  /// Largest file read, in bytes.
  std::size_t max_file_bytes = 16u << 20;
};

/// Parses one file's text; includes are recorded, not followed. @throws PlanError
PlanFile parsePlanFile(std::string_view xml, const std::string& label);

/// Loads a plan file and, transitively, the files it includes (each once; a cycle of
/// includes is an error naming the cycle). @throws PlanError naming file and line.
Plan loadPlan(const std::filesystem::path& path, const LoadOptions& options = {});

/// As loadPlan, for text held in memory (e.g. received by the server).
Plan loadPlanText(std::string_view xml, const std::string& label, const LoadOptions& options = {});

struct WriteOptions {
  /// Also write a <TreeNodesModel> of the node types the file uses, for Groot2.
  const NodeRegistry* model_from = nullptr;
};

/// Writes one plan file (its own trees and includes; not the included files).
std::string writePlanFile(const PlanFile& file, const WriteOptions& options = {});

/// Writes the file atomically (temporary file + rename), so a crash never leaves half a plan.
/// @throws std::runtime_error when the file cannot be written.
void savePlanFile(const PlanFile& file, const std::filesystem::path& path, const WriteOptions& options = {});

}  // namespace costar::bt
