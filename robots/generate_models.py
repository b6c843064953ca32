#!/usr/bin/env python3
"""Writes the simulator's and the planner's models of one arm from its robot description.

    generate_models.py DESCRIPTION.json OUTPUT_DIR

reads a robot description (format costar-robot-description/1, see robots/README.md) and writes
OUTPUT_DIR/NAME.xml, an MJCF model of the arm alone for MuJoCo, and OUTPUT_DIR/NAME.urdf, the
same chain for Orocos KDL (kdl_parser) and collision checking (planning::RobotModel). Both are
made from the same numbers, so the simulator and the planner cannot disagree.

Conventions:
- The base link is fixed to the world at the origin (the workcell places it: "robot_base"); every
  link frame sits on its joint.
- MJCF: arm geoms contype 2, conaffinity 0 (they touch the table and parts, not each other);
  a collision shape's optional rgba colours it (default: the description's top-level "rgba", else
  orange);
  one motor actuator per joint named after it, ctrlrange the joint's torque limit (the
  simulation runs computed-torque control); joint damping 0.5, armature 0.1; a keyframe "home";
  the tool frame is a body with a site of the same name.
- URDF: capsules become a cylinder and two spheres (the same solid), each a <collision> and a
  <visual> of the same solid in its colour (RViz and the editor's 3D view draw it); the tool frame is a link
  on a fixed joint; the base link carries no inertia (KDL does not accept one on the root).
Bad input stops with a message naming the file, the field and the problem (exit status 1)."""
import math
import pathlib
import sys

from description_reader import DescriptionError, Reader, fmt, write_fingerprint

FORMAT = "costar-robot-description/1"


def rotation_rpy(rpy):
    """R = Rz(yaw) Ry(pitch) Rx(roll), as URDF."""
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return [[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr]]


def quat_rpy(rpy):
    """(w, x, y, z) of R = Rz(yaw) Ry(pitch) Rx(roll), for MJCF's quat."""
    r, p, y = (v / 2 for v in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy)


def mat_vec(m, v):
    return [sum(m[i][k] * v[k] for k in range(3)) for i in range(3)]


def mat_mat(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


# The colour of a shape that names none, when the description gives no "rgba" of its own.
DEFAULT_RGBA = [0.93, 0.55, 0.13, 1]

# The largest length (m) and mass (kg) a description may give: an arm is a few metres long.
MAX_M = 10.0
MAX_KG = 1000.0


def read_rgba(reader, parent, field):
    """An optional colour: 4 numbers from 0 to 1, or None."""
    rgba = reader.get(parent, "rgba", field, "list", optional=True)
    if rgba is not None and (len(rgba) != 4 or not all(
            isinstance(x, (int, float)) and not isinstance(x, bool) and 0 <= x <= 1 for x in rgba)):
        name = f"{field}.rgba" if field else "rgba"
        reader.fail(name, f"must be 4 numbers from 0 to 1 (red, green, blue, alpha), not {rgba}")
    return rgba


def read_description(path):
    reader = Reader(path)
    root = reader.root
    if root.get("format") != FORMAT:
        reader.fail("format", f'must be "{FORMAT}"')
    robot = {"name": reader.get(root, "name", "", "string"), "base_link": reader.get(root, "base_link", "", "string"),
             "rgba": read_rgba(reader, root, "") or DEFAULT_RGBA}
    links = {}
    for i, link in enumerate(reader.get(root, "links", "", "list")):
        field = f"links[{i}]"
        name = reader.get(link, "name", field, "string")
        if name in links:
            reader.fail(f"{field}.name", f'"{name}" appears twice')
        mass = reader.get(link, "mass", field, "number", at_most=MAX_KG)
        inertia = reader.get(link, "inertia", field, "vec3", at_most=MAX_KG * MAX_M ** 2)
        if mass <= 0 or min(inertia) <= 0:
            reader.fail(field, "mass and inertia must be positive")
        a, b, c = inertia
        if a + b < c or b + c < a or a + c < b:
            reader.fail(f"{field}.inertia", "violates the triangle inequality (no rigid body has it)")
        shapes = []
        for k, shape in enumerate(reader.get(link, "collision", field, "list", optional=True, default=[])):
            shape_field = f"{field}.collision[{k}]"
            kind = reader.get(shape, "type", shape_field, "string")
            if kind not in ("capsule", "cylinder"):
                reader.fail(f"{shape_field}.type", f'"{kind}" is not one of capsule, cylinder')
            start = reader.get(shape, "from", shape_field, "vec3", at_most=MAX_M)
            end = reader.get(shape, "to", shape_field, "vec3", at_most=MAX_M)
            radius = reader.get(shape, "radius", shape_field, "number", at_most=MAX_M)
            if radius <= 0 or math.dist(start, end) <= 0:
                reader.fail(shape_field, "needs a positive radius and distinct from/to")
            rgba = read_rgba(reader, shape, shape_field)
            shapes.append({"type": kind, "from": start, "to": end, "radius": radius, "rgba": rgba})
        links[name] = {"name": name, "mass": mass, "com": reader.get(link, "com", field, "vec3", at_most=MAX_M),
                       "inertia": inertia, "collision": shapes}
    if robot["base_link"] not in links:
        reader.fail("base_link", f'"{robot["base_link"]}" is not a link')

    # The joints must form one chain from the base link.
    joints = []
    parent = robot["base_link"]
    for i, joint in enumerate(reader.get(root, "joints", "", "list")):
        field = f"joints[{i}]"
        entry = {key: reader.get(joint, key, field, "string") for key in ("name", "parent", "child")}
        if entry["parent"] != parent:
            reader.fail(f"{field}.parent", f'must be "{parent}" (the joints form one chain from the base link)')
        if entry["child"] not in links:
            reader.fail(f"{field}.child", f'"{entry["child"]}" is not a link')
        entry["origin"] = reader.get(joint, "origin", field, "vec3", at_most=MAX_M)
        entry["rpy"] = reader.get(joint, "rpy", field, "vec3", optional=True, default=[0, 0, 0])
        axis = reader.get(joint, "axis", field, "vec3")
        norm = math.sqrt(sum(x * x for x in axis))
        if abs(norm - 1) > 1e-9:
            reader.fail(f"{field}.axis", "must be a unit vector")
        entry["axis"] = axis
        # Two joints at one point are a wrist or a shoulder (the Panda's joints 1 and 2) when their
        # axes differ; about the same axis they are one joint: a link of zero length.
        if joints and not any(entry["origin"]):
            turned = mat_vec(rotation_rpy(entry["rpy"]), axis)
            if math.dist(turned, joints[-1]["axis"]) < 1e-9 or math.dist(turned, [-x for x in joints[-1]["axis"]]) < 1e-9:
                reader.fail(f"{field}.origin", f'[0, 0, 0] puts {entry["name"]} on the joint before it, about the same '
                            "axis: a link of zero length")
        for key in ("lower_deg", "upper_deg", "velocity_deg_s", "effort_nm"):
            entry[key] = reader.get(joint, key, field, "number")
        if not entry["lower_deg"] < entry["upper_deg"]:
            reader.fail(field, "lower_deg must be below upper_deg")
        if entry["velocity_deg_s"] <= 0 or entry["effort_nm"] <= 0:
            reader.fail(field, "velocity_deg_s and effort_nm must be positive")
        joints.append(entry)
        parent = entry["child"]
    robot["joints"] = joints

    tool = reader.get(root, "tool", "", "object")
    robot["tool"] = {"name": reader.get(tool, "name", "tool", "string"),
                     "parent": reader.get(tool, "parent", "tool", "string"),
                     "origin": reader.get(tool, "origin", "tool", "vec3", at_most=MAX_M),
                     "rpy": reader.get(tool, "rpy", "tool", "vec3", optional=True, default=[0, 0, 0])}
    if robot["tool"]["parent"] != parent:
        reader.fail("tool.parent", f'must be "{parent}", the last link of the chain')
    if robot["tool"]["name"] in links:
        reader.fail("tool.name", "must differ from every link name")

    home = reader.get(root, "home_deg", "", "list")
    if len(home) != len(joints):
        reader.fail("home_deg", f"needs {len(joints)} values, one per joint, not {len(home)}")
    for i, (value, joint) in enumerate(zip(home, joints)):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not joint["lower_deg"] <= value <= joint["upper_deg"]:
            reader.fail(f"home_deg[{i}]", f"must be a number within the limits of {joint['name']}")
    robot["home_deg"] = home
    chain_links = [robot["base_link"]] + [j["child"] for j in joints]
    robot["links"] = [links[name] for name in chain_links]
    for name in links:
        if name not in chain_links:
            reader.fail("links", f'"{name}" is not on the chain')
    check_published_lengths(reader, root, robot)
    return robot


def check_published_lengths(reader, root, robot):
    """For a 7-joint S-R-S arm: the joint origins must add up to the manufacturer's lengths."""
    published = root.get("published_lengths")
    if published is None:
        return
    if len(robot["joints"]) != 7:
        reader.fail("published_lengths", "are defined for 7-joint arms only")
    # Positions of the joint origins and of the tool at zero angles.
    rotation, position, points = [[1, 0, 0], [0, 1, 0], [0, 0, 1]], [0.0, 0.0, 0.0], []
    for frame in robot["joints"] + [robot["tool"]]:
        position = [p + d for p, d in zip(position, mat_vec(rotation, frame["origin"]))]
        rotation = mat_mat(rotation, rotation_rpy(frame["rpy"]))
        points.append(position)
    expected = {"base_to_shoulder": math.dist([0, 0, 0], points[1]), "shoulder_to_elbow": math.dist(points[1], points[3]),
                "elbow_to_wrist": math.dist(points[3], points[5]), "wrist_to_flange": math.dist(points[5], points[7])}
    for key, length in expected.items():
        value = reader.get(published, key, "published_lengths", "number")
        if abs(value - length) > 1e-9:
            reader.fail(f"published_lengths.{key}", f"is {value} m but the joint origins give {length:.9g} m")


def capsule_or_cylinder_mjcf(name, shape):
    colour = f' rgba="{fmt(shape["rgba"])}"' if shape["rgba"] is not None else ""
    return (f'<geom name="{name}" type="{shape["type"]}" fromto="{fmt(shape["from"] + shape["to"])}" '
            f'size="{shape["radius"]:.12g}"{colour}/>')


def inertial_mjcf(link):
    return f'<inertial pos="{fmt(link["com"])}" mass="{link["mass"]:.12g}" diaginertia="{fmt(link["inertia"])}"/>'


def write_mjcf(robot, path, source):
    joints, links, tool = robot["joints"], robot["links"], robot["tool"]
    lines = ['<?xml version="1.0" encoding="UTF-8"?>',
             f'<!-- GENERATED by robots/generate_models.py from {source}: edit that file, not this one.',
             f'     {robot["name"]} alone, fixed to the world at the origin; joint i is actuated by the motor of the',
             '     same name (torque, limited to the joint\'s maximum torque). -->',
             f'<mujoco model="{robot["name"]}">',
             '  <compiler angle="radian" autolimits="true"/>',
             '  <option timestep="0.002" integrator="Euler"/>',
             '  <default>',
             f'    <default class="{robot["name"]}">',
             '      <joint damping="0.5" armature="0.1"/>',
             f'      <geom contype="2" conaffinity="0" rgba="{fmt(robot["rgba"])}" group="1"/>',
             '    </default>',
             '  </default>',
             '  <worldbody>',
             f'    <body name="{links[0]["name"]}" childclass="{robot["name"]}">']
    indent = "      "

    def add_link_contents(link):
        lines.append(indent + inertial_mjcf(link))
        for k, shape in enumerate(link["collision"]):
            lines.append(indent + capsule_or_cylinder_mjcf(f'{link["name"]}_collision_{k}', shape))

    add_link_contents(links[0])
    for joint, link in zip(joints, links[1:]):
        quat = quat_rpy(joint["rpy"])
        lines.append(indent + f'<body name="{link["name"]}" pos="{fmt(joint["origin"])}" quat="{fmt(quat)}">')
        indent += "  "
        lines.append(indent + f'<joint name="{joint["name"]}" axis="{fmt(joint["axis"])}" '
                     f'range="{fmt([math.radians(joint["lower_deg"]), math.radians(joint["upper_deg"])])}"/>')
        add_link_contents(link)
    lines.append(indent + f'<body name="{tool["name"]}" pos="{fmt(tool["origin"])}" quat="{fmt(quat_rpy(tool["rpy"]))}">')
    lines.append(indent + f'  <site name="{tool["name"]}" size="0.005" rgba="1 0.5 0 0.6"/>')
    lines.append(indent + '</body>')
    for _ in joints:
        indent = indent[:-2]
        lines.append(indent + '</body>')
    lines += ['    </body>', '  </worldbody>', '  <actuator>']
    for joint in joints:
        effort = joint["effort_nm"]
        lines.append(f'    <motor name="{joint["name"]}" joint="{joint["name"]}" ctrlrange="{fmt([-effort, effort])}"/>')
    home = [math.radians(v) for v in robot["home_deg"]]
    lines += ['  </actuator>', '  <keyframe>', f'    <key name="home" qpos="{fmt(home)}"/>', '  </keyframe>',
              '</mujoco>', '']
    path.write_text("\n".join(lines))


def urdf_shapes(shape):
    """(origin xyz, rpy, geometry XML) of the URDF solids that make up a capsule or cylinder."""
    start, end, radius = shape["from"], shape["to"], shape["radius"]
    axis = [b - a for a, b in zip(start, end)]
    length = math.sqrt(sum(x * x for x in axis))
    middle = [(a + b) / 2 for a, b in zip(start, end)]
    # Turn z onto the axis: pitch about y, then yaw about z.
    pitch = math.acos(max(-1.0, min(1.0, axis[2] / length)))
    yaw = math.atan2(axis[1], axis[0]) if math.hypot(axis[0], axis[1]) > 1e-12 else 0.0
    solids = [(middle, [0, pitch, yaw], f'<cylinder radius="{radius:.12g}" length="{length:.12g}"/>')]
    if shape["type"] == "capsule":
        solids += [(point, [0, 0, 0], f'<sphere radius="{radius:.12g}"/>') for point in (start, end)]
    return solids


def write_urdf(robot, path, source):
    lines = ['<?xml version="1.0"?>',
             f'<!-- GENERATED by robots/generate_models.py from {source}: edit that file, not this one.',
             '     Capsules are a cylinder and two spheres. -->',
             f'<robot name="{robot["name"]}">']
    for link in robot["links"]:
        ixx, iyy, izz = link["inertia"]
        lines.append(f'  <link name="{link["name"]}">')
        # The base is fixed to the world: KDL rejects (warns about) an inertia on the root link.
        if link is not robot["links"][0]:
            lines.append(f'    <inertial><origin xyz="{fmt(link["com"])}" rpy="0 0 0"/><mass value="{link["mass"]:.12g}"/>'
                         f'<inertia ixx="{ixx:.12g}" ixy="0" ixz="0" iyy="{iyy:.12g}" iyz="0" izz="{izz:.12g}"/></inertial>')
        for k, shape in enumerate(link["collision"]):
            colour = fmt(shape["rgba"] or robot["rgba"])
            for xyz, rpy, geometry in urdf_shapes(shape):
                origin = f'<origin xyz="{fmt(xyz)}" rpy="{fmt(rpy)}"/>'
                lines.append(f'    <collision>{origin}<geometry>{geometry}</geometry></collision>')
                lines.append(f'    <visual>{origin}<geometry>{geometry}</geometry>'
                             f'<material name="{link["name"]}_{k}"><color rgba="{colour}"/></material></visual>')
        lines.append('  </link>')
    tool = robot["tool"]
    lines.append(f'  <link name="{tool["name"]}"/>')
    for joint in robot["joints"]:
        lines += [f'  <joint name="{joint["name"]}" type="revolute">',
                  f'    <parent link="{joint["parent"]}"/><child link="{joint["child"]}"/>',
                  f'    <origin xyz="{fmt(joint["origin"])}" rpy="{fmt(joint["rpy"])}"/>',
                  f'    <axis xyz="{fmt(joint["axis"])}"/>',
                  f'    <limit lower="{math.radians(joint["lower_deg"]):.12g}" upper="{math.radians(joint["upper_deg"]):.12g}" '
                  f'velocity="{math.radians(joint["velocity_deg_s"]):.12g}" effort="{joint["effort_nm"]:.12g}"/>',
                  '  </joint>']
    lines += [f'  <joint name="{tool["name"]}_joint" type="fixed">',
              f'    <parent link="{tool["parent"]}"/><child link="{tool["name"]}"/>',
              f'    <origin xyz="{fmt(tool["origin"])}" rpy="{fmt(tool["rpy"])}"/>',
              '  </joint>', '</robot>', '']
    path.write_text("\n".join(lines))


def main(argv):
    if len(argv) != 3:
        print("usage: generate_models.py DESCRIPTION.json OUTPUT_DIR", file=sys.stderr)
        return 2
    source = pathlib.Path(argv[1])
    try:
        robot = read_description(source)
    except DescriptionError as error:
        print(f"generate_models.py: {error}", file=sys.stderr)
        return 1
    out = pathlib.Path(argv[2])
    out.mkdir(parents=True, exist_ok=True)
    shown = "/".join(source.resolve().parts[-3:])
    write_mjcf(robot, out / f'{robot["name"]}.xml', shown)
    write_urdf(robot, out / f'{robot["name"]}.urdf', shown)
    write_fingerprint(source, out / f'{robot["name"]}.fingerprint')  # last: the models are complete
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
