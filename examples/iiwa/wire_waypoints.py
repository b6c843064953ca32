#!/usr/bin/env python3
"""The waypoints of examples/iiwa/wire_bending.xml, as a technician would teach them with the
jog keys: the wire's free end taken from above, swung clockwise around pin B in 10-degree
steps to 90 degrees and a few past it (the springback), back to 90, then the whole end swung
counter-clockwise around pin A likewise. The numbers are sim/scenes/wire_bending.json's jig.

  python3 examples/iiwa/wire_waypoints.py > examples/iiwa/wire_waypoints.json
  python3 examples/iiwa/wire_waypoints.py --tcp-z 0.03 --over-b 2.5 --wrap 0.009 > examples/iiwa/wire_waypoints_2f.json

(the 3-finger gripper's TCP is 7 mm below its pinching fingertips' middle; the 2-finger
gripper's is between its pads, and they hold the wire firmly enough that it springs back less
at B).
"""
import argparse
import json
import math

JIG = (0.40, -0.12)  # the clamp's mouth on the table (m); the jig's yaw is 0
PIN_A = (0.065, 0.00975)  # in the jig's frame (m)
PIN_B = (0.13, -0.00975)
STEP = 10  # degrees between waypoints of a swing


def rotate(v, angle):
    c, s = math.cos(angle), math.sin(angle)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def tool_down(heading):
    """The flange's z down and its x at `heading` about the vertical: Rz(heading) Ry(pi), (w, x, y, z)."""
    c, s = math.cos(heading / 2), math.sin(heading / 2)
    return [0.0, -s, c, 0.0]


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--grasp-x", type=float, default=0.222, help="where along the wire the fingers take it (m)")
    parser.add_argument("--tcp-z", type=float, default=0.023, help="the TCP's height while bending (m)")
    parser.add_argument("--over-b", type=float, default=4.5, help="degrees bent past 90 at pin B")
    parser.add_argument("--over-a", type=float, default=3.5, help="degrees bent past 90 at pin A")
    parser.add_argument("--wrap", type=float, default=0.00925,
                        help="the radius the wire's axis wraps a pin at (m): the pin's 8 mm, the wire's 1 mm, and play")
    args = parser.parse_args()

    waypoints = []

    def add(name, point, heading, z=args.tcp_z):
        waypoints.append({"name": name, "frame": "world",
                          "position": [round(JIG[0] + point[0], 5), round(JIG[1] + point[1], 5), round(z, 5)],
                          "orientation": [round(c, 6) for c in tool_down(heading)]})

    add("wire_above_end", (args.grasp_x, 0.0), 0.0, args.tcp_z + 0.08)
    add("wire_grip", (args.grasp_x, 0.0), 0.0)

    # Around B, clockwise: the wire wraps on the pin over `phi`, the rest of it stays straight.
    free_b = args.grasp_x - PIN_B[0]

    def swing_b(phi):
        tangent = (math.cos(-phi), math.sin(-phi))
        normal = (math.sin(phi), math.cos(phi))
        free = free_b - args.wrap * phi
        point = (PIN_B[0] + args.wrap * normal[0] + free * tangent[0],
                 PIN_B[1] + args.wrap * normal[1] + free * tangent[1])
        return point, -phi

    angles = range(STEP, 91, STEP)
    for a in angles:
        add("bend_b_%d" % a, *swing_b(math.radians(a)))
    add("bend_b_over", *swing_b(math.radians(90 + args.over_b)))
    add("bend_b_done", *swing_b(math.radians(90)))

    # Around A, counter-clockwise: the L beyond A's tangent point turns about the pin.
    held, _ = swing_b(math.radians(90))
    start = (PIN_A[0], 0.0)

    def swing_a(psi):
        normal = rotate((0, -1), psi)
        touch = (PIN_A[0] + args.wrap * normal[0], PIN_A[1] + args.wrap * normal[1])
        arm = rotate((held[0] - start[0] - args.wrap * psi, held[1] - start[1]), psi)
        return (touch[0] + arm[0], touch[1] + arm[1]), -math.pi / 2 + psi

    for a in angles:
        add("bend_a_%d" % a, *swing_a(math.radians(a)))
    add("bend_a_over", *swing_a(math.radians(90 + args.over_a)))
    add("bend_a_done", *swing_a(math.radians(90)))
    point, heading = swing_a(math.radians(90))
    add("wire_above_done", point, heading, args.tcp_z + 0.08)
    print(json.dumps({"waypoints": waypoints}, indent=1))


if __name__ == "__main__":
    main()
