"""Task files (DESIGN section 4) and the step specifications they and the flags produce.

A task names a robot and scene, a start, defaults, and steps; each step is one
motion goal. Paths in a task resolve relative to the task file.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from moveplan.core.config import check_keys, load_yaml, mapping, number
from moveplan.core.errors import ConfigError

__all__ = ["GOAL_KINDS", "StepSpec", "TaskFile", "load_task", "parse_goal", "parse_scaling"]

GOAL_KINDS = ("joints", "named")
_TASK_KEYS = {"robot", "scene", "group", "start", "defaults", "steps", "seed"}
_DEFAULT_KEYS = {"velocity_scaling", "acceleration_scaling", "planner", "planning_time"}
_STEP_KEYS = {"name", *GOAL_KINDS, *_DEFAULT_KEYS}


@dataclass(frozen=True)
class StepSpec:
    """One requested motion: a goal plus per-step overrides (None = use the plan's default).

    `goal` holds exactly one kind: {"joints": [values] | {joint: value}} or {"named": name}.
    """

    name: str
    goal: dict[str, Any]
    velocity_scaling: float | None = None
    acceleration_scaling: float | None = None
    planner: str | None = None
    planning_time: float | None = None


@dataclass(frozen=True)
class TaskFile:
    """A parsed task file; paths are already resolved against its folder."""

    source: Path
    robot: Path | None
    scene: Path | None
    group: str | None
    start: dict[str, Any]
    defaults: dict[str, Any]
    steps: tuple[StepSpec, ...]
    seed: int | None = None
    raw: bytes = field(default=b"", repr=False)


def parse_scaling(value: Any, where: str) -> float:
    """Return a velocity or acceleration scaling factor, checked to lie in (0, 1]."""
    factor = number(value, where)
    if not 0.0 < factor <= 1.0:
        raise ConfigError(f"{where}: expected a scaling factor in (0, 1], got {value!r}")
    return factor


def parse_goal(entry: dict[str, Any], where: str) -> dict[str, Any]:
    """Return the one goal of a step or start entry, checked for shape."""
    kinds = [k for k in GOAL_KINDS if k in entry]
    if len(kinds) != 1:
        raise ConfigError(f"{where}: give exactly one goal of: {', '.join(GOAL_KINDS)}")
    kind = kinds[0]
    value = entry[kind]
    if kind == "named":
        if not isinstance(value, str):
            raise ConfigError(f"{where}.named: expected a group_state name, got {value!r}")
        return {"named": value}
    if isinstance(value, list):
        return {"joints": [number(v, f"{where}.joints[{i}]") for i, v in enumerate(value)]}
    if isinstance(value, dict):
        return {"joints": {str(k): number(v, f"{where}.joints.{k}") for k, v in value.items()}}
    raise ConfigError(f"{where}.joints: expected a list of values or a mapping joint: value, got {value!r}")


def _defaults(entry: dict[str, Any], where: str) -> dict[str, Any]:
    result: dict[str, Any] = {}
    for key in ("velocity_scaling", "acceleration_scaling"):
        if key in entry:
            result[key] = parse_scaling(entry[key], f"{where}.{key}")
    if "planner" in entry:
        if not isinstance(entry["planner"], str):
            raise ConfigError(f"{where}.planner: expected a planner name, got {entry['planner']!r}")
        result["planner"] = entry["planner"]
    if "planning_time" in entry:
        result["planning_time"] = number(entry["planning_time"], f"{where}.planning_time", positive=True)
    return result


def load_task(path: Path) -> TaskFile:
    """Return the task in a task file."""
    source = str(path)
    top = mapping(load_yaml(path), source)
    check_keys(top, _TASK_KEYS, source)
    folder = path.parent

    def relative(key: str) -> Path | None:
        if key not in top:
            return None
        if not isinstance(top[key], str):
            raise ConfigError(f"{source}: {key}: expected a path, got {top[key]!r}")
        return folder / top[key]

    start = mapping(top.get("start"), f"{source}: start")
    check_keys(start, {"named", "joints", "from"}, f"{source}: start")
    if "from" in start:
        start = {"from": folder / str(start["from"])}
    elif start:
        start = parse_goal(start, f"{source}: start")
    defaults = mapping(top.get("defaults"), f"{source}: defaults")
    check_keys(defaults, _DEFAULT_KEYS, f"{source}: defaults")
    steps_raw = top.get("steps") or []
    if not isinstance(steps_raw, list):
        raise ConfigError(f"{source}: steps: expected a list of steps")
    steps = []
    for k, entry in enumerate(steps_raw):
        where = f"{source}: steps[{k}]"
        entry = mapping(entry, where)
        check_keys(entry, _STEP_KEYS, where)
        name = str(entry.get("name", f"step{k + 1}"))
        steps.append(StepSpec(name=name, goal=parse_goal(entry, where), **_defaults(entry, where)))
    names = [s.name for s in steps]
    for name in names:
        if names.count(name) > 1:
            raise ConfigError(f"{source}: step name '{name}' is used twice")
    seed = top.get("seed")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or seed < 0):
        raise ConfigError(f"{source}: seed: expected a non-negative integer, got {seed!r}")
    group = top.get("group")
    return TaskFile(
        source=path,
        robot=relative("robot"),
        scene=relative("scene"),
        group=str(group) if group is not None else None,
        start=start,
        defaults=_defaults(defaults, f"{source}: defaults"),
        steps=tuple(steps),
        seed=seed,
        raw=path.read_bytes(),
    )
