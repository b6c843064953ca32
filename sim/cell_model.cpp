#include "sim/cell_model.h"

#include <Eigen/Geometry>
#include <initializer_list>
#include <pugixml.hpp>
#include <sstream>
#include <stdexcept>

namespace costar::sim {

namespace {

constexpr const char* kMergedSections[] = {"default", "asset", "equality", "contact", "tendon", "actuator", "sensor"};

void load(pugi::xml_document& doc, const std::filesystem::path& file, const char* role) {
  const pugi::xml_parse_result result = doc.load_file(file.c_str(), pugi::parse_default | pugi::parse_comments);
  if (!result) {
    throw std::runtime_error("cell model: the " + std::string(role) + " model '" + file.string() +
                             "' cannot be read: " + result.description() + " (at byte " +
                             std::to_string(result.offset) + ")");
  }
  if (!doc.child("mujoco")) {
    throw std::runtime_error("cell model: the " + std::string(role) + " model '" + file.string() +
                             "' is not MJCF (no <mujoco> element)");
  }
}

std::string numbers(std::initializer_list<double> values) {
  std::ostringstream out;
  out.precision(17);
  for (const double value : values) {
    out << (out.tellp() > 0 ? " " : "") << value;
  }
  return out.str();
}

/// The cell's section `name`, made (at the end) when it has none.
pugi::xml_node section(pugi::xml_node cell, const char* name) {
  pugi::xml_node found = cell.child(name);
  return found ? found : cell.append_child(name);
}

void mergeSections(pugi::xml_node cell, pugi::xml_node piece) {
  for (const char* name : kMergedSections) {
    for (const pugi::xml_node from : piece.children(name)) {
      pugi::xml_node to = section(cell, name);
      for (const pugi::xml_node child : from.children()) {
        to.append_copy(child);
      }
    }
  }
}

pugi::xml_node findBody(pugi::xml_node root, const std::string& name) {
  return root.find_node([&name](const pugi::xml_node& node) {
    return std::string(node.name()) == "body" && name == node.attribute("name").value();
  });
}

}  // namespace

std::string composeCellModel(const CellModelPieces& pieces) {
  pugi::xml_document cell_doc;
  pugi::xml_document robot_doc;
  pugi::xml_document gripper_doc;
  load(cell_doc, pieces.cell, "cell");
  load(robot_doc, pieces.robot, "robot");
  load(gripper_doc, pieces.gripper, "gripper");
  pugi::xml_node cell = cell_doc.child("mujoco");
  const pugi::xml_node robot = robot_doc.child("mujoco");
  const pugi::xml_node gripper = gripper_doc.child("mujoco");

  // Textures and meshes named in the pieces are files beside the cell model.
  pugi::xml_node compiler = section(cell, "compiler");
  const std::string folder = pieces.cell.parent_path().string();
  for (const char* key : {"texturedir", "meshdir"}) {
    (compiler.attribute(key) ? compiler.attribute(key) : compiler.append_attribute(key)).set_value(folder.c_str());
  }

  pugi::xml_node worldbody = cell.child("worldbody");
  pugi::xml_node marker = worldbody.find_child([](const pugi::xml_node& node) {
    return node.type() == pugi::node_comment && std::string(node.value()) == "ROBOT";
  });
  if (!marker) {
    throw std::runtime_error("cell model '" + pieces.cell.string() + "': its <worldbody> has no <!--ROBOT--> marker");
  }
  for (const pugi::xml_node child : robot.child("worldbody").children()) {
    if (child.type() != pugi::node_element) {
      continue;
    }
    pugi::xml_node copy = worldbody.insert_copy_before(child, marker);
    if (pieces.robot_base && std::string(copy.name()) == "body" && !copy.attribute("pos") && !copy.attribute("quat")) {
      const Eigen::Vector3d& p = pieces.robot_base->translation();
      const Eigen::Quaterniond q(pieces.robot_base->linear());
      copy.append_attribute("pos").set_value(numbers({p.x(), p.y(), p.z()}).c_str());
      copy.append_attribute("quat").set_value(numbers({q.w(), q.x(), q.y(), q.z()}).c_str());
    }
  }
  worldbody.remove_child(marker);
  mergeSections(cell, robot);

  pugi::xml_node flange = findBody(worldbody, pieces.flange_body);
  if (!flange) {
    throw std::runtime_error("robot model '" + pieces.robot.string() + "': no body '" + pieces.flange_body +
                             "' (the flange the gripper is mounted on)");
  }
  const pugi::xml_node mount = gripper.child("worldbody").find_child_by_attribute("body", "name", "mount");
  if (!mount) {
    throw std::runtime_error("gripper model '" + pieces.gripper.string() +
                             "': its <worldbody> needs a body \"mount\" (the flange) holding the gripper");
  }
  for (const pugi::xml_node child : mount.children()) {
    if (child.type() == pugi::node_element) {
      flange.append_copy(child);
    }
  }
  mergeSections(cell, gripper);
  if (!pieces.force_torque_site.empty()) {
    pugi::xml_node site = flange.prepend_child("site");
    site.append_attribute("name").set_value(pieces.force_torque_site.c_str());
    site.append_attribute("size").set_value("0.005");
    site.append_attribute("group").set_value("5");
    pugi::xml_node sensors = section(cell, "sensor");
    pugi::xml_node force = sensors.append_child("force");
    force.append_attribute("name").set_value(pieces.force_sensor.c_str());
    force.append_attribute("site").set_value(pieces.force_torque_site.c_str());
    pugi::xml_node torque = sensors.append_child("torque");
    torque.append_attribute("name").set_value(pieces.torque_sensor.c_str());
    torque.append_attribute("site").set_value(pieces.force_torque_site.c_str());
  }

  std::ostringstream out;
  cell_doc.save(out, "  ");
  return out.str();
}

double modelTimestep(const std::string& mjcf) {
  pugi::xml_document doc;
  if (!doc.load_string(mjcf.c_str())) {
    throw std::runtime_error("the workcell model is not XML");
  }
  const pugi::xml_attribute timestep = doc.child("mujoco").child("option").attribute("timestep");
  if (!timestep) {
    return 0.002;
  }
  const double value = timestep.as_double(-1.0);
  if (!(value > 0.0 && value < 1.0)) {
    throw std::runtime_error(std::string("the workcell model's <option timestep=\"") + timestep.value() +
                             "\"> is not a time step in seconds");
  }
  return value;
}

}  // namespace costar::sim
