// The simulated cell's views: the RGB-D camera's point cloud (in the world frame) and, for
// end-to-end tests only, the simulator's true state.

#include "server/engine_parts.h"

#include "sim/power_tool.h"
#include "sim/simulation.h"
#include "workcell/workcell.h"

namespace costar::server {

std::optional<json> Engine::groundTruth() {
  return call([this]() -> std::optional<json> {
    sim::Simulation* simulation = cell_->simulation();
    if (simulation == nullptr) {
      return std::nullopt;
    }
    json parts = json::array();
    for (const sim::PartState& part : simulation->parts()) {
      json item = poseJson(part.pose);
      item["name"] = part.name;
      item["class"] = part.object_class;
      item["color"] = part.color;  // the material's name in the class file
      parts.push_back(std::move(item));
    }
    json truth = {{"TEST_ONLY", "the simulator's true state; never used by plans"},
                  {"t", toSeconds(simulation->time())},
                  {"parts", std::move(parts)},
                  {"tcp", poseJson(simulation->tcpPose())},
                  {"arm_table_contact_steps", simulation->armTableContactSteps()}};
    if (simulation->adaptiveGripper() == nullptr) {  // a 2-finger gripper: its opening
      truth["finger_opening"] = simulation->fingers().opening;
    }
    if (const sim::SimPowerTool* tool = simulation->powerTool(); tool != nullptr && tool->hasTool()) {
      const tool::PowerToolReading reading = tool->read();
      json power_tool = poseJson(tool->toolPose());
      power_tool["powered"] = reading.powered;
      power_tool["speed"] = reading.speed;
      power_tool["held"] = reading.held;
      power_tool["docked"] = reading.docked;
      power_tool["arm_workpiece_steps"] = tool->armWorkpieceSteps();
      if (tool->coverage()) {  // the marked area's fraction worked (texels worked 0.05 s or more)
        power_tool["coverage"] = tool->coverage()->fraction();
      }
      truth["power_tool"] = std::move(power_tool);
    }
    // With a person in the scene: what the speed and separation judge recorded (docs/PERSON.md).
    if (const std::optional<sim::SeparationRecord> record = simulation->separationRecord()) {
      truth["separation"] = {
          {"violation_steps", record->violation_steps},       {"contact_steps", record->contact_steps},
          {"hand_contact_steps", record->hand_contact_steps}, {"min_separation_fast", record->min_separation_fast},
          {"collaborative_s", record->collaborative_seconds}, {"stops", record->stops}};
    }
    if (const std::optional<sim::JigState> jig = simulation->jig(); jig && jig->has_wire) {
      json bends = json::array();
      for (const sim::MeasuredBend& bend : jig->bends) {
        bends.push_back({{"target_deg", bend.target_deg},
                         {"angle_deg", bend.angle_deg},
                         {"out_of_plane_deg", bend.out_of_plane_deg}});
      }
      double slipped = 0.0;
      for (const sim::PinState& pin : jig->pins) {
        slipped = std::max(slipped, pin.slipped);
      }
      truth["wire"] = {{"bends", std::move(bends)},      {"speed", jig->wire_speed},
                       {"held", jig->grip.held},         {"holds", jig->grip.holds},
                       {"releases", jig->grip.releases}, {"pulled_out", jig->grip.pulled_out},
                       {"max_slip", jig->grip.max_slip}, {"pin_slipped", slipped}};
    }
    return truth;
  });
}

std::optional<json> Engine::pointCloud(std::size_t max_points) {
  return call([this, max_points]() -> std::optional<json> {
    sim::Simulation* simulation = cell_->simulation();
    if (simulation == nullptr) {
      return std::nullopt;
    }
    static std::uint64_t noise_seed = 1;
    const camera::RgbdFrame frame = simulation->captureRgbd(noise_seed++);
    const std::size_t valid = frame.validCount();
    const std::size_t stride =
        std::max<std::size_t>(1, (valid + max_points - 1) / std::max<std::size_t>(1, max_points));
    json points = json::array();
    json colors = json::array();
    std::size_t seen = 0;
    for (int v = 0; v < frame.intrinsics.height; ++v) {
      for (int u = 0; u < frame.intrinsics.width; ++u) {
        if (!frame.valid(u, v) || (seen++ % stride) != 0) {
          continue;
        }
        const Eigen::Vector3d p = frame.camera_pose * frame.point(u, v).cast<double>();
        points.push_back(rounded(p.x(), 1e4));
        points.push_back(rounded(p.y(), 1e4));
        points.push_back(rounded(p.z(), 1e4));
        if (frame.rgb.width == frame.intrinsics.width && frame.rgb.height == frame.intrinsics.height) {
          const std::uint8_t* rgb = frame.rgb.at(u, v);
          colors.push_back(rgb[0]);
          colors.push_back(rgb[1]);
          colors.push_back(rgb[2]);
        }
      }
    }
    return json{{"frame", "world"},
                {"camera", poseJson(frame.camera_pose)},
                {"t", toSeconds(frame.stamp)},
                {"points", std::move(points)},
                {"colors", std::move(colors)}};
  });
}

}  // namespace costar::server
