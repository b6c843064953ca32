#include "dds/report_json.h"

#include <gtest/gtest.h>

namespace costar::dds {
namespace {

TEST(ReportJson, EverySymbolKindAndPredicateReadsBackEqual) {
  world::Report report;
  world::Symbol frame{"part_1", "perception", TimePoint(Duration(123456789)),
                      world::FrameValue{"world", world::poseFromXyzRpy(0.1, -0.2, 0.3, 0.4, 0.5, 0.6)},
                      Eigen::Vector3d(0.1, 0.7, 0.3)};
  report.symbols.push_back(frame);
  report.symbols.push_back({"joints", "arm", {}, world::JointsValue{{"a", "b"}, {0.5, -1.0 / 3.0}}, std::nullopt});
  report.symbols.push_back({"node", "perception", {}, world::ObjectClassValue{"a node"}, std::nullopt});
  report.symbols.push_back({"wrench", "arm", {}, world::WrenchValue{"tool", {1, 2, 3}, {4, 5, 6}}, std::nullopt});
  report.symbols.push_back({"speed", "tool", {}, world::NumberValue{1200.5, "rpm"}, std::nullopt});
  report.predicates.push_back({"is_a", {"part_1", "node"}, true, "perception"});
  report.predicates.push_back({"gripper_open", {}, false, "gripper"});

  const world::Report back = reportFromJson(nlohmann::json::parse(toJson(report).dump()));
  ASSERT_EQ(back.symbols.size(), report.symbols.size());
  EXPECT_EQ(back.symbols[0].stamp, frame.stamp);
  EXPECT_EQ(back.symbols[0].frame()->pose.matrix(), frame.frame()->pose.matrix());  // to the bit
  EXPECT_EQ(*back.symbols[0].color, *frame.color);
  EXPECT_EQ(back.symbols[1].joints()->positions, report.symbols[1].joints()->positions);
  EXPECT_EQ(back.symbols[2].kind(), world::SymbolKind::kObjectClass);
  EXPECT_EQ(back.symbols[3].wrench()->torque, Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(back.symbols[4].number()->unit, "rpm");
  ASSERT_EQ(back.predicates.size(), 2u);
  EXPECT_EQ(back.predicates[0].str(), "is_a(part_1,node)");
  EXPECT_FALSE(back.predicates[1].value);
}

TEST(ReportJson, ABadSymbolIsNamed) {
  nlohmann::json json = {{"symbols",
                          {{{"name", "p"},
                            {"source", "s"},
                            {"stamp_ns", 0},
                            {"kind", "frame"},
                            {"parent", "world"},
                            {"pose", {1, 2, 3}}}}},
                         {"predicates", nlohmann::json::array()}};
  try {
    reportFromJson(json);
    FAIL() << "a 3-number pose was read";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("symbols[0] ('p'): a pose is 12 numbers"), std::string::npos)
        << error.what();
  }
  json["symbols"][0]["kind"] = "colour";
  EXPECT_THROW(reportFromJson(json), std::invalid_argument);
}

}  // namespace
}  // namespace costar::dds
