"""Reading YAML files and checking their fields, with the file and key path in every error.

Shared by every parser of a configuration file: robot config, scene, task and MoveIt requests.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from ..errors import ConfigError, known

__all__ = ["boolean", "check_keys", "load_yaml", "mapping", "number", "string_list"]


def load_yaml(path: Path) -> Any:
    """Return the parsed content of a YAML file; ConfigError names the file and line."""
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"{path}: file not found") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read: {exc}") from None
    try:
        # libyaml's loader, where PyYAML has it, reads a MotionBenchMaker scene 10x faster.
        return yaml.load(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))  # noqa: S506 - a safe loader
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" line {mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ConfigError(f"{path}:{where} malformed YAML: {problem}") from None


def mapping(value: Any, where: str) -> dict[str, Any]:
    """Return `value` if it is a mapping with string keys, else raise ConfigError at `where`."""
    if value is None:
        return {}
    if not isinstance(value, Mapping) or not all(isinstance(k, str) for k in value):
        raise ConfigError(f"{where}: expected a mapping, got {type(value).__name__}")
    return dict(value)


def check_keys(value: Mapping[str, Any], allowed: set[str] | frozenset[str], where: str) -> None:
    """Raise ConfigError for the first key of `value` not in `allowed` (typos must not pass)."""
    for key in value:
        if key not in allowed:
            raise ConfigError(f"{where}: unknown key '{key}'; expected one of: {known(allowed)}")


def number(value: Any, where: str, positive: bool = False) -> float:
    """Return `value` as a finite float, else raise ConfigError at `where`."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ConfigError(f"{where}: expected a finite number, got {value!r}")
    if positive and value <= 0:
        raise ConfigError(f"{where}: expected a positive number, got {value!r}")
    return float(value)


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
