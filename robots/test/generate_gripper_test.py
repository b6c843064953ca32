#!/usr/bin/env python3
"""robots/generate_gripper.py: the model it writes from robots/grippers/robotiq3f.json, and the
errors it gives for bad descriptions (file, field, problem; exit status 1; nothing written)."""
import math
import unittest
import xml.etree.ElementTree as ET

from generator_case import ROOT, GeneratorCase

ROBOTIQ = ROOT / "robots" / "grippers" / "robotiq3f.json"


def setter(path, value):
    """A change to a description: the field at `path` (keys and indices) set to `value`."""
    def change(d):
        target = d
        for key in path[:-1]:
            target = target[key]
        target[path[-1]] = value
    return change


class GenerateGripper(GeneratorCase):
    GENERATOR = ROOT / "robots" / "generate_gripper.py"
    DESCRIPTION = ROBOTIQ
    VARIANT_NAME = "robotiq3f.json"  # a description's name is its file's

    def test_writes_three_underactuated_fingers_and_a_scissor_axis(self):
        result = self.run_generator(ROBOTIQ, self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        alone = ET.parse(self.tmp / "robotiq3f.xml").getroot()
        body = ET.parse(self.tmp / "robotiq3f_body.xml").getroot()
        sections = ET.parse(self.tmp / "robotiq3f_sections.xml").getroot()
        fingers = ["finger_middle", "finger_1", "finger_2"]
        joints = [j.get("name") for j in body.iter("joint")]
        for finger in fingers:
            for phalanx in ("proximal", "medial", "distal"):
                self.assertIn(f"robotiq3f_{finger}_{phalanx}", joints)
        # Fingers 1 and 2 turn on the scissor axis, in opposite senses; finger_middle does not.
        scissors = {j.get("name"): j.get("axis") for j in body.iter("joint") if j.get("name").endswith("_scissor")}
        self.assertEqual(scissors, {"robotiq3f_finger_1_scissor": "0 0 1", "robotiq3f_finger_2_scissor": "0 0 -1"})
        # Per finger a flexion tendon (proximal + medial) that a force-limited servo pulls.
        tendons = {t.get("name"): [j.get("joint") for j in t.iter("joint")] for t in sections.iter("fixed")}
        self.assertEqual(len(tendons), 3)
        self.assertEqual(tendons["robotiq3f_finger_1_flex"], ["robotiq3f_finger_1_proximal", "robotiq3f_finger_1_medial"])
        servos = {p.get("name"): p for p in sections.iter("position")}
        self.assertEqual(set(servos), {"robotiq3f_" + f for f in fingers} | {"robotiq3f_scissor"})
        force = [float(x) for x in servos["robotiq3f_finger_1"].get("forcerange").split()]
        self.assertAlmostEqual(force[1], 60 * 0.07)  # max_force_n x lever_m
        closed = float(servos["robotiq3f_finger_1"].get("ctrlrange").split()[1])
        self.assertAlmostEqual(closed, math.radians(110))  # closed_deg
        equalities = [e.get("name") for e in sections.find("equality")]
        self.assertEqual(equalities[0], "robotiq3f_finger_2_scissor_coupling")
        # For fingertip modes, per finger: the medial and distal phalanges straight; off until a
        # mode needs them.
        locks = [e for e in sections.find("equality") if e.get("name").endswith(("_medial_lock", "_distal_lock"))]
        self.assertEqual(len(locks), 6)
        self.assertTrue(all(e.get("active") == "false" for e in locks))
        # The gripper's geoms touch parts (contype 2), not each other (conaffinity 0).
        self.assertTrue(all(g.get("contype") == "2" and g.get("conaffinity") == "0" for g in body.iter("geom")))
        # The standalone model holds both.
        self.assertEqual(len(list(alone.iter("fixed"))), 3)
        self.assertEqual(alone.find("worldbody/body").get("name"), "robotiq3f_base")

    def test_bad_descriptions_name_the_field(self):
        def drop(key):
            return lambda d: d.pop(key)

        self.expect_error(drop("modes"), "modes: missing")
        self.expect_error(setter(["kind"], "vacuum"), 'kind: "vacuum" is not one of adaptive-3f, parallel')
        self.expect_error(setter(["name"], "other"), 'name: "other" must be the file\'s name (robotiq3f)')
        self.expect_error(setter(["format"], "x"), "format: must be")
        self.expect_error(setter(["fingers", 1, "scissor_sign"], 2), "fingers[1].scissor_sign: must be -1, 0")
        self.expect_error(setter(["fingers", 2, "name"], "finger_1"), 'fingers[2].name: "finger_1" appears twice')
        self.expect_error(lambda d: d["fingers"].pop(), "fingers: a 3-finger gripper needs 3 fingers, not 2")
        self.expect_error(setter(["fingers", 0, "name"], "thumb"), "fingers: must be finger_middle, finger_1, finger_2")
        self.expect_error(setter(["fingers", 0, "scissor_sign"], 1), "fingers[0].scissor_sign: must be 0")
        self.expect_error(setter(["phalanges", 0, "length"], -0.05), "phalanges[0].length: must be positive")
        self.expect_error(setter(["phalanges", 1, "lower_deg"], 10), "phalanges[1]: the straight finger")
        self.expect_error(setter(["modes", 3, "scissor_deg"], 120), "modes[3].scissor_deg: must be within")
        self.expect_error(setter(["modes", 0, "closing"], ["finger_9"]), 'modes[0].closing[0]: "finger_9" is not a finger')
        self.expect_error(setter(["modes", 1, "name"], "wide"), 'modes[2].name: "wide" appears twice')
        self.expect_error(setter(["actuation", "max_force_n"], "a lot"), "actuation.max_force_n: must be a finite number")
        self.expect_error(setter(["tcp"], [0, 0]), "tcp: must be 3 finite numbers")
        self.expect_error(setter(["actuation", "closed_deg"], 200), "actuation.closed_deg: must be above the open finger")
        self.expect_error(setter(["phalanges", 1, "spring_rest_deg"], 5), "phalanges[1].spring_rest_deg: must be at most 0")
        # Issue 27: sizes beyond a hand's passed.
        self.expect_error(setter(["phalanges", 2, "length"], 1e308), "phalanges[2].length: must be at most 0.5 in magnitude")
        self.expect_error(setter(["palm", "centre"], [0, 0, 1e308]), "palm.centre: must be 3 numbers of magnitude at most 1")
        self.expect_error(setter(["actuation", "max_force_n"], 1e308), "actuation.max_force_n: must be at most 1e+06")

    def test_a_key_given_twice_is_refused(self):
        text = self.DESCRIPTION.read_text().replace('"tcp": [', '"tcp": [0, 0, 0.1], "tcp": [', 1)
        path = self.tmp / "gripper.json"
        path.write_text(text)
        result = self.run_generator(path, self.tmp / "out")
        self.assertEqual(result.returncode, 1)
        self.assertIn("gripper.json: key 'tcp' appears twice", result.stderr)

    def test_the_models_carry_the_fingerprint_of_their_description(self):
        result = self.run_generator(self.DESCRIPTION, self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        # FNV-1a 64 of the bytes, as core/files.h fingerprint() computes it.
        value = 14695981039346656037
        for byte in self.DESCRIPTION.read_bytes():
            value = ((value ^ byte) * 1099511628211) % (1 << 64)
        self.assertEqual((self.tmp / "robotiq3f.fingerprint").read_text(), f"fnv1a64:{value:016x}\n")

    def test_unreadable_json_names_the_line(self):
        path = self.tmp / "gripper.json"
        path.write_text('{\n  "format": \n}')
        result = self.run_generator(path, self.tmp / "out")
        self.assertEqual(result.returncode, 1)
        self.assertIn("gripper.json: line 3", result.stderr)


PARALLEL = ROOT / "robots" / "grippers" / "parallel-2f.json"
FRANKA = ROOT / "robots" / "grippers" / "franka-hand.json"


class GenerateParallelGripper(GeneratorCase):
    GENERATOR = ROOT / "robots" / "generate_gripper.py"
    DESCRIPTION = PARALLEL
    VARIANT_NAME = "parallel-2f.json"

    def generated(self, description):
        result = self.run_generator(description, self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        name = description.stem
        return ET.parse(self.tmp / f"{name}_mount.xml").getroot(), ET.parse(self.tmp / f"{name}.urdf").getroot()

    def test_the_fingers_slide_coupled_with_the_stroke_and_force_described(self):
        for description, half, force in ((PARALLEL, 0.0425, 60), (FRANKA, 0.04, 70)):
            mount, urdf = self.generated(description)
            joints = {j.get("name"): j for j in mount.iter("joint") if j.get("type") == "slide"}
            self.assertEqual(set(joints), {"left_finger_joint", "right_finger_joint"})
            self.assertEqual(joints["left_finger_joint"].get("axis"), "0 1 0")
            self.assertEqual(joints["right_finger_joint"].get("axis"), "0 -1 0")
            self.assertAlmostEqual(float(joints["left_finger_joint"].get("range").split()[1]), half)
            servo = mount.find("actuator/position")
            self.assertEqual(servo.get("name"), "fingers")
            self.assertAlmostEqual(float(servo.get("ctrlrange").split()[1]), half)  # the simulator's stroke / 2
            self.assertAlmostEqual(float(servo.get("forcerange").split()[1]), force)
            self.assertEqual(mount.find("equality/joint").get("name"), "finger_coupling")
            pads = {g.get("name"): g for g in mount.iter("geom") if g.get("class") == "finger_pad"}
            self.assertEqual(set(pads), {"left_pad", "right_pad"})
            # The pads' inner faces touch when closed: centre y = half its thickness, mirrored.
            left = [float(x) for x in pads["left_pad"].get("pos").split()]
            right = [float(x) for x in pads["right_pad"].get("pos").split()]
            self.assertAlmostEqual(left[1], float(pads["left_pad"].get("size").split()[1]))
            self.assertAlmostEqual(right[1], -left[1])
            self.assertIsNotNone(mount.find("worldbody/body[@name='mount']/site[@name='tcp']"))
            self.assertIsNotNone(mount.find("worldbody/body[@name='mount']/geom[@name='gripper_marker']"))
            # The planner's fingers: one box over the whole travel, fully open outer faces included.
            travel = [float(x) for x in urdf.find("link[@name='fingers']/collision/geometry/box").get("size").split()]
            self.assertGreater(travel[1], 2 * half + 0.01)
            self.assertEqual(urdf.find("joint[@name='tool_centre_point']/parent").get("link"), "fingers")

    def test_bad_descriptions_name_the_field(self):
        self.expect_error(setter(["stroke_m"], -0.08), "stroke_m: must be positive")
        self.expect_error(setter(["finger", "pad", "centre"], [0, 0.01, 0.14]), "finger.pad: the closed pad's inner face must be on y = 0")
        self.expect_error(setter(["finger", "link", "centre"], [0, -0.02, 0.12]), "finger.link: the +y finger's box must lie at y >= 0")
        self.expect_error(setter(["body", "size"], [0.07, 0.05, 0.07]), "body.size: the body's +x face must hold the 6.67 cm calibration marker")
        self.expect_error(setter(["grip_force_n", "default"], 500), "grip_force_n.default: must be at most grip_force_n.max")
        self.expect_error(setter(["servo", "kp"], 0), "servo.kp: must be positive")
        self.expect_error(lambda d: d.pop("finger"), "finger: missing")
        self.expect_error(setter(["name"], "parallel 2f"), 'name: "parallel 2f" must be the file\'s name')


if __name__ == "__main__":
    unittest.main()
