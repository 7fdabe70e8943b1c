"""Reading YAML files and checking their fields, with the file and key path in every error.

Shared by every parser of a configuration file: robot config, scene, task and MoveIt requests.
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from ..errors import ConfigError, known

try:
    from yaml.cyaml import CParser as _CParser  # libyaml's parser, where PyYAML has it
except ImportError:  # a PyYAML built without libyaml
    _CParser = None

__all__ = [
    "MAX_ALIAS_EXPANSION", "MAX_MAGNITUDE", "MAX_YAML_BYTES", "MAX_YAML_EVENTS", "boolean", "check_keys", "coordinate",
    "load_yaml", "mapping", "number", "parse_yaml", "string_list",
]


MAX_MAGNITUDE = 1e6
"""Largest |value| of a position in [rad] or [m] or a time in [s] from a flag or a task: a million
radians, a thousand kilometres, eleven days. Beyond it, a typo (1e308) must not reach the planner."""

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


class _Loader(getattr(yaml, "CSafeLoader", yaml.SafeLoader)):  # type: ignore[misc]
    """PyYAML's safe loader, reading numbers with an exponent as ROS does.

    libyaml's where PyYAML has it: it reads a MotionBenchMaker scene 10x faster.
    """


_Loader.add_implicit_resolver("tag:yaml.org,2002:float", _ROS_FLOAT, list("-+0123456789."))


def load_yaml(path: Path) -> Any:
    """Return the parsed content of a YAML file; ConfigError names the file and line.

    A file larger than MAX_YAML_BYTES, or with more than MAX_YAML_EVENTS parse events, is refused
    before its values are built. Aliases may add at most MAX_ALIAS_EXPANSION values to the
    document (and may not contain themselves), so that no reader of the result walks a billion
    shared copies.
    """
    try:
        size = path.stat().st_size
        if size > MAX_YAML_BYTES:
            raise ConfigError(f"{path}: {size:,} bytes; moveplan reads YAML files of at most {MAX_YAML_BYTES:,} bytes")
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read: {exc}") from None
    return parse_yaml(text, path)


def parse_yaml(text: str, path: Path, after: str = "") -> Any:
    """Return YAML `text` parsed under load_yaml's limits; ConfigError names `path`, the line and `after`."""
    try:
        events = _count_events(text)
        if events > MAX_YAML_EVENTS:
            raise ConfigError(f"{path}: more than {MAX_YAML_EVENTS:,} YAML values (lists and mappings count twice); "
                              "moveplan reads at most that many per file (a 10,000-shape scene has ~350,000)")
        content = yaml.load(text, Loader=_Loader)  # noqa: S506 - a safe loader
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" line {mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ConfigError(f"{path}:{where} malformed YAML{after}: {problem}") from None
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
        raise ConfigError(f"{where}: expected a list of {what}, got {value!r}")
    return value
