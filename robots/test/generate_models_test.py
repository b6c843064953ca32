#!/usr/bin/env python3
"""robots/generate_models.py: the models it writes from robots/iiwa14/iiwa14.json, and the errors
it gives for bad descriptions (file, field, problem; exit status 1; nothing written)."""
import json
import pathlib
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

ROOT = pathlib.Path(__file__).resolve().parents[2]
GENERATOR = ROOT / "robots" / "generate_models.py"
IIWA = ROOT / "robots" / "iiwa14" / "iiwa14.json"


def run(description, out):
    return subprocess.run([sys.executable, str(GENERATOR), str(description), str(out)], capture_output=True, text=True)


class GenerateModels(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.tmp = pathlib.Path(self.dir.name)

    def tearDown(self):
        self.dir.cleanup()

    def variant(self, change):
        data = json.loads(IIWA.read_text())
        change(data)
        path = self.tmp / "robot.json"
        path.write_text(json.dumps(data))
        return path

    def expect_error(self, change, *fragments):
        out = self.tmp / "out"
        result = run(self.variant(change), out)
        self.assertEqual(result.returncode, 1, result.stderr)
        for fragment in ("robot.json",) + fragments:
            self.assertIn(fragment, result.stderr)
        self.assertFalse(out.exists(), "nothing is written for a bad description")

    def test_writes_both_models_with_the_described_chain(self):
        result = run(IIWA, self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        mjcf = ET.parse(self.tmp / "iiwa14.xml").getroot()
        urdf = ET.parse(self.tmp / "iiwa14.urdf").getroot()
        names = [f"iiwa_joint_{i}" for i in range(1, 8)]
        self.assertEqual([j.get("name") for j in mjcf.find("worldbody").iter("joint")], names)
        self.assertEqual([m.get("joint") for m in mjcf.iter("motor")], names)
        self.assertEqual([j.get("name") for j in urdf.iter("joint") if j.get("type") == "revolute"], names)
        limits = [float(l.get("upper")) for l in urdf.iter("limit")]
        self.assertAlmostEqual(limits[0], 170 * 3.141592653589793 / 180, places=9)
        self.assertAlmostEqual(limits[6], 175 * 3.141592653589793 / 180, places=9)
        # Capsules: a cylinder and two spheres in the URDF.
        link1 = next(l for l in urdf.iter("link") if l.get("name") == "iiwa_link_1")
        self.assertEqual(sorted(g[0].tag for g in link1.iter("geometry")), ["cylinder", "sphere", "sphere"])

    def test_bad_descriptions_name_the_field(self):
        self.expect_error(lambda d: d["joints"][3].update(axis=[0, -1, 1]), "joints[3].axis", "unit vector")
        self.expect_error(lambda d: d["joints"][2].update(parent="iiwa_link_0"), "joints[2].parent")
        self.expect_error(lambda d: d["joints"][1].update(lower_deg=130), "joints[1]", "lower_deg must be below")
        self.expect_error(lambda d: d["joints"][0].pop("effort_nm"), "joints[0].effort_nm", "missing")
        self.expect_error(lambda d: d["links"][2].update(mass=-1), "links[2]", "positive")
        self.expect_error(lambda d: d["links"][2].update(inertia=[1, 0.1, 0.1]), "links[2].inertia", "triangle")
        self.expect_error(lambda d: d.update(home_deg=[0, 0, 0]), "home_deg", "7 values")
        self.expect_error(lambda d: d["tool"].update(parent="iiwa_link_3"), "tool.parent")
        self.expect_error(lambda d: d["links"][1]["collision"][0].update(type="mesh"), "links[1].collision[0].type")
        # The joint origins must add up to the manufacturer's lengths.
        self.expect_error(lambda d: d["joints"][3].update(origin=[0, 0, 0.2255]), "published_lengths.shoulder_to_elbow",
                          "0.43")

    def test_unreadable_input(self):
        broken = self.tmp / "robot.json"
        broken.write_text('{"format": ')
        result = run(broken, self.tmp / "out")
        self.assertEqual(result.returncode, 1)
        self.assertIn("robot.json: line 1", result.stderr)
        result = run(self.tmp / "missing.json", self.tmp / "out")
        self.assertEqual(result.returncode, 1)
        self.assertIn("cannot read", result.stderr)


if __name__ == "__main__":
    unittest.main()
