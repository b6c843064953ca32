#include "server/run_controls.h"

namespace costar::server {

void RunControls::request(RunControl control) {
  switch (control) {
    case RunControl::kStop:
      stop_requested_ = true;
      break;
    case RunControl::kPause:
      pause_requested_ = 1;
      break;
    case RunControl::kResume:
      pause_requested_ = -1;
      break;
    case RunControl::kStep:
      ++steps_requested_;
      break;
  }
}

void RunControls::reset(bool paused) {
  stop_requested_ = false;
  pause_requested_ = 0;
  steps_requested_ = 0;
  paused_ = paused;
}

bool RunControls::apply(bt::Executor& executor) {
  if (stop_requested_.exchange(false)) {
    executor.requestStop();
    paused_ = false;
    return true;
  }
  if (const int pause = pause_requested_.exchange(0); pause != 0) {
    paused_ = pause > 0;
  }
  if (steps_requested_.load() > 0) {
    paused_ = true;  // a step while running pauses after it
  }
  return false;
}

bool RunControls::takeStep() {
  if (steps_requested_.load() > 0) {
    --steps_requested_;
    return true;
  }
  return false;
}

}  // namespace costar::server
