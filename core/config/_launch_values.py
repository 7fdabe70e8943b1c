"""What a launch file's statements build, as moveplan follows them without running anything.

A launch file builds substitutions that ROS resolves once every launch argument is known
(LaunchConfiguration, PathJoinSubstitution, Command, FindPackageShare); they are kept as
`Lazy` values and resolved at the end, against the arguments given and the defaults declared.
Anything moveplan does not follow (a function of a package not in the workspace, a
PythonExpression, an environment variable without default) is `Unknown`; an `Unknown` that
waited for launch arguments without a value names them, so an error can ask for them.

`LaunchRecord` collects what the nodes of one launch file (and those it includes) are given:
robot_description and robot_description_semantic (a xacro or file, and its args), parameter
files, MoveItConfigsBuilder chains, and the launch arguments declared.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = [
    "Builder", "Condition", "Declared", "Lazy", "LaunchContext", "LaunchRecord", "NodeRecord", "Unknown", "XacroFile",
    "YamlFile", "is_true", "text",
]


@dataclass(frozen=True)
class Unknown:
    """A value moveplan does not follow; `needs` names the launch arguments without a value it waited for."""

    needs: frozenset[str] = frozenset()


@dataclass(frozen=True)
class Lazy:
    """A launch substitution, resolved once the launch arguments are known.

    kinds: "arg" (parts: name, default or None), "concat" (parts joined), "path" (parts joined
    as a path), "share" (parts: package name).
    """

    kind: str
    parts: tuple[Any, ...]


@dataclass(frozen=True)
class Condition:
    """A launch condition: kind "if" or "unless" (parts: a value), "equals" or "not_equals" (parts: name, value)."""

    kind: str
    parts: tuple[Any, ...]

    def holds(self, context: LaunchContext) -> bool:
        """Return False only when the condition is known to be false: a node under an unknown one counts."""
        if self.kind in ("if", "unless"):
            value = is_true(self.parts[0], context)
            return True if value is None else value == (self.kind == "if")
        name, expected = (text(part, context) for part in self.parts)
        if isinstance(name, Unknown) or isinstance(expected, Unknown):
            return True
        actual = text(context.argument(name), context)
        return True if isinstance(actual, Unknown) else (actual == expected) == (self.kind == "equals")


@dataclass(frozen=True)
class XacroFile:
    """A robot description read in Python: xacro.process_file(path, mappings=...), or a file's text (no mappings)."""

    path: Any
    mappings: Any


@dataclass(frozen=True)
class YamlFile:
    """A YAML file a launch file loads into a parameter dict (yaml.safe_load(open(path)))."""

    path: str


@dataclass(frozen=True)
class Declared:
    """A DeclareLaunchArgument: its default (None: none) and its choices (None: it lists none)."""

    default: Any
    choices: tuple[str, ...] | None = None


@dataclass
class LaunchContext:
    """The launch arguments of one launch file: those given (by --launch-arg or an include) and those declared."""

    given: dict[str, str]
    find_package: Callable[[str], str | None]
    declared: dict[str, Declared] = field(default_factory=dict)
    missing: dict[str, None] = field(default_factory=dict)  # arguments read without a value, in order
    computed: frozenset[str] = frozenset()  # arguments the including file computes in a way not followed

    def argument(self, name: str, fallback: Any = None) -> Any:
        """Return a launch argument's value: given, declared default, `fallback` (the substitution's), else Unknown."""
        if name in self.given:
            return self.given[name]
        declared = self.declared.get(name)
        if declared is not None and declared.default is not None:
            return declared.default
        if fallback is not None:
            return fallback
        if name in self.computed:
            return Unknown()  # not the user's to give: the including launch file computes it
        self.missing[name] = None
        return Unknown(frozenset({name}))


@dataclass
class NodeRecord:
    """A Node or process a launch file starts: its executable, parameters and arguments, unresolved."""

    package: Any
    executable: Any
    parameters: list[Any]
    arguments: list[Any]
    condition: Any


@dataclass
class Builder:
    """A MoveItConfigsBuilder chain: its robot name, package and the files its methods name (method -> args)."""

    robot_name: Any
    package: Any
    calls: dict[str, tuple[Any, Any]] = field(default_factory=dict)  # method -> (file_path, mappings)


@dataclass
class LaunchRecord:
    """What one launch file's evaluation saw, unresolved: nodes, builders, includes done, and its context."""

    file: Path
    context: LaunchContext
    nodes: list[NodeRecord] = field(default_factory=list)
    builders: list[Builder] = field(default_factory=list)
    included: list[LaunchRecord] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    loose: list[dict[Any, Any]] = field(default_factory=list)  # parameter dicts built but handed to no node seen


def text(value: Any, context: LaunchContext, depth: int = 0) -> str | Unknown:
    """Return a value as the text ROS would resolve it to, or Unknown."""
    if depth > 20:
        return Unknown()
    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return str(value)
    if isinstance(value, Unknown) or value is None:
        return value if isinstance(value, Unknown) else Unknown()
    if isinstance(value, list | tuple):
        return _join([text(part, context, depth + 1) for part in value], "")
    if not isinstance(value, Lazy):
        return Unknown()
    if value.kind == "arg":
        name = text(value.parts[0], context, depth + 1)
        if isinstance(name, Unknown):
            return name
        return text(context.argument(name, value.parts[1]), context, depth + 1)
    if value.kind == "share":
        package = text(value.parts[0], context, depth + 1)
        if isinstance(package, Unknown):
            return package
        folder = context.find_package(package)
        return folder if folder is not None else Unknown()
    parts = [text(part, context, depth + 1) for part in value.parts]
    if value.kind == "path":
        unknown = _unknown(parts)
        return unknown if unknown is not None else os.path.join(*[str(p) for p in parts]) if parts else ""
    return _join(parts, "")


def is_true(value: Any, context: LaunchContext) -> bool | None:
    """Return a condition's text as launch reads it (true/1, false/0); None when it is not known."""
    resolved = text(value, context)
    if isinstance(resolved, Unknown):
        return None
    lowered = resolved.strip().lower()
    if lowered in ("true", "1"):
        return True
    if lowered in ("false", "0"):
        return False
    return None


def _unknown(parts: list[str | Unknown]) -> Unknown | None:
    """Return an Unknown naming every argument the unknown parts wait for, None if every part is known."""
    unknown = [p for p in parts if isinstance(p, Unknown)]
    if not unknown:
        return None
    return Unknown(frozenset().union(*(p.needs for p in unknown)))


def _join(parts: list[str | Unknown], separator: str) -> str | Unknown:
    unknown = _unknown(parts)
    return unknown if unknown is not None else separator.join(str(p) for p in parts)
