#include "bt/tree.h"

#include <stdexcept>
#include <unordered_set>

namespace costar::bt {

Tree::Tree(std::string main_tree_id, std::vector<std::unique_ptr<TreeNode>> nodes, TreeNode* root, const Clock& clock)
    : main_tree_id_(std::move(main_tree_id)),
      context_(std::make_unique<TreeContext>(clock)),
      owned_(std::move(nodes)),
      root_(root) {
  if (root_ == nullptr) {
    throw std::invalid_argument("Tree: no root node");
  }
  preorder_.reserve(owned_.size());
  index(root_, nullptr, main_tree_id_ + "/" + root_->pathSegment(0));
  std::unordered_set<const TreeNode*> owned;
  for (const auto& node : owned_) {
    owned.insert(node.get());
  }
  for (const TreeNode* node : preorder_) {
    if (!owned.contains(node)) {
      throw std::invalid_argument("Tree: node " + node->path() + " is not owned by the tree");
    }
  }
}

Tree::~Tree() {
  // Stop running operations before the nodes that hold them go away. Observers hear nothing of
  // it: a tree is often destroyed after them (the halts of a run are reported by halt()).
  if (context_ != nullptr) {  // null when moved from
    context_->removeAllObservers();
  }
  if (root_ != nullptr && owned_.size() > 0) {
    root_->halt();
  }
}

void Tree::index(TreeNode* node, const TreeNode* parent, std::string path) {
  node->uid_ = static_cast<std::uint32_t>(preorder_.size());
  node->parent_ = parent;
  node->context_ = context_.get();
  node->path_ = std::move(path);
  preorder_.push_back(node);
  const auto children = node->children();
  for (std::size_t i = 0; i < children.size(); ++i) {
    index(children[i], node, node->path_ + "/" + children[i]->pathSegment(i));
  }
}

}  // namespace costar::bt
