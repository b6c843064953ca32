"""Reading a description file (a robot's or a gripper's) for the model generators: typed access
to its fields, with errors that name the file, the field and the problem."""
import json
import math
import pathlib


class DescriptionError(Exception):
    pass


def fmt(values):
    return " ".join(f"{float(x):.12g}" for x in values)


def _finite(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


class Reader:
    """Typed access to the description, with errors that name the field."""

    def __init__(self, path):
        self.path = path
        try:
            self.root = json.loads(pathlib.Path(path).read_text())
        except OSError as error:
            raise DescriptionError(f"{path}: cannot read: {error.strerror}")
        except json.JSONDecodeError as error:
            raise DescriptionError(f"{path}: line {error.lineno}, column {error.colno}: {error.msg}")
        if not isinstance(self.root, dict):
            raise DescriptionError(f"{path}: the top level must be an object")

    def fail(self, field, problem):
        raise DescriptionError(f"{self.path}: {field}: {problem}")

    def get(self, obj, key, field, kind, optional=False, default=None, positive=False):
        """obj[key], checked to be of `kind` (number, string, vec3, list, object); `field` names obj."""
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
        elif kind == "string":
            if not isinstance(value, str) or not value:
                self.fail(name, "must be a non-empty string")
        elif kind == "vec3":
            if not isinstance(value, list) or len(value) != 3 or not all(_finite(x) for x in value):
                self.fail(name, f"must be 3 finite numbers, not {json.dumps(value)}")
            if positive and min(value) <= 0:
                self.fail(name, "must be 3 positive numbers")
        elif kind == "list":
            if not isinstance(value, list) or not value:
                self.fail(name, "must be a non-empty list")
        elif kind == "object":
            if not isinstance(value, dict):
                self.fail(name, "must be an object")
        return value
