"""The ros2msg definitions moveplan ships (core/bag/cdr/msgs), per distro, and their fields parsed.

A schema text is a top-level .msg definition followed by every definition it depends on,
each after a line of "=" and a "MSG: pkg/Type" line (core/bag/cdr/msgs/README.md).
`parse_definitions` reads it as rosidl's .msg parser does, into what an encoder needs:
per message type its fields in order, each with its type, array kind and default.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache
from importlib.resources import files
from typing import Any

from ...errors import UsageError, known

__all__ = [
    "CONTROLLER_STATE",
    "POINT_SOURCES",
    "PRIMITIVES",
    "Field",
    "controller_state_fields",
    "parse_definitions",
    "schema_text",
]

CONTROLLER_STATE = "control_msgs/msg/JointTrajectoryControllerState"
# Humble's deprecated points repeat the new ones: ros2_controllers#1985 fills `desired`
# from the reference and `actual` from the feedback.
POINT_SOURCES = {
    "reference": "reference",
    "feedback": "feedback",
    "error": "error",
    "output": "output",
    "desired": "reference",
    "actual": "feedback",
}

PRIMITIVES = frozenset({
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16", "int32",
    "uint32", "int64", "uint64", "string", "wstring", "duration", "time",
})
_SEPARATOR = re.compile(r"^={3,}$", re.MULTILINE)
_MSG_LINE = re.compile(r"^MSG:\s+(\S+)$", re.MULTILINE)


@dataclass(frozen=True)
class Field:
    """One field of a message definition.

    Attributes:
        name: Field name.
        type: A primitive ("float64", "string"; a bounded string is "string") or a
            message type "pkg/Type".
        array: Whether the field is an array.
        size: Length of a fixed-size array, bound of a bounded one, None if unbounded.
        bounded: Whether `size` is an upper bound (`float64[<=3]`) rather than a length.
        default: The default written for a missing primitive value, None if the definition gives none.
    """

    name: str
    type: str
    array: bool = False
    size: int | None = None
    bounded: bool = False
    default: Any = None

    @property
    def primitive(self) -> bool:
        """Return whether the field's (element) type is a primitive, not a message."""
        return self.type in PRIMITIVES

    @property
    def fixed(self) -> bool:
        """Return whether the field is a fixed-size array (written without a length)."""
        return self.array and self.size is not None and not self.bounded


@cache
def schema_text(msgtype: str, distro: str) -> bytes:
    """Return the shipped ros2msg definition of `msgtype` ("pkg/msg/Type") for `distro`.

    The text is exactly what rosbag2 stores as an MCAP schema (see core/bag/cdr/msgs/README.md).
    """
    folder = files("moveplan.core.bag.cdr.msgs")
    distros = [entry.name for entry in folder.iterdir() if entry.is_dir() and entry.name.isalpha()]
    if distro not in distros:
        raise UsageError(f"unknown ROS distro '{distro}'; known: {known(distros)}")
    return folder.joinpath(distro, msgtype.replace("/", "__") + ".msg").read_bytes()


def parse_definitions(msgtype: str, text: str) -> dict[str, tuple[Field, ...]]:
    """Return the fields of every message a schema text defines, by "pkg/msg/Type" and "pkg/Type".

    The first definition is `msgtype`'s; each after it names itself in its "MSG:" line.

    Raises:
        ValueError: A line is not a field or constant, or a type or default is malformed.

    """
    text = "\n".join(line for line in text.splitlines() if line.strip())
    definitions: dict[str, tuple[Field, ...]] = {}
    name = msgtype
    for section in _SEPARATOR.split(text):
        section = section.strip()
        match = _MSG_LINE.match(section)
        if match:
            name = match.group(1)
            section = _MSG_LINE.sub("", section)
        package, short = name.split("/")[0], name.split("/")[-1]
        definitions[name] = definitions[f"{package}/{short}"] = _fields(package, section)
    return definitions


def _fields(package: str, text: str) -> tuple[Field, ...]:
    """Return the fields of one .msg definition of `package`; constants and comments are skipped."""
    fields = []
    for line in text.replace("\t", " ").splitlines():
        line = line.split("#", 1)[0].rstrip()
        if not line:
            continue
        type_string, _, rest = line.partition(" ")
        rest = rest.lstrip()
        if not rest:
            raise ValueError(f"not a field or constant: '{line}'")
        if "=" in rest:
            continue  # a constant
        name, _, default = rest.partition(" ")
        fields.append(_field(type_string, name, default.lstrip(), package))
    return tuple(fields)


def _field(type_string: str, name: str, default: str, package: str) -> Field:
    """Return a field of `type_string` ("float64[<=3]", "Point[]", "string<=8") in `package`."""
    array, size, bounded = type_string.endswith("]"), None, False
    if array:
        if "[" not in type_string:
            raise ValueError(f"type '{type_string}' ends with ']' but has no '['")
        type_string, _, bound = type_string[:-1].rpartition("[")
        if bound:
            bounded = bound.startswith("<=")
            size = int(bound.removeprefix("<="))
            if size <= 0:
                raise ValueError(f"array size of '{type_string}' must be > 0")
    if type_string.startswith(("string<=", "wstring<=")):
        type_string = type_string.split("<=", 1)[0]  # the bound is not enforced on writing
    if type_string not in PRIMITIVES:
        parts = type_string.split("/")
        if len(parts) > 2 or not all(parts):
            raise ValueError(f"invalid message type '{type_string}'")
        type_string = type_string if len(parts) == 2 else f"{package}/{type_string}"
    if not default:
        return Field(name, type_string, array, size, bounded)
    if array or type_string not in PRIMITIVES:
        raise ValueError(f"field '{name}': defaults are supported for primitive non-array fields only")
    return Field(name, type_string, array, size, bounded, _default(type_string, default))


def _default(type_name: str, text: str) -> Any:
    """Return the default value `text` of a primitive field, parsed as rosidl parses it."""
    if type_name == "bool":
        if text.lower() not in ("true", "1", "false", "0"):
            raise ValueError(f"bool default must be true, false, 1 or 0, got '{text}'")
        return text.lower() in ("true", "1")
    if type_name in ("float32", "float64"):
        return float(text)
    if type_name in ("string", "wstring"):
        for quote in ('"', "'"):
            if len(text) > 1 and text.startswith(quote) and text.endswith(quote):
                return text[1:-1].replace("\\" + quote, quote)
        return text
    try:
        return int(text)
    except ValueError:
        return int(text, 0)


@cache
def controller_state_fields(distro: str) -> tuple[tuple[str, str], ...]:
    """Return (kind, name) of each JointTrajectoryControllerState field of `distro`, in order.

    Read from the shipped schema, as the layouts differ (Humble keeps the deprecated
    desired/actual points, Jazzy adds speed_scaling_factor). Kinds: header, names, point,
    multi_dof_point, scale.

    Raises:
        UsageError: `distro` has no shipped message definitions.
        ValueError: The schema has a field these encoders do not know.

    """
    kinds = {
        "std_msgs/Header": "header",
        "string[]": "names",
        "trajectory_msgs/JointTrajectoryPoint": "point",
        "trajectory_msgs/MultiDOFJointTrajectoryPoint": "multi_dof_point",
        "float64": "scale",
    }
    root = schema_text(CONTROLLER_STATE, distro).decode().split("\n" + "=" * 80)[0]
    result = []
    for line in root.splitlines():
        words = line.split("#", 1)[0].split()
        if not words or "=" in line.split("#", 1)[0]:
            continue  # blank, comment or constant
        msgtype, name = words[0], words[1]
        kind = kinds.get(msgtype)
        known_point = kind != "point" or name in POINT_SOURCES
        if kind is None or not known_point or (kind == "scale" and name != "speed_scaling_factor"):
            raise ValueError(f"{CONTROLLER_STATE} ({distro}): unexpected field '{msgtype} {name}'")
        result.append((kind, name))
    return tuple(result)
