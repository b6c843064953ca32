#include "faults/fault.h"

#include <gtest/gtest.h>

namespace costar::faults {
namespace {

TEST(FaultSpec, ParsesEveryMoment) {
  const FaultSpec timed = parseFault("nan:arm-driver@t=2.5s");
  EXPECT_EQ(timed.kind, FaultKind::kNan);
  EXPECT_EQ(timed.target, "arm-driver");
  EXPECT_EQ(timed.when.type, FaultWhen::Type::kTime);
  EXPECT_DOUBLE_EQ(timed.when.seconds, 2.5);
  EXPECT_EQ(timed.text, "nan:arm-driver@t=2.5s");

  const FaultSpec op = parseFault("hang:perception@op=3");
  EXPECT_EQ(op.kind, FaultKind::kHang);
  EXPECT_EQ(op.target, "perception");
  EXPECT_EQ(op.when.type, FaultWhen::Type::kOperation);
  EXPECT_EQ(op.when.operation, 3);

  const FaultSpec random = parseFault("empty-frame:camera@random");
  EXPECT_EQ(random.kind, FaultKind::kEmptyFrame);
  EXPECT_EQ(random.when.type, FaultWhen::Type::kRandom);
  EXPECT_DOUBLE_EQ(random.when.seconds, 10.0);
  EXPECT_DOUBLE_EQ(parseFault("die:smartmove@random=4s").when.seconds, 4.0);
  EXPECT_DOUBLE_EQ(parseFault("throw:gripper@t=0").when.seconds, 0.0);
}

void expectError(const std::string& spec, const std::string& words) {
  try {
    parseFault(spec);
    ADD_FAILURE() << spec << " was accepted";
  } catch (const FaultSpecError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'" + spec + "'"), std::string::npos) << message;
    EXPECT_NE(message.find(words), std::string::npos) << message;
  }
}

TEST(FaultSpec, RefusesBadSpecsNamingThePart) {
  expectError("nan:arm-driver", "KIND:TARGET@WHEN");
  expectError("arm-driver@t=1", "KIND:TARGET@WHEN");
  expectError("melt:arm@t=1", "unknown kind 'melt'");
  expectError("nan:@t=1", "no target");
  expectError("nan:perception@t=1", "cannot have a 'nan' fault");
  expectError("die:camera@t=1", "cannot have a 'die' fault");
  expectError("empty-frame:arm-driver@t=1", "cannot have a 'empty-frame' fault");
  expectError("throw:arm@t=-1", "t= needs a time");
  expectError("throw:arm@t=abc", "t= needs a time");
  expectError("throw:arm@op=0", "op= needs a whole number");
  expectError("throw:arm@op=1.5", "op= needs a whole number");
  expectError("throw:arm@random=0s", "random= needs a window");
  expectError("throw:arm@soon", "unknown moment 'soon'");
}

// Issue 27: t=1e10s overflowed the clock's nanoseconds and took effect at once ("due at
// -9223372036.855 s"); nan and inf are refused too.
TEST(FaultSpec, AMomentBeyondTheClocksRangeIsRefused) {
  for (const char* spec :
       {"nan:arm-driver@t=1e10s", "nan:arm-driver@t=nan", "nan:arm-driver@t=inf", "nan:arm-driver@t=1e308"}) {
    expectError(spec, "t= needs a time in seconds from 0 to 1e9");
  }
  expectError("die:arm@random=1e10s", "random= needs a window in seconds above 0 and at most 1e9");
  EXPECT_EQ(parseFault("nan:arm-driver@t=1e9s").when.seconds, 1e9);
  try {
    parseFault("nan:arm-driver@t=" + std::string(400, '9'));
    ADD_FAILURE() << "400 digits accepted";
  } catch (const FaultSpecError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("fault 'nan:arm-driver@t=" + std::string(40, '9') + "...': t= needs", 0), 0u)
        << e.what();
  }
}

}  // namespace
}  // namespace costar::faults
