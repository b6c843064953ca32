#!/usr/bin/env python3
"""Writes the simulator's model of one gripper from its gripper description.

    generate_gripper.py DESCRIPTION.json OUTPUT_DIR

reads a gripper description (format costar-gripper-description/1, see robots/README.md). A
"parallel" gripper's are NAME_mount.xml, NAME.urdf and NAME.fingerprint (robots/parallel_gripper.py);
an "adaptive-3f" gripper's, into OUTPUT_DIR:
- NAME_body.xml: the gripper's bodies, to go inside any flange body (an arm's tool0, the test
  bench's carrier): <mujoco> around one <body name="NAME_base">;
- NAME_sections.xml: its tendons, equalities and actuators, to go at the model's top level;
- NAME.xml: the gripper alone, fixed at the world origin (the two above put together);
- NAME_mount.xml: the gripper as a workcell's gripper piece (sim/cell_model.h): its bodies in
  a body "mount" (the flange) with the tool centre point (site "tcp") and the hand-eye
  calibration marker (geom "gripper_marker", on the palm's +x face), its sections beside it;
- NAME.urdf: the gripper for the planner (planning::mountUrdf): link "mount" (the palm, added
  to the flange link), link "NAME_fingers" (each finger as a cylinder about its base axis that
  holds the open finger at any scissor angle) and link "tcp".
sim/adaptive_gripper_sim.h mounts the first two into any model (mountAdaptiveGripper); a
simulated workcell composes NAME_mount.xml like any gripper piece (workcell/grippers.cpp).

Conventions (those of the parallel grippers, robots/parallel_gripper.py): gripper geoms contype 2, conaffinity 0
(they touch parts and the table box, not each other); pads condim 4 with friction 1.2. Each
finger is an underactuated chain of three hinges (proximal, medial, distal) about the finger's
-x axis (closing moves the tip along the finger's +y); one tendon sums the three angles, and a
force-limited position servo pulls it (in fingertip modes, Pinch, equalities hold the medial
and distal phalanges straight): the proximal phalanx moves first (weak spring), the
medial and distal ones bend (stiff springs) once it is blocked, so the finger wraps the part
and squeezes it with at most the force limit. Fingers with a scissor_sign turn about their
base's z axis, coupled by an equality; one position servo drives that scissor axis.
Bad input stops with a message naming the file, the field and the problem (exit status 1)."""
import math
import pathlib
import sys

from description_reader import MARKER_ASSET, MARKER_HALF, DescriptionError, Reader, fmt, marker_geom, write_fingerprint
from parallel_gripper import parallel_mount_xml, parallel_urdf, read_parallel

FORMAT = "costar-gripper-description/1"
PHALANGES = ("proximal", "medial", "distal")
FINGERS = ("finger_middle", "finger_1", "finger_2")


# The largest sizes a gripper description may give: a hand is well under a metre across, a
# phalanx a few centimetres long.
MAX_M = 1.0
MAX_PHALANX_M = 0.5
MAX_KG = 100.0


KINDS = ("adaptive-3f", "parallel")


def read_description(path):
    """The description of either kind: "adaptive-3f" (below) or "parallel" (parallel_gripper.py)."""
    reader = Reader(path)
    root = reader.root
    if root.get("format") != FORMAT:
        reader.fail("format", f'must be "{FORMAT}"')
    kind = reader.get(root, "kind", "", "string")
    if kind not in KINDS:
        reader.fail("kind", f'"{kind}" is not one of {", ".join(KINDS)}')
    name = reader.get(root, "name", "", "string")
    if name != pathlib.Path(path).stem:
        reader.fail("name", f'"{name}" must be the file\'s name ({pathlib.Path(path).stem}): the build finds grippers by their files')
    if kind == "parallel":
        return read_parallel(reader, root, name)
    g = {"name": name, "kind": kind}
    if not g["name"].replace("_", "").isalnum():
        reader.fail("name", "must be letters, digits and underscores")
    palm = reader.get(root, "palm", "", "object")
    g["palm"] = {"size": reader.get(palm, "size", "palm", "vec3", positive=True, at_most=MAX_M),
                 "centre": reader.get(palm, "centre", "palm", "vec3", at_most=MAX_M),
                 "mass": reader.get(palm, "mass", "palm", "number", positive=True, at_most=MAX_KG)}
    g["tcp"] = reader.get(root, "tcp", "", "vec3", at_most=MAX_M)

    fingers = []
    for i, finger in enumerate(reader.get(root, "fingers", "", "list")):
        field = f"fingers[{i}]"
        entry = {"name": reader.get(finger, "name", field, "string"),
                 "base": reader.get(finger, "base", field, "vec3", at_most=MAX_M),
                 "yaw_deg": reader.get(finger, "yaw_deg", field, "number"),
                 "scissor_sign": reader.get(finger, "scissor_sign", field, "number")}
        if entry["name"] in (f["name"] for f in fingers):
            reader.fail(f"{field}.name", f'"{entry["name"]}" appears twice')
        if entry["scissor_sign"] not in (-1, 0, 1):
            reader.fail(f"{field}.scissor_sign", "must be -1, 0 (no scissor axis) or 1")
        fingers.append(entry)
    if len(fingers) != 3:
        reader.fail("fingers", f"a 3-finger gripper needs 3 fingers, not {len(fingers)}")
    # The driver (gripper/adaptive_gripper_driver.h) knows the fingers by these names, in this order.
    if [f["name"] for f in fingers] != list(FINGERS):
        reader.fail("fingers", f"must be {', '.join(FINGERS)}, in this order")
    if fingers[0]["scissor_sign"] != 0:
        reader.fail("fingers[0].scissor_sign", "must be 0: finger_middle does not turn on the scissor axis")
    if not any(f["scissor_sign"] != 0 for f in fingers):
        reader.fail("fingers", "no finger turns on the scissor axis (scissor_sign 0 everywhere)")
    g["fingers"] = fingers

    phalanges = reader.get(root, "phalanges", "", "list")
    if [p.get("name") if isinstance(p, dict) else None for p in phalanges] != list(PHALANGES):
        reader.fail("phalanges", f"must be {', '.join(PHALANGES)}, in this order")
    g["phalanges"] = []
    for i, phalanx in enumerate(phalanges):
        field = f"phalanges[{i}]"
        entry = {"name": phalanx["name"]}
        for key in ("length", "width", "thickness"):
            entry[key] = reader.get(phalanx, key, field, "number", positive=True, at_most=MAX_PHALANX_M)
        entry["mass"] = reader.get(phalanx, "mass", field, "number", positive=True, at_most=MAX_KG)
        for key in ("lower_deg", "upper_deg"):
            entry[key] = reader.get(phalanx, key, field, "number")
        entry["stiffness"] = reader.get(phalanx, "stiffness_nm_rad", field, "number", positive=True)
        entry["rest_deg"] = reader.get(phalanx, "spring_rest_deg", field, "number")
        if not entry["lower_deg"] < entry["upper_deg"]:
            reader.fail(field, "lower_deg must be below upper_deg")
        if entry["rest_deg"] > entry["upper_deg"] or entry["rest_deg"] > 0:
            reader.fail(f"{field}.spring_rest_deg", "must be at most 0 (straight) and upper_deg: the spring holds the phalanx open")
        if not entry["lower_deg"] <= 0 <= entry["upper_deg"]:
            reader.fail(field, "the straight finger (0 degrees) must be within lower_deg .. upper_deg")
        g["phalanges"].append(entry)

    act = reader.get(root, "actuation", "", "object")
    g["actuation"] = {}
    for key in ("lever_m", "closed_deg", "min_force_n", "max_force_n", "servo_gain_nm_rad", "scissor_speed_deg_s",
                "scissor_gain_nm_rad", "scissor_max_torque_nm"):
        g["actuation"][key] = reader.get(act, key, "actuation", "number", positive=True)
    for key in ("scissor_lower_deg", "scissor_upper_deg"):
        g["actuation"][key] = reader.get(act, key, "actuation", "number")
    if g["actuation"]["min_force_n"] > g["actuation"]["max_force_n"]:
        reader.fail("actuation.min_force_n", "must not exceed max_force_n")
    reach = sum(p["upper_deg"] for p in g["phalanges"][:2])
    if not g["phalanges"][0]["lower_deg"] < g["actuation"]["closed_deg"] <= reach:
        reader.fail("actuation.closed_deg", f"must be above the open finger and at most the proximal and medial phalanges' reach ({reach:g} degrees)")
    lower, upper = g["actuation"]["scissor_lower_deg"], g["actuation"]["scissor_upper_deg"]
    if not lower < upper:
        reader.fail("actuation", "scissor_lower_deg must be below scissor_upper_deg")

    modes = []
    names = [f["name"] for f in fingers]
    for i, mode in enumerate(reader.get(root, "modes", "", "list")):
        field = f"modes[{i}]"
        entry = {"name": reader.get(mode, "name", field, "string"),
                 "scissor_deg": reader.get(mode, "scissor_deg", field, "number"),
                 "closing": reader.get(mode, "closing", field, "list"),
                 "grasp_centre": reader.get(mode, "grasp_centre", field, "vec3", at_most=MAX_M),
                 "fingertip": mode.get("fingertip", False)}
        if not isinstance(entry["fingertip"], bool):
            reader.fail(f"{field}.fingertip", "must be true or false")
        if entry["name"] not in ("basic", "pinch", "wide", "scissor"):
            reader.fail(f"{field}.name", f'"{entry["name"]}" is not one of basic, pinch, wide, scissor')
        if entry["name"] in (m["name"] for m in modes):
            reader.fail(f"{field}.name", f'"{entry["name"]}" appears twice')
        if not lower <= entry["scissor_deg"] <= upper:
            reader.fail(f"{field}.scissor_deg", f"must be within scissor_lower_deg .. scissor_upper_deg ({lower} .. {upper})")
        for k, finger in enumerate(entry["closing"]):
            if finger not in names:
                reader.fail(f"{field}.closing[{k}]", f'"{finger}" is not a finger ({", ".join(names)})')
        modes.append(entry)
    missing = {"basic", "pinch", "wide", "scissor"} - {m["name"] for m in modes}
    if missing:
        reader.fail("modes", f"missing {', '.join(sorted(missing))}")
    g["modes"] = modes
    return g


def box_inertia(mass, size):
    x, y, z = size
    return [mass * (y * y + z * z) / 12, mass * (x * x + z * z) / 12, mass * (x * x + y * y) / 12]


def body_xml(g):
    n = g["name"]
    palm = g["palm"]
    half = [s / 2 for s in palm["size"]]
    lines = [f'<body name="{n}_base">',
             f'  <inertial pos="{fmt(palm["centre"])}" mass="{palm["mass"]:.12g}" '
             f'diaginertia="{fmt(box_inertia(palm["mass"], palm["size"]))}"/>',
             f'  <geom name="{n}_palm" type="box" pos="{fmt(palm["centre"])}" size="{fmt(half)}" contype="2" '
             'conaffinity="0" rgba="0.2 0.22 0.25 1" group="1"/>',
             f'  <site name="{n}_tcp" pos="{fmt(g["tcp"])}" size="0.004" rgba="1 0.5 0 0.6"/>']
    for finger in g["fingers"]:
        f = f'{n}_{finger["name"]}'
        yaw = math.radians(finger["yaw_deg"]) / 2
        lines.append(f'  <body name="{f}" pos="{fmt(finger["base"])}" quat="{fmt([math.cos(yaw), 0, 0, math.sin(yaw)])}">')
        indent = "    "
        if finger["scissor_sign"] != 0:
            act = g["actuation"]
            rng = [math.radians(act["scissor_lower_deg"]), math.radians(act["scissor_upper_deg"])]
            lines.append(indent + f'<joint name="{f}_scissor" type="hinge" axis="0 0 {int(finger["scissor_sign"])}" '
                         f'range="{fmt(rng)}" damping="1" armature="0.01"/>')
        knuckle = g["phalanges"][0]["width"] / 2
        lines.append(indent + f'<geom name="{f}_knuckle" type="cylinder" fromto="{fmt([-knuckle, 0, 0, knuckle, 0, 0])}" size="0.012" '
                     'contype="2" conaffinity="0" rgba="0.2 0.22 0.25 1" group="1" mass="0.05"/>')
        offset = 0.0
        for phalanx in g["phalanges"]:
            p = f'{f}_{phalanx["name"]}'
            length, width, thick = phalanx["length"], phalanx["width"], phalanx["thickness"]
            lines.append(indent + f'<body name="{p}" pos="0 0 {offset:.12g}">')
            indent += "  "
            rng = [math.radians(phalanx["lower_deg"]), math.radians(phalanx["upper_deg"])]
            springref = math.radians(phalanx["rest_deg"])
            lines.append(indent + f'<joint name="{p}" type="hinge" axis="-1 0 0" range="{fmt(rng)}" '
                         f'stiffness="{phalanx["stiffness"]:.12g}" springref="{springref:.12g}" damping="0.1" '
                         'armature="0.002"/>')
            # The phalanx, and a pad on its inner (+y) face that grips.
            lines.append(indent + f'<geom name="{p}" type="box" pos="0 0 {length / 2:.12g}" '
                         f'size="{fmt([width / 2, thick / 2 - 0.002, length / 2])}" mass="{phalanx["mass"]:.12g}" '
                         'contype="2" conaffinity="0" rgba="0.25 0.27 0.3 1" group="1"/>')
            lines.append(indent + f'<geom name="{p}_pad" type="box" pos="0 {thick / 2 - 0.002:.12g} {length / 2:.12g}" '
                         f'size="{fmt([width / 2, 0.002, length / 2])}" mass="0.005" contype="2" conaffinity="0" '
                         'condim="4" friction="1.2 0.01 0.001" solref="0.004 1" rgba="0.1 0.1 0.1 1" group="1"/>')
            offset = length
        for _ in g["phalanges"]:
            indent = indent[:-2]
            lines.append(indent + '</body>')
        lines.append('  </body>')
    lines.append('</body>')
    return lines


def sections_xml(g):
    n = g["name"]
    act = g["actuation"]
    closed = math.radians(act["closed_deg"])
    opened = math.radians(g["phalanges"][0]["lower_deg"])
    torque = act["max_force_n"] * act["lever_m"]
    lines = ['<tendon>']
    for finger in g["fingers"]:
        f = f'{n}_{finger["name"]}'
        # The flexion tendon pulls the proximal and medial phalanges; the distal one follows
        # through its preloaded spring and contact.
        lines.append(f'  <fixed name="{f}_flex" damping="0.05">')
        lines += [f'    <joint joint="{f}_{p}" coef="1"/>' for p in PHALANGES[:2]]
        lines.append('  </fixed>')
    lines += ['</tendon>', '<equality>']
    scissors = [f for f in g["fingers"] if f["scissor_sign"] != 0]
    for follower in scissors[1:]:
        lines.append(f'  <joint name="{n}_{follower["name"]}_scissor_coupling" joint1="{n}_{follower["name"]}_scissor" '
                     f'joint2="{n}_{scissors[0]["name"]}_scissor" polycoef="0 1 0 0 0" solref="0.004 1"/>')
    # Fingertip modes (Pinch) hold the medial and distal phalanges straight: inactive joint
    # equalities the simulated driver switches on in those modes.
    for finger in g["fingers"]:
        for phalanx in PHALANGES[1:]:
            joint = f'{n}_{finger["name"]}_{phalanx}'
            lines.append(f'  <joint name="{joint}_lock" joint1="{joint}" polycoef="0 0 0 0 0" active="false" solref="0.004 1"/>')
    lines += ['</equality>', '<actuator>']
    for finger in g["fingers"]:
        f = f'{n}_{finger["name"]}'
        # Tendon length = the proximal and medial angles, from open (proximal at its lower limit)
        # to closed (closed_deg: the finger curled as it closes on nothing, reached with the
        # least force). The force limit is the grip force at the lever.
        lines.append(f'  <position name="{f}" tendon="{f}_flex" kp="{act["servo_gain_nm_rad"]:.12g}" '
                     f'ctrlrange="{fmt([opened, closed])}" forcerange="{fmt([-torque, torque])}"/>')
    rng = [math.radians(act["scissor_lower_deg"]), math.radians(act["scissor_upper_deg"])]
    lines.append(f'  <position name="{n}_scissor" joint="{n}_{scissors[0]["name"]}_scissor" '
                 f'kp="{act["scissor_gain_nm_rad"]:.12g}" ctrlrange="{fmt(rng)}" '
                 f'forcerange="{fmt([-act["scissor_max_torque_nm"], act["scissor_max_torque_nm"]])}"/>')
    lines.append('</actuator>')
    return lines



def mount_xml(g):
    """The gripper piece of a workcell model: body "mount" is the flange."""
    palm = g["palm"]
    half = [s / 2 for s in palm["size"]]
    if min(half[1], half[2]) < MARKER_HALF:
        raise DescriptionError("palm.size: the palm's +x face must hold the 6.67 cm calibration marker")
    face = [palm["centre"][0] + half[0], palm["centre"][1], palm["centre"][2]]
    lines = MARKER_ASSET + ['<worldbody>',
                            '  <body name="mount">',
                            f'    <site name="tcp" pos="{fmt(g["tcp"])}" size="0.004" rgba="1 0.5 0 0.6"/>',
                            '    ' + marker_geom(face)]
    lines += ["    " + line for line in body_xml(g)]
    lines += ['  </body>', '</worldbody>']
    return lines + sections_xml(g)


def urdf(g, source):
    """The planner's gripper: the palm on the flange, the fingers' reach, the tool centre point."""
    n = g["name"]
    palm = g["palm"]
    phalanges = g["phalanges"]
    length = sum(p["length"] for p in phalanges)
    thick = max(p["thickness"] for p in phalanges)
    # The open finger leans out by the proximal phalanx's lower limit; a cylinder about the
    # finger's base axis holds it at every scissor angle (closing fingers move inside the grasp).
    lean = math.radians(-phalanges[0]["lower_deg"])
    radius = length * math.sin(max(lean, 0.0)) + thick / 2 + 0.003
    knuckle = 0.012
    lines = ['<?xml version="1.0"?>',
             f'<!-- GENERATED by robots/generate_gripper.py from {source}: edit that file, not this one.',
             '     The gripper for the planner (planning/robot_model.h, mountUrdf): link "mount" is the flange,',
             '     its shapes join the flange link; the fingers are one link, each finger a cylinder about its',
             '     base axis that holds the open finger at any scissor angle; tcp: the tool centre point. -->',
             f'<robot name="{n}">',
             '  <link name="mount">',
             f'    <collision><origin xyz="{fmt(palm["centre"])}" rpy="0 0 0"/><geometry><box size="{fmt(palm["size"])}"/>'
             '</geometry></collision>',
             '  </link>',
             f'  <link name="{n}_fingers">']
    for finger in g["fingers"]:
        bottom = finger["base"][2] - knuckle
        # The open fingertip's lowest corner, and a millimetre.
        top = finger["base"][2] + length * math.cos(lean) + thick / 2 * math.sin(max(lean, 0.0)) + 0.001
        centre = [finger["base"][0], finger["base"][1], (bottom + top) / 2]
        lines.append(f'    <collision><origin xyz="{fmt(centre)}" rpy="0 0 0"/><geometry><cylinder radius="{radius:.12g}" '
                     f'length="{top - bottom:.12g}"/></geometry></collision>')
    lines += ['  </link>',
              '  <link name="tcp"/>',
              f'  <joint name="{n}_fingers" type="fixed"><parent link="mount"/><child link="{n}_fingers"/>',
              '    <origin xyz="0 0 0" rpy="0 0 0"/></joint>',
              f'  <joint name="{n}_tool_centre_point" type="fixed"><parent link="{n}_fingers"/><child link="tcp"/>',
              f'    <origin xyz="{fmt(g["tcp"])}" rpy="0 0 0"/></joint>',
              '</robot>', '']
    return "\n".join(lines)


def wrap(lines, model, source, what):
    return "\n".join(['<?xml version="1.0" encoding="UTF-8"?>',
                      f'<!-- GENERATED by robots/generate_gripper.py from {source}: edit that file, not this one.',
                      f'     {what} -->', f'<mujoco model="{model}">'] + ["  " + line for line in lines] +
                     ['</mujoco>', ''])


def main(argv):
    if len(argv) != 3:
        print("usage: generate_gripper.py DESCRIPTION.json OUTPUT_DIR", file=sys.stderr)
        return 2
    source = pathlib.Path(argv[1])
    try:
        gripper = read_description(source)
    except DescriptionError as error:
        print(f"generate_gripper.py: {error}", file=sys.stderr)
        return 1
    out = pathlib.Path(argv[2])
    out.mkdir(parents=True, exist_ok=True)
    shown = "/".join(source.resolve().parts[-3:])
    n = gripper["name"]
    if gripper["kind"] == "parallel":
        (out / f"{n}_mount.xml").write_text(
            wrap(parallel_mount_xml(gripper), f"{n}_mount", shown,
                 "The gripper as a workcell's gripper piece (sim/cell_model.h): body \"mount\" is the flange."))
        (out / f"{n}.urdf").write_text(parallel_urdf(gripper, shown))
        write_fingerprint(source, out / f"{n}.fingerprint")  # last: the models are complete
        return 0
    body, sections = body_xml(gripper), sections_xml(gripper)
    (out / f"{n}_body.xml").write_text(
        wrap(body, f"{n}_body", shown, "The gripper's bodies: they go inside a flange body."))
    (out / f"{n}_sections.xml").write_text(
        wrap(sections, f"{n}_sections", shown, "Tendons, equalities, actuators: they go at the model's top level."))
    alone = ['<compiler angle="radian" autolimits="true"/>',
             '<option timestep="0.002" cone="elliptic" impratio="10" integrator="Euler"/>',
             '<worldbody>'] + ["  " + line for line in body] + ['</worldbody>'] + sections
    (out / f"{n}.xml").write_text(wrap(alone, n, shown, "The gripper alone, fixed at the world origin."))
    try:
        mount = mount_xml(gripper)
    except DescriptionError as error:
        print(f"generate_gripper.py: {source}: {error}", file=sys.stderr)
        return 1
    (out / f"{n}_mount.xml").write_text(
        wrap(mount, f"{n}_mount", shown,
             "The gripper as a workcell's gripper piece (sim/cell_model.h): body \"mount\" is the flange."))
    (out / f"{n}.urdf").write_text(urdf(gripper, shown))
    write_fingerprint(source, out / f"{n}.fingerprint")  # last: the models are complete
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
