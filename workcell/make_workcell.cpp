// makeWorkcell: the light cells from costar_workcell_base, the robot cells from here.

#include "workcell/ur5_sim_workcell.h"
#include "workcell/workcell.h"

namespace costar::workcell {

std::unique_ptr<Workcell> makeWorkcell(const WorkcellOptions& options) {
  if (auto cell = makeLightWorkcell(options)) {
    return cell;
  }
  return makeUr5SimWorkcell(options);  // the one robot cell makeLightWorkcell knows by name
}

}  // namespace costar::workcell
