#include "cli/inject_option.h"

#include "faults/fault.h"

namespace costar::cli {

void addInjectOption(CLI::App* command, std::vector<std::string>& specs) {
  command
      ->add_option("--inject", specs,
                   "break something on purpose (repeatable): " + faults::faultGrammar() +
                       "\n  The cell must end the run as FAILURE with a reason and stop the arm (docs/FAULTS.md).")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            try {
              faults::parseFault(text);
            } catch (const faults::FaultSpecError& e) {
              return e.what();
            }
            return {};
          },
          "KIND:TARGET@WHEN"));
}

}  // namespace costar::cli
