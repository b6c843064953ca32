#!/usr/bin/env python3
"""robots/generate_models.py: the models it writes from robots/iiwa14/iiwa14.json, and the errors
it gives for bad descriptions (file, field, problem; exit status 1; nothing written)."""
import unittest
import xml.etree.ElementTree as ET

from generator_case import ROOT, GeneratorCase

IIWA = ROOT / "robots" / "iiwa14" / "iiwa14.json"


class GenerateModels(GeneratorCase):
    GENERATOR = ROOT / "robots" / "generate_models.py"
    DESCRIPTION = IIWA
    VARIANT_NAME = "robot.json"

    def test_writes_both_models_with_the_described_chain(self):
        result = self.run_generator(IIWA, self.tmp)
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
        self.assertEqual(sorted(c.find("geometry")[0].tag for c in link1.findall("collision")), ["cylinder", "sphere", "sphere"])

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
        self.expect_error(lambda d: d["links"][1]["collision"][0].update(rgba=[2, 0, 0, 1]),
                          "links[1].collision[0].rgba", "4 numbers from 0 to 1")
        self.expect_error(lambda d: d["links"][1]["collision"][0].update(rgba=[0.5, 0.5, 0.5]),
                          "links[1].collision[0].rgba", "4 numbers from 0 to 1")
        # The joint origins must add up to the manufacturer's lengths.
        self.expect_error(lambda d: d["joints"][3].update(origin=[0, 0, 0.2255]), "published_lengths.shoulder_to_elbow",
                          "0.43")
        # Issue 27: a zero-length link and numbers of 1e308 passed.
        self.expect_error(lambda d: d["joints"][3].update(origin=[0, 0, 0], axis=[0, 0, 1]), "joints[3].origin",
                          "a link of zero length")
        self.expect_error(lambda d: d["joints"][2].update(origin=[0, 0, 1e308]), "joints[2].origin",
                          "magnitude at most 10")
        self.expect_error(lambda d: d["links"][2].update(mass=1e308), "links[2].mass", "at most 1000")
        self.expect_error(lambda d: d["joints"][2].update(effort_nm=1e308), "joints[2].effort_nm", "at most 1e+06")

    def test_a_shape_keeps_the_colour_it_is_given(self):
        ur5 = ROOT / "robots" / "ur5" / "ur5.json"
        result = self.run_generator(ur5, self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        geoms = {g.get("name"): g.get("rgba") for g in ET.parse(self.tmp / "ur5.xml").getroot().iter("geom")}
        self.assertEqual(geoms["base_link_collision_0"], "0.2 0.25 0.33 1")  # the UR5's dark blue cap
        self.assertEqual(geoms["shoulder_link_collision_0"], "0.7 0.72 0.75 1")  # its grey cover
        iiwa = self.run_generator(IIWA, self.tmp / "iiwa")
        self.assertEqual(iiwa.returncode, 0, iiwa.stderr)
        colours = [g.get("rgba") for g in ET.parse(self.tmp / "iiwa" / "iiwa14.xml").getroot().iter("geom")
                   if g.get("name", "").endswith("_collision_0")]
        self.assertTrue(colours and all(c is None for c in colours))  # the class's colour
        default = next(d for d in ET.parse(self.tmp / "iiwa" / "iiwa14.xml").getroot().iter("default") if d.get("class"))
        self.assertEqual(default.find("geom").get("rgba"), "0.93 0.55 0.13 1")  # orange when the description names none
        # The URDF draws every collision solid as a visual of the same solid in its colour (RViz, the editor).
        urdf = ET.parse(self.tmp / "ur5.urdf").getroot()
        for link in urdf.iter("link"):
            collisions, visuals = link.findall("collision"), link.findall("visual")
            self.assertEqual(len(visuals), len(collisions), link.get("name"))
            for c, v in zip(collisions, visuals):
                self.assertEqual(ET.tostring(c.find("geometry")), ET.tostring(v.find("geometry")))
                self.assertEqual(c.find("origin").attrib, v.find("origin").attrib)
        base = next(l for l in urdf.iter("link") if l.get("name") == "base_link")
        self.assertEqual(base.find("visual/material/color").get("rgba"), "0.2 0.25 0.33 1")

    def test_the_description_colours_every_shape_that_names_none(self):
        variant = self.variant(lambda d: d.update(rgba=[0.9, 0.9, 0.9, 1]))
        result = self.run_generator(variant, self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        default = next(d for d in ET.parse(self.tmp / "iiwa14.xml").getroot().iter("default") if d.get("class"))
        self.assertEqual(default.find("geom").get("rgba"), "0.9 0.9 0.9 1")
        urdf = ET.parse(self.tmp / "iiwa14.urdf").getroot()
        self.assertEqual({c.get("rgba") for c in urdf.iter("color")}, {"0.9 0.9 0.9 1"})
        self.expect_error(lambda d: d.update(rgba=[1, 1, 1]), "rgba", "4 numbers from 0 to 1")

    def test_the_models_carry_the_fingerprint_of_their_description(self):
        result = self.run_generator(IIWA, self.tmp)
        self.assertEqual(result.returncode, 0, result.stderr)
        value = 14695981039346656037
        for byte in IIWA.read_bytes():
            value = ((value ^ byte) * 1099511628211) % (1 << 64)
        self.assertEqual((self.tmp / "iiwa14.fingerprint").read_text(), f"fnv1a64:{value:016x}\n")

    def test_unreadable_input(self):
        broken = self.tmp / "robot.json"
        broken.write_text('{"format": ')
        result = self.run_generator(broken, self.tmp / "out")
        self.assertEqual(result.returncode, 1)
        self.assertIn("robot.json: line 1", result.stderr)
        result = self.run_generator(self.tmp / "missing.json", self.tmp / "out")
        self.assertEqual(result.returncode, 1)
        self.assertIn("cannot read", result.stderr)


if __name__ == "__main__":
    unittest.main()
