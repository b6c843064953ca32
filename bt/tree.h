#pragma once
// A Tree owns the nodes of one instantiated plan, gives each its path and uid, and is the
// root that generates ticks.

#include <memory>
#include <string>
#include <vector>

#include "bt/node.h"

namespace costar::bt {

class Tree {
 public:
  /// Takes ownership of `nodes`, wired already (parents know their children); `root` is one
  /// of them. Paths start with `main_tree_id`.
  /// @throws std::invalid_argument if `root` is null or a reachable node is not in `nodes`.
  Tree(std::string main_tree_id, std::vector<std::unique_ptr<TreeNode>> nodes, TreeNode* root, const Clock& clock);
  Tree(Tree&&) noexcept = default;
  Tree& operator=(Tree&&) noexcept = default;
  ~Tree();

  /// One tick of the root.
  Status tick() { return root_->tick(); }
  /// Halts every RUNNING node (cancelling operations); the tree is IDLE afterwards.
  void halt() { root_->halt(); }
  /// Halts and clears all memory: the tree behaves as freshly built.
  void reset() { root_->reset(); }

  TreeNode& root() const { return *root_; }
  const std::string& mainTreeId() const { return main_tree_id_; }
  TreeContext& context() const { return *context_; }
  /// Every node in pre-order; nodes()[i]->uid() == i.
  const std::vector<TreeNode*>& nodes() const { return preorder_; }

  void addObserver(TreeObserver* observer) { context_->addObserver(observer); }
  void removeObserver(TreeObserver* observer) { context_->removeObserver(observer); }

 private:
  void index(TreeNode* node, const TreeNode* parent, std::string path);

  std::string main_tree_id_;
  std::unique_ptr<TreeContext> context_;
  std::vector<std::unique_ptr<TreeNode>> owned_;
  std::vector<TreeNode*> preorder_;
  TreeNode* root_;
};

}  // namespace costar::bt
