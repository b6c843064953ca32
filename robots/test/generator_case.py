"""What the generator tests share: run a generator on a description, or on a variant of it
changed by the test, and check the error it gives (file, field, problem; exit status 1;
nothing written)."""
import json
import pathlib
import subprocess
import sys
import tempfile
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def run(generator, description, out):
    return subprocess.run([sys.executable, str(generator), str(description), str(out)], capture_output=True, text=True)


class GeneratorCase(unittest.TestCase):
    """Subclasses set GENERATOR (the script), DESCRIPTION (the good description) and
    VARIANT_NAME (the file name a changed description is written under)."""
    GENERATOR = None
    DESCRIPTION = None
    VARIANT_NAME = "description.json"

    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.tmp = pathlib.Path(self.dir.name)

    def tearDown(self):
        self.dir.cleanup()

    def run_generator(self, description, out):
        return run(self.GENERATOR, description, out)

    def variant(self, change):
        data = json.loads(self.DESCRIPTION.read_text())
        change(data)
        path = self.tmp / self.VARIANT_NAME
        path.write_text(json.dumps(data))
        return path

    def expect_error(self, change, *fragments):
        out = self.tmp / "out"
        result = self.run_generator(self.variant(change), out)
        self.assertEqual(result.returncode, 1, result.stderr)
        for fragment in (self.VARIANT_NAME,) + fragments:
            self.assertIn(fragment, result.stderr)
        self.assertFalse(out.exists(), "nothing is written for a bad description")
