"""Reading YAML files and checking their fields, with the file and key path in every error.

Shared by every parser of a configuration file: robot config, scene, task and MoveIt requests.
"""

from __future__ import annotations

import ast
import itertools
import math
import operator
import os
import re
import stat
from collections.abc import Callable, Hashable, Mapping
from pathlib import Path
from typing import Any

import yaml

from ..errors import ConfigError, MoveplanError, known
from ._plain_yaml import DECLINED, read_plain

__all__ = [
    "DEGREES", "MAX_ALIAS_EXPANSION", "MAX_EXPRESSION_LENGTH", "MAX_MAGNITUDE", "MAX_YAML_BYTES", "MAX_YAML_EVENTS",
    "TURN", "angle", "beyond_a_turn", "boolean", "check_keys", "coordinate", "coordinates", "expression", "load_yaml",
    "mapping",
    "read_input", "read_input_text", "text_of",
    "more_than_a_turn", "number", "parse_yaml", "pose_angle", "pose_angles", "string_list",
]


def _libyaml_parser() -> Any:
    """Return libyaml's parser class, None in a PyYAML built without libyaml."""
    try:
        from yaml.cyaml import CParser  # type: ignore[attr-defined]  # cyaml's __all__ omits it
    except ImportError:
        return None
    return CParser


_CParser = _libyaml_parser()

MAX_MAGNITUDE = 1e6
"""Largest |value| of a position in [rad] or [m] or a time in [s] from a flag or a task: a million
radians, a thousand kilometres, eleven days. Beyond it, a typo (1e308) must not reach the planner."""

MAX_EXPRESSION_LENGTH = 100
"""Characters of one number or pi expression: `-pi/2+0.25` is 10, a double written in full 25."""

TURN = 2.0 * math.pi
"""One full turn in [rad]. A pose angle, or a revolute joint value outside its limits, given without a unit
beyond it is refused: it reads as degrees (`180` for pi)."""

DEGREES = "deg"
"""The suffix of an angle given in degrees: `90deg`."""

_TURN_SLACK = 1e-4  # [rad]: 6.2832, 2*pi rounded by hand, is still a turn

_BINARY: dict[type, Callable[[float, float], float]] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
}

MAX_ALIAS_EXPANSION = 100_000
"""Values YAML aliases may add to a file once expanded: ROS files reuse a joint list or a block of
gains a few times; a "billion laughs" file adds billions (docs/formats.md, Limits)."""

MAX_YAML_BYTES = 64 * 1024 * 1024
"""Size of a YAML file moveplan reads: a MotionBenchMaker scene is ~10 kB, a 10,000-shape scene ~2 MB."""

MAX_YAML_EVENTS = 3_000_000
"""Parse events a YAML file may hold (one per value, two per list or mapping): a 10,000-shape scene
has ~350,000, a 100,000-triangle inline mesh ~1,300,000. Counted before the file is built into Python
values, which costs ~50 times more: a 200,000-shape scene is refused in a second, not in a minute."""

# ROS 2 reads a parameter as a double when strtod accepts it, and yaml-cpp (MoveIt's scenes and requests)
# likewise: `1.0e9`, `1e9` and `1e-3` are numbers there, strings to YAML 1.1's float pattern.
_ROS_FLOAT = re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$")


class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):  # type: ignore[misc]  # a base chosen at import
    """PyYAML's safe loader, reading numbers with an exponent as ROS does.

    libyaml's where PyYAML has it: it reads a MotionBenchMaker scene 10x faster.
    """


_Loader.add_implicit_resolver("tag:yaml.org,2002:float", _ROS_FLOAT, list("-+0123456789."))
# xacro.load_yaml adds unit tags (!degrees, ...) to PyYAML's SafeLoader that evaluate xacro expressions:
# a file moveplan reads gets PyYAML's safe constructors alone, whichever loader it derives from.
_Loader.yaml_constructors = dict(yaml.constructor.SafeConstructor.yaml_constructors)


class _MergingLoader(_Loader):
    """_Loader that merges a mapping's repeated keys as rcl merges a ROS 2 parameter file's.

    Several `/**:` blocks in one file all apply: mappings merge key by key, a later scalar wins.
    """

    def construct_mapping(self, node: Any, deep: bool = False) -> dict[Any, Any]:
        self.flatten_mapping(node)
        merged: dict[Any, Any] = {}
        for key_node, value_node in node.value:
            key = self.construct_object(key_node, deep=True)
            if not isinstance(key, Hashable):  # as PyYAML's own construct_mapping refuses it
                raise yaml.constructor.ConstructorError("while constructing a mapping", node.start_mark,
                                                        "found unhashable key", key_node.start_mark)
            value = self.construct_object(value_node, deep=True)  # deep: a lazily built mapping would merge empty
            merged[key] = _merged(merged[key], value) if key in merged else value
        return merged


_MergingLoader.add_constructor("tag:yaml.org,2002:map", _MergingLoader.construct_mapping)


def _merged(old: Any, new: Any) -> Any:
    """Return `new` over `old`: mappings key by key (recursively), anything else `new`."""
    if isinstance(old, dict) and isinstance(new, dict):
        return {**old, **{k: _merged(old[k], v) if k in old else v for k, v in new.items()}}
    return new


def load_yaml(path: Path, merge: bool = False) -> Any:
    """Return the parsed content of a YAML file; ConfigError names the file and line.

    With `merge`, repeated keys of a mapping merge as rcl merges a ROS 2 parameter file's.

    A file larger than MAX_YAML_BYTES, or with more than MAX_YAML_EVENTS parse events, is refused
    before its values are built. Aliases may add at most MAX_ALIAS_EXPANSION values to the
    document (and may not contain themselves), so that no reader of the result walks a billion
    shared copies.
    """
    return parse_yaml(read_input_text(path), path, merge=merge)


def read_input(path: Path, limit: int = MAX_YAML_BYTES) -> bytes:
    """Return the bytes of the regular file `path`; ConfigError if it is missing, not a regular file or over `limit`.

    A device (/dev/zero), FIFO or socket never ends or blocks: it is refused before it is read, and
    the read itself stops after `limit` bytes whatever the file's size claims.
    """
    try:
        # O_NONBLOCK: opening a FIFO must not wait for a writer; it is refused just below.
        descriptor = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except FileNotFoundError:
        raise ConfigError(f"{path}: file not found") from None
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror or exc}") from None
    mode = os.fstat(descriptor).st_mode
    if not stat.S_ISREG(mode):
        os.close(descriptor)
        if stat.S_ISDIR(mode):
            raise ConfigError(f"{path}: a folder, not a file")
        raise ConfigError(f"{path}: not a regular file (a device, FIFO or socket); moveplan reads files")
    with os.fdopen(descriptor, "rb") as stream:
        try:
            data = stream.read(limit + 1)
        except OSError as exc:
            raise ConfigError(f"{path}: cannot read: {exc.strerror or exc}") from None
    if len(data) > limit:
        raise ConfigError(f"{path}: more than {limit:,} bytes; moveplan reads files of at most {limit:,} bytes")
    return data


def read_input_text(path: Path, limit: int = MAX_YAML_BYTES) -> str:
    """Return the UTF-8 text of the regular file `path`, read as read_input reads it."""
    return text_of(read_input(path, limit), path)


def text_of(data: bytes, path: Path) -> str:
    """Return the UTF-8 text of `data`, read from `path`; ConfigError names the file and the first bad byte."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{path}: cannot read: not UTF-8 text ({exc.reason} at byte {exc.start})") from None


def parse_yaml(text: str, path: Path, after: str = "", merge: bool = False) -> Any:
    """Return YAML `text` parsed under load_yaml's limits; ConfigError names `path`, the line and `after`."""
    try:
        events = _count_events(text)
        if events > MAX_YAML_EVENTS:
            raise ConfigError(f"{path}: more than {MAX_YAML_EVENTS:,} YAML values (lists and mappings count twice); "
                              "moveplan reads at most that many per file (a 10,000-shape scene has ~350,000)")
        content = read_plain(text, _Loader, _merged if merge else None)
        if content is DECLINED:
            content = yaml.load(text, Loader=_MergingLoader if merge else _Loader)  # noqa: S506 - safe loaders
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" line {mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ConfigError(f"{path}:{where} malformed YAML{after}: {problem}") from None
    except ValueError as exc:  # a date YAML resolves but the calendar refuses (2024-02-30)
        raise ConfigError(f"{path}: malformed YAML{after}: {exc}") from None
    if "*" in text:  # an alias is written *name: without one, nothing is shared (half of a scene's parse)
        _check_aliases(content, path)
    return content


def _count_events(text: str) -> int:
    """Return the parse events of `text`, building no value (without libyaml, counted up to MAX_YAML_EVENTS + 1)."""
    if _CParser is not None:
        # libyaml counts the events in C, creating no Python object: ~40 MB/s.
        return int(_CParser(text).raw_parse())
    return sum(1 for _ in itertools.islice(yaml.parse(text, Loader=_Loader), MAX_YAML_EVENTS + 1))


def _check_aliases(content: Any, path: Path) -> None:
    """Raise ConfigError if aliases make `content` contain itself or grow by more than MAX_ALIAS_EXPANSION values.

    An alias is the same Python object in several places: the document as written holds each
    container once, as expanded once per place. Both counts are made without expanding anything.
    """
    written = 0
    expanded: dict[int, int] = {}  # id(container) -> values in it, expanded
    open_ids: set[int] = set()
    stack: list[tuple[Any, bool]] = [(content, False)] if isinstance(content, dict | list) else []
    while stack:
        node, done = stack.pop()
        key = id(node)
        children = list(node.values()) + list(node) if isinstance(node, dict) else node
        if done:
            open_ids.discard(key)
            expanded[key] = 1 + sum(expanded.get(id(c), 1) for c in children)
            continue
        if key in expanded:
            continue
        if key in open_ids:
            raise ConfigError(f"{path}: a YAML alias refers to a node that contains it; "
                              "moveplan reads no recursive documents")
        open_ids.add(key)
        written += 1 + len(children)
        stack.append((node, True))
        stack.extend((c, False) for c in children if isinstance(c, dict | list))
    total = expanded.get(id(content), 1)
    if total - written > MAX_ALIAS_EXPANSION:
        raise ConfigError(f"{path}: YAML aliases expand the document by more than {MAX_ALIAS_EXPANSION} values "
                          "(moveplan's limit, against alias bombs)")


def mapping(value: Any, where: str) -> dict[str, Any]:
    """Return `value` if it is a mapping with string keys, else raise ConfigError at `where`."""
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise ConfigError(f"{where}: expected a mapping, got {type(value).__name__}")
    for key in value:
        if not isinstance(key, str):
            raise ConfigError(f"{where}: keys must be names, got {str(key)[:60]!r}")
    return dict(value)


def check_keys(value: Mapping[str, Any], allowed: set[str] | frozenset[str], where: str) -> None:
    """Raise ConfigError for the first key of `value` not in `allowed` (typos must not pass)."""
    for key in value:
        if key not in allowed:
            raise ConfigError(f"{where}: unknown key '{key}'; expected one of: {known(allowed)}")


def number(value: Any, where: str, positive: bool = False, bound: float | None = None) -> float:
    """Return `value` as a finite float, else raise ConfigError at `where`.

    With `bound`, |value| must not exceed it (MAX_MAGNITUDE for positions and times).
    """
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ConfigError(f"{where}: expected a finite number, got {_shown(value)}")
    if isinstance(value, int) and abs(value) > 1e300:  # float() of a 400-digit integer overflows
        value = math.inf
    if not math.isfinite(value):
        raise ConfigError(f"{where}: expected a finite number, got {_shown(value)}")
    if positive and value <= 0:
        raise ConfigError(f"{where}: expected a positive number, got {value!r}")
    if bound is not None and abs(value) > bound:
        raise ConfigError(f"{where}: {value:g} is out of range; values are limited to |value| <= {bound:,.0f}")
    return float(value)


def coordinate(value: Any, where: str) -> float:
    """Return a position in [rad] or [m] or a time in [s], checked to be finite and within MAX_MAGNITUDE."""
    return number(value, where, bound=MAX_MAGNITUDE)


def coordinates(values: list[Any] | tuple[Any, ...], where: str) -> list[float]:
    """Return a list's numbers as `coordinate` checks each, the first bad one named `where[i]`."""
    # A scene has hundreds of numbers: checked in one pass, each error message made only when one is bad.
    try:
        floats = [float(v) for v in values if type(v) is float or type(v) is int]  # not bool, a subclass of int
    except OverflowError:  # an integer of hundreds of digits: coordinate names it
        floats = []
    if len(floats) == len(values) and all(-MAX_MAGNITUDE <= v <= MAX_MAGNITUDE for v in floats):  # NaN is not
        return floats
    return [coordinate(v, f"{where}[{i}]") for i, v in enumerate(values)]


def expression(text: str, where: str, error: type[MoveplanError] = ConfigError) -> float:
    """Return the number `text` spells: a decimal, or an expression of numbers and pi (`-pi/2+0.25`).

    Raises:
        error: Not such an expression, longer than MAX_EXPRESSION_LENGTH characters, a value (or an
            intermediate value) beyond MAX_MAGNITUDE, or a deg suffix, which only angles take.
    """
    text = text.strip()
    shown = _shown_text(text)
    if text.endswith(DEGREES):
        raise error(f"{where}: {shown}: a '{DEGREES}' suffix is for angles (pose roll, pitch, yaw and revolute "
                    "joint values), not for this value")
    return _evaluate(text, where, error, shown, "a number or an expression like pi/2")


def angle(value: Any, where: str, error: type[MoveplanError] = ConfigError) -> tuple[float, bool]:
    """Return an angle in [rad], and whether it was written in degrees.

    `value` is a number in [rad] (from YAML), or text: a number or pi expression in [rad]
    (`pi/2`), or degrees with a deg suffix (`90deg`, `-45 deg`). `error` is raised for text
    that is none of these (UsageError for a flag; a YAML value is always a ConfigError).
    """
    if not isinstance(value, str):
        return coordinate(value, where), False
    text = value.strip()
    expected = "a number in radians (1.57, pi/2) or degrees (90deg)"
    if text.endswith(DEGREES):
        body = text[: -len(DEGREES)].strip()
        return math.radians(_evaluate(body, where, error, _shown_text(text), expected)), True
    return _evaluate(text, where, error, _shown_text(text), expected), False


def pose_angle(value: Any, where: str, error: type[MoveplanError] = ConfigError) -> float:
    """Return a pose's roll, pitch or yaw in [rad] (as `angle` reads it); a unitless value beyond a turn is refused.

    Raises:
        error: As `angle`, and for a value in [rad] beyond 2*pi: degrees written without their unit.
    """
    radians, in_degrees = angle(value, where, error)
    if not in_degrees and more_than_a_turn(radians):
        raise error(f"{where}: {beyond_a_turn(radians)}")
    return radians


def pose_angles(value: Any, where: str) -> tuple[float, float, float]:
    """Return a YAML file's `rpy: [roll, pitch, yaw]` in [rad], each read by `pose_angle`."""
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ConfigError(f"{where}: expected a list of 3 angles, got {_shown(value)}")
    roll, pitch, yaw = (pose_angle(v, f"{where}[{i}]") for i, v in enumerate(value))
    return roll, pitch, yaw


def more_than_a_turn(radians: float) -> bool:
    """Return whether |radians| exceeds a full turn, beyond rounding (6.2832 for 2*pi is still one)."""
    return abs(radians) > TURN + _TURN_SLACK


def beyond_a_turn(radians: float, limits: str = "") -> str:
    """Return why a unitless angle beyond 2*pi is refused, and how to write it; `limits` is said after the turn."""
    return (f"{radians:g} rad is more than a full turn (2*pi){limits}: angles are in radians (pi, -pi/2) "
            f"or, with a unit, in degrees ({radians:g}{DEGREES})")


def _evaluate(text: str, where: str, error: type[MoveplanError], shown: str, expected: str) -> float:
    """Return the value of a number or pi expression; `shown` and `expected` word the error."""
    if len(text) > MAX_EXPRESSION_LENGTH:
        raise error(f"{where}: {shown} is longer than {MAX_EXPRESSION_LENGTH} characters, "
                    "the longest number or pi expression moveplan reads")

    def bounded(result: float) -> float:
        if not abs(result) <= MAX_MAGNITUDE:  # NaN and inf fail this too
            raise OverflowError
        return result

    def value(node: ast.AST) -> float:
        if isinstance(node, ast.Constant) and isinstance(node.value, int | float) and not isinstance(node.value, bool):
            return bounded(float(node.value))
        if isinstance(node, ast.Name) and node.id == "pi":
            return math.pi
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            return -value(node.operand) if isinstance(node.op, ast.USub) else value(node.operand)
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            return bounded(_BINARY[type(node.op)](value(node.left), value(node.right)))
        raise ValueError

    try:
        return value(ast.parse(text, mode="eval").body)
    except (SyntaxError, ValueError, ZeroDivisionError, RecursionError, MemoryError):
        raise error(f"{where}: expected {expected}, got {shown}") from None
    except OverflowError:
        raise error(f"{where}: {shown} is out of range; values are limited to "
                    f"|value| <= {MAX_MAGNITUDE:,.0f} (rad, m or s)") from None


def _shown_text(text: str) -> str:
    """Return `text` quoted, or its two ends and its length when longer than 40 characters."""
    return f"'{text}'" if len(text) <= 40 else f"'{text[:20]}...{text[-10:]}' ({len(text)} characters)"


def _shown(value: Any) -> str:
    """Return repr(value), shortened to 60 characters: a message is one line, not a copy of the file."""
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:45]}... ({len(text)} characters)"


def boolean(value: Any, where: str) -> bool:
    """Return `value` if it is a YAML boolean, else raise ConfigError at `where`.

    A quoted "false" is a string, and `bool("false")` is True: only true/false written
    unquoted (YAML 1.1 also reads yes/no/on/off) count.
    """
    if not isinstance(value, bool):
        raise ConfigError(f"{where}: expected true or false, got {value!r}")
    return value


def string_list(value: Any, where: str, what: str = "names") -> list[str]:
    """Return `value` if it is a list of strings (None: an empty list), else raise ConfigError at `where`."""
    if value is None:
        return []
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        shown = repr(value) if len(repr(value)) <= 80 else f"{repr(value)[:77]}..."
        raise ConfigError(f"{where}: expected a list of {what}, got {shown}")
    return value
