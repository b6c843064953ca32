"""The models of a parallel 2-finger gripper (description "kind": "parallel", robots/README.md):
read by robots/generate_gripper.py, which writes NAME_mount.xml (the workcell's gripper piece,
sim/cell_model.h) and NAME.urdf (the planner's, planning::mountUrdf).

The simulator finds the fingers by these names: joints left_finger_joint and right_finger_joint
(slides along +y and -y, coupled by an equality), pads left_pad and right_pad, the position
servo "fingers" on the left joint (its control range is half the stroke: the opening is twice
it). Geoms are in explicit classes, as the robot's bodies may carry a childclass."""
from description_reader import MARKER_ASSET, MARKER_HALF, fmt, marker_geom

MAX_M = 1.0
MAX_KG = 100.0


def _box(reader, obj, key, field, mass=True):
    where = f"{field}.{key}" if field else key
    box = reader.get(obj, key, field, "object")
    entry = {"size": reader.get(box, "size", where, "vec3", positive=True, at_most=MAX_M),
             "centre": reader.get(box, "centre", where, "vec3", at_most=MAX_M)}
    if mass:
        entry["mass"] = reader.get(box, "mass", where, "number", positive=True, at_most=MAX_KG)
    return entry


def read_parallel(reader, root, name):
    g = {"name": name, "kind": "parallel"}
    if not name.replace("_", "").replace("-", "").isalnum():
        reader.fail("name", "must be letters, digits, underscores and hyphens")
    coupling = root.get("coupling")
    if coupling is not None:
        g["coupling"] = {"radius": reader.get(coupling, "radius", "coupling", "number", positive=True, at_most=MAX_M),
                         "from_z": reader.get(coupling, "from_z", "coupling", "number", at_most=MAX_M),
                         "to_z": reader.get(coupling, "to_z", "coupling", "number", at_most=MAX_M)}
        if not g["coupling"]["from_z"] < g["coupling"]["to_z"]:
            reader.fail("coupling", "from_z must be below to_z")
    g["body"] = _box(reader, root, "body", "")
    g["tcp"] = reader.get(root, "tcp", "", "vec3", at_most=MAX_M)
    g["stroke"] = reader.get(root, "stroke_m", "", "number", positive=True, at_most=0.5)
    finger = reader.get(root, "finger", "", "object")
    g["link"] = _box(reader, finger, "link", "finger")
    g["pad"] = _box(reader, finger, "pad", "finger")
    friction = reader.get(finger["pad"], "friction", "finger.pad", "vec3", positive=True, at_most=10.0)
    g["pad"]["friction"] = friction
    for part in ("link", "pad"):
        if g[part]["centre"][1] - g[part]["size"][1] / 2 < -1e-9:
            reader.fail(f"finger.{part}", "the +y finger's box must lie at y >= 0 when closed (its mirror is the other finger)")
    if abs(g["pad"]["centre"][1] - g["pad"]["size"][1] / 2) > 1e-9:
        reader.fail("finger.pad", "the closed pad's inner face must be on y = 0 (centre.y = size.y / 2)")
    servo = reader.get(root, "servo", "", "object")
    g["servo"] = {key: reader.get(servo, key, "servo", "number", positive=True)
                  for key in ("kp", "force_n", "damping", "armature")}
    force = reader.get(root, "grip_force_n", "", "object")
    g["grip"] = {key: reader.get(force, key, "grip_force_n", "number", positive=True) for key in ("default", "max")}
    if g["grip"]["default"] > g["grip"]["max"]:
        reader.fail("grip_force_n.default", "must be at most grip_force_n.max")
    g["grasps"] = reader.get(root, "grasps", "", "string")
    half = [s / 2 for s in g["body"]["size"]]
    if min(half[1], half[2]) < MARKER_HALF:
        reader.fail("body.size", "the body's +x face must hold the 6.67 cm calibration marker (y and z at least 0.0667 m)")
    return g


def _finger(side, g):
    sign = 1 if side == "left" else -1
    link, pad = g["link"], g["pad"]
    half_stroke = g["stroke"] / 2
    s = g["servo"]

    def at(centre):
        return [centre[0], sign * centre[1], centre[2]]

    return [f'<body name="{side}_finger" pos="0 0 0">',
            f'  <joint name="{side}_finger_joint" type="slide" axis="0 {sign} 0" range="0 {half_stroke:.12g}" '
            f'damping="{s["damping"]:.12g}" armature="{s["armature"]:.12g}"/>',
            f'  <geom name="{side}_finger" class="gripper" type="box" pos="{fmt(at(link["centre"]))}" '
            f'size="{fmt(x / 2 for x in link["size"])}" mass="{link["mass"]:.12g}"/>',
            f'  <geom name="{side}_pad" class="finger_pad" type="box" pos="{fmt(at(pad["centre"]))}" '
            f'size="{fmt(x / 2 for x in pad["size"])}" mass="{pad["mass"]:.12g}"/>',
            '</body>']


def parallel_mount_xml(g):
    """The gripper piece of a workcell model: body "mount" is the flange."""
    body = g["body"]
    face = [body["centre"][0] + body["size"][0] / 2, body["centre"][1], body["centre"][2]]
    s = g["servo"]
    lines = ['<compiler angle="radian" autolimits="true"/>',
             '<default>',
             '  <default class="gripper">',
             '    <geom contype="2" conaffinity="0" rgba="0.2 0.25 0.33 1" group="1"/>',
             '  </default>',
             '  <default class="gripper_visual"/>',
             '  <default class="finger_pad">',
             f'    <geom contype="2" conaffinity="0" condim="4" friction="{fmt(g["pad"]["friction"])}" solref="0.004 1" '
             'rgba="0.15 0.15 0.15 1"/>',
             '  </default>',
             '</default>'] + MARKER_ASSET + [
             '<worldbody>',
             '  <body name="mount">',
             f'    <site name="tcp" class="gripper_visual" pos="{fmt(g["tcp"])}" size="0.004" rgba="1 0.5 0 0.6"/>']
    if "coupling" in g:
        c = g["coupling"]
        lines.append(f'    <geom name="gripper_coupling" class="gripper" type="cylinder" fromto="0 0 {c["from_z"]:.12g} '
                     f'0 0 {c["to_z"]:.12g}" size="{c["radius"]:.12g}"/>')
    lines += [f'    <geom name="gripper_body" class="gripper" type="box" pos="{fmt(body["centre"])}" '
              f'size="{fmt(x / 2 for x in body["size"])}" mass="{body["mass"]:.12g}"/>',
              '    ' + marker_geom(face, "gripper_visual")]
    lines += ["    " + line for line in _finger("left", g) + _finger("right", g)]
    lines += ['  </body>',
              '</worldbody>',
              '<equality>',
              '  <joint name="finger_coupling" joint1="right_finger_joint" joint2="left_finger_joint" polycoef="0 1 0 0 0" '
              'solref="0.004 1"/>',
              '</equality>',
              '<actuator>',
              f'  <position name="fingers" joint="left_finger_joint" kp="{s["kp"]:.12g}" ctrlrange="0 {g["stroke"] / 2:.12g}" '
              f'forcerange="-{s["force_n"]:.12g} {s["force_n"]:.12g}"/>',
              '</actuator>']
    return lines


def parallel_urdf(g, source):
    """The planner's gripper: the coupling and body on the flange, one box over the fingers' whole
    travel (a collision world that knows the opening puts the fingers where they are,
    gripper/finger_geometry.h), the tool centre point."""
    n = g["name"]
    body, link, pad = g["body"], g["link"], g["pad"]
    # The fingers' travel: the link's width, from the fully open outer faces, from the lowest to
    # the highest of the link and pad.
    outer = max(link["centre"][1] + link["size"][1] / 2, pad["centre"][1] + pad["size"][1] / 2)
    low = min(link["centre"][2] - link["size"][2] / 2, pad["centre"][2] - pad["size"][2] / 2)
    high = max(link["centre"][2] + link["size"][2] / 2, pad["centre"][2] + pad["size"][2] / 2)
    travel = [link["size"][0], g["stroke"] + 2 * outer, high - low]
    lines = ['<?xml version="1.0"?>',
             f'<!-- GENERATED by robots/generate_gripper.py from {source}: edit that file, not this one.',
             '     The gripper for the planner (planning/robot_model.h, mountUrdf): link "mount" is the flange,',
             '     its shapes join the flange link; the fingers\' link has one box over their whole travel (a',
             '     collision world that knows the opening puts the fingers where they are); tcp: the tool centre point. -->',
             f'<robot name="{n}">',
             '  <link name="mount">']
    if "coupling" in g:
        c = g["coupling"]
        lines.append(f'    <collision><origin xyz="0 0 {(c["from_z"] + c["to_z"]) / 2:.12g}" rpy="0 0 0"/><geometry><cylinder '
                     f'radius="{c["radius"]:.12g}" length="{c["to_z"] - c["from_z"]:.12g}"/></geometry></collision>')
    lines += [f'    <collision><origin xyz="{fmt(body["centre"])}" rpy="0 0 0"/><geometry><box size="{fmt(body["size"])}"/>'
              '</geometry></collision>',
              '  </link>',
              '  <link name="fingers">',
              f'    <collision><origin xyz="0 0 {(low + high) / 2:.12g}" rpy="0 0 0"/><geometry><box size="{fmt(travel)}"/>'
              '</geometry></collision>',
              '  </link>',
              '  <link name="tcp"/>',
              '  <joint name="gripper_fingers" type="fixed"><parent link="mount"/><child link="fingers"/>',
              '    <origin xyz="0 0 0" rpy="0 0 0"/></joint>',
              '  <joint name="tool_centre_point" type="fixed"><parent link="fingers"/><child link="tcp"/>',
              f'    <origin xyz="{fmt(g["tcp"])}" rpy="0 0 0"/></joint>',
              '</robot>', '']
    return "\n".join(lines)
