#pragma once
// A component's operations as one table of (spec, handler): each operation is declared
// together with the function that starts it, so a declared operation and its implementation
// cannot drift apart (no if-chain on operation names to keep in step with the description).
//
//   class Gripper final : public component::TableComponent {
//     Gripper() {
//       component::ComponentDescription description{.name = "gripper", ...};
//       component::OperationTable operations;
//       operations.add({"Open", "Opens the fingers.", {speed}}, [this](const ParamMap& p) { return open(p); });
//       declare(std::move(description), std::move(operations));
//     }
//   };

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "component/component.h"

namespace costar::component {

class OperationTable {
 public:
  /// Starts the operation with parameters already checked against its spec.
  /// @throws std::exception when it cannot start; the message is the reason.
  using Handler = std::function<std::unique_ptr<RunningOperation>(const ParamMap& params)>;

  /// Declares an operation with its handler.
  /// @throws std::logic_error for an unnamed operation, a name declared twice, or no handler.
  OperationTable& add(OperationSpec spec, Handler handler);

  /// The declared operations, in the order added.
  const std::vector<OperationSpec>& specs() const { return specs_; }
  bool contains(std::string_view operation) const { return handlers_.contains(operation); }

  /// Starts `operation`. @throws std::invalid_argument naming `component` for an operation not
  /// in the table; whatever the handler throws.
  std::unique_ptr<RunningOperation> begin(const std::string& component, const std::string& operation,
                                          const ParamMap& params) const;

 private:
  std::vector<OperationSpec> specs_;
  std::map<std::string, Handler, std::less<>> handlers_;
};

/// A LocalComponent that starts its operations from an OperationTable: the operations its
/// description declares are the table's, and nothing else can add one.
class TableComponent : public LocalComponent {
 public:
  const ComponentDescription& description() const final { return description_; }

 protected:
  /// Sets what the component declares and how it starts its operations, once, at the end of
  /// the subclass's constructor. `description.operations` is filled from the table; when the
  /// description already lists operations they must be exactly the table's, by name.
  /// @throws std::logic_error naming every operation declared without a handler and every
  /// handler of an operation not declared, or when called twice.
  void declare(ComponentDescription description, OperationTable operations);

 private:
  std::unique_ptr<RunningOperation> begin(const std::string& operation, const ParamMap& params) final;

  ComponentDescription description_;
  OperationTable operations_;
  bool declared_ = false;
};

}  // namespace costar::component
