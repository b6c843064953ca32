"""Reading a description file (a robot's or a gripper's) for the model generators: typed access
to its fields, with errors that name the file, the field and the problem."""
import json
import math
import pathlib


class DescriptionError(Exception):
    pass


def fingerprint(path):
    """FNV-1a (64 bits) of the file's bytes, as core/files.h fingerprint() writes it: the runtime
    compares it with the description it reads, so that a description edited after the build is
    refused instead of applied in part (the simulator uses these models, the runtime the JSON)."""
    value = 14695981039346656037
    for byte in pathlib.Path(path).read_bytes():
        value ^= byte
        value = (value * 1099511628211) % (1 << 64)
    return f"fnv1a64:{value:016x}"


def write_fingerprint(source, out_file):
    """NAME.fingerprint beside the generated models: the fingerprint of the description they
    were generated from (core/files.h checkGeneratedFrom reads it)."""
    pathlib.Path(out_file).write_text(fingerprint(source) + "\n")


def fmt(values):
    return " ".join(f"{float(x):.12g}" for x in values)


# The hand-eye calibration marker every generated gripper carries on its body's +x face
# (DICT_4X4_50 id 1, docs/CALIBRATION.md): 6.67 cm square with its white quiet zone, image right
# along -y of the flange, image up towards the flange, 0.3 mm off the face.
MARKER_HALF = 0.033333
MARKER_ASSET = ['<asset>',
                '  <texture name="gripper_marker" type="2d" file="aruco_4x4_50_id1.png"/>',
                '  <material name="gripper_marker" texture="gripper_marker" texrepeat="1 1" texuniform="false" '
                'specular="0" shininess="0" reflectance="0"/>',
                '</asset>']


def marker_geom(face_centre, cls=None):
    """The marker's geom on a +x face whose centre is `face_centre` (a visual-only sticker)."""
    pos = [face_centre[0] + 0.0003, face_centre[1], face_centre[2]]
    klass = f' class="{cls}"' if cls else ""
    return (f'<geom name="gripper_marker"{klass} type="box" pos="{fmt(pos)}" '
            f'xyaxes="0 -1 0 0 0 -1" size="{MARKER_HALF} {MARKER_HALF} 0.0003" material="gripper_marker" '
            'contype="0" conaffinity="0" group="2" mass="0"/>')


def _no_duplicates(pairs):
    """An object's keys, each once: a key given twice is refused (json keeps the last silently)."""
    seen = {}
    for key, value in pairs:
        if key in seen:
            raise DescriptionError(f"key '{key}' appears twice (a key may appear once in an object)")
        seen[key] = value
    return seen


def _finite(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


class Reader:
    """Typed access to the description, with errors that name the field."""

    def __init__(self, path):
        self.path = path
        try:
            self.root = json.loads(pathlib.Path(path).read_text(), object_pairs_hook=_no_duplicates)
        except OSError as error:
            raise DescriptionError(f"{path}: cannot read: {error.strerror}")
        except json.JSONDecodeError as error:
            raise DescriptionError(f"{path}: line {error.lineno}, column {error.colno}: {error.msg}")
        except DescriptionError as error:
            raise DescriptionError(f"{path}: {error}")
        if not isinstance(self.root, dict):
            raise DescriptionError(f"{path}: the top level must be an object")

    def fail(self, field, problem):
        raise DescriptionError(f"{self.path}: {field}: {problem}")

    # No number in a description is larger than this (1e308 is a typing error, and overflows what
    # the simulator computes from it); fields with a tighter bound pass it as `at_most`.
    LARGEST = 1e6

    def get(self, obj, key, field, kind, optional=False, default=None, positive=False, at_most=LARGEST):
        """obj[key], checked to be of `kind` (number, string, vec3, list, object); `field` names obj.
        A number or each of a vec3's is at most `at_most` in magnitude."""
        name = f"{field}.{key}" if field else key
        if not isinstance(obj, dict):
            self.fail(field, "must be an object")
        if key not in obj:
            if optional:
                return default
            self.fail(name, "missing")
        value = obj[key]
        if kind == "number":
            if not _finite(value):
                self.fail(name, f"must be a finite number, not {json.dumps(value)}")
            if positive and value <= 0:
                self.fail(name, f"must be positive, not {value}")
            if abs(value) > at_most:
                self.fail(name, f"must be at most {at_most:g} in magnitude, not {value:g}")
        elif kind == "string":
            if not isinstance(value, str) or not value:
                self.fail(name, "must be a non-empty string")
        elif kind == "vec3":
            if not isinstance(value, list) or len(value) != 3 or not all(_finite(x) for x in value):
                self.fail(name, f"must be 3 finite numbers, not {json.dumps(value)}")
            if positive and min(value) <= 0:
                self.fail(name, "must be 3 positive numbers")
            if max(abs(x) for x in value) > at_most:
                self.fail(name, f"must be 3 numbers of magnitude at most {at_most:g}, not {fmt(value)}")
        elif kind == "list":
            if not isinstance(value, list) or not value:
                self.fail(name, "must be a non-empty list")
        elif kind == "object":
            if not isinstance(value, dict):
                self.fail(name, "must be an object")
        return value
