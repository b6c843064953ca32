#pragma once
// Fault injection: what can break in a robot cell, and when. A fault spec reads
//   KIND:TARGET@WHEN
// e.g. "nan:arm-driver@t=2.5s", "hang:perception@op=1", "die:smartmove@random=8s".
//
//   TARGET  arm-driver, gripper-driver  the drivers' readings (joint encoders, finger sensors)
//           camera                      the RGB-D camera's frames
//           any component's name        arm, gripper, perception, smartmove, predicator, ...
//   KIND    drivers:    throw (reads fail), hang (readings stop updating), nan (readings are NaN)
//           camera:     throw (capture fails), hang (the same old frame again),
//                       empty-frame (no pixels), nan-frame (every depth NaN),
//                       drop-frame (one frame comes empty, once: a frame lost on the way)
//           components: throw (its next start or poll throws, once),
//                       hang (stops answering: every call gets no answer in time),
//                       die (its process is gone: every call fails)
//   WHEN    t=SECONDS[s]   at that clock time (simulated in a simulated cell)
//           op=N           at the target's Nth call: a component's Nth start, a driver's Nth
//                          command, the camera's Nth frame
//           random[=MAXs]  at a time drawn uniformly in [0, MAX) (default 10 s) from the seed
//
// Faults other than a component's throw and a camera's drop-frame last: a broken device stays broken. The injector
// (faults/injector.h) breaks things; what keeps the cell safe is on the receiving side
// (docs/FAULTS.md).

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace costar::faults {

enum class FaultKind { kThrow, kHang, kNan, kEmptyFrame, kNanFrame, kDie, kDropFrame };
const char* toString(FaultKind kind);

/// What a target is, which decides the kinds it accepts.
enum class TargetType { kArmDriver, kGripperDriver, kCamera, kComponent };
TargetType targetType(std::string_view target);

struct FaultWhen {
  enum class Type { kTime, kOperation, kRandom };
  Type type = Type::kTime;
  double seconds = 0.0;  // kTime: the time; kRandom: the window's end
  int operation = 1;     // kOperation: 1-based
};

struct FaultSpec {
  FaultKind kind = FaultKind::kThrow;
  std::string target;
  FaultWhen when;
  /// The spec as written.
  std::string text;
};

/// A spec that cannot be parsed: the message names the spec, the part and the problem.
class FaultSpecError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Parses "KIND:TARGET@WHEN". @throws FaultSpecError.
FaultSpec parseFault(std::string_view text);

/// The grammar in a few lines, for --help and error messages.
std::string faultGrammar();

/// The exception a component that stopped answering gives: the caller's call timed out.
class NoAnswer : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace costar::faults
