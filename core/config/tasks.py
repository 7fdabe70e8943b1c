"""Task files (docs/formats.md) and the step specifications they and the flags produce.

A task names a robot and scene, a start, defaults, and steps; each step is one
motion goal, parsed here into a typed goal (goals.py). Paths in a task resolve
relative to the task file; its robot may also be a shipped config's bare name.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from ..errors import ConfigError
from ..types import GoalTolerances
from .constraints import ArcPoint, PathConstraints, path_constraints
from .fields import (
    MAX_MAGNITUDE,
    angle,
    check_keys,
    coordinate,
    load_yaml,
    mapping,
    number,
    pose_angle,
    read_input,
)
from .goal_tolerances import parse_goal_tolerances
from .goals import GOAL_KINDS, SHIFT_AXES, Goal, JointGoal, NamedGoal, PoseGoal, ShiftGoal, Start, StartFrom
from .motion import MIN_SCALING, MotionSettings, is_scaling
from .poses import vector
from .sources import shipped_config

__all__ = [
    "GOAL_KINDS", "SHIFT_AXES", "StepSpec", "TaskFile", "load_task", "parse_goal", "parse_pose",
    "parse_scaling", "parse_shift",
]

MAX_SEED = 2**32 - 1
"""Largest seed: OMPL's random generator takes 32-bit seeds (cli/parsing.py has the same bound for --seed)."""

_TASK_KEYS = {"robot", "scene", "group", "start", "defaults", "steps", "seed"}
_DEFAULT_KEYS = {f.name for f in fields(MotionSettings)}
_STEP_KEYS = {"name", "linear", "min_fraction", "path_constraints", "arc", "tolerances", *GOAL_KINDS,
              *_DEFAULT_KEYS}
_POSE_KEYS = {"frame", "xyz", "rpy", "quat", "link"}


@dataclass(frozen=True)
class StepSpec:
    """One requested motion: a goal plus per-step overrides (None = use the plan's default).

    A `linear` step moves the tip along a straight line (pose and shift goals); below
    `min_fraction` of it, it fails. Every state of the motion satisfies `constraints`.
    """

    name: str
    goal: Goal
    linear: bool = False
    min_fraction: float | None = None
    motion: MotionSettings = MotionSettings()
    constraints: PathConstraints | None = None
    arc: ArcPoint | None = None  # Pilz's CIRC: the point the arc passes through or turns about
    tolerances: GoalTolerances | None = None  # sent with the step's FollowJointTrajectory goal


@dataclass(frozen=True)
class TaskFile:
    """A parsed task file; paths are already resolved against its folder (a robot by bare name: the shipped config)."""

    source: Path
    robot: Path | None
    scene: Path | None
    group: str | None
    start: Start
    defaults: MotionSettings
    steps: tuple[StepSpec, ...]
    seed: int | None = None
    raw: bytes = field(default=b"", repr=False)


def _arc(value: Any, where: str) -> ArcPoint:
    """Return a step's `arc: {center | interim: [x, y, z], frame: ...}`, the point of planner CIRC."""
    entry = mapping(value, where)
    check_keys(entry, {"center", "interim", "frame"}, where)
    kinds = [k for k in ("center", "interim") if k in entry]
    if len(kinds) != 1:
        raise ConfigError(f"{where}: give one of center and interim (the point the arc turns about or passes)")
    xyz = vector(entry[kinds[0]], 3, f"{where}.{kinds[0]}")
    frame = entry.get("frame", "")
    if not isinstance(frame, str):
        raise ConfigError(f"{where}.frame: expected a frame name, got {frame!r}")
    return ArcPoint(kinds[0], (float(xyz[0]), float(xyz[1]), float(xyz[2])), frame)


def parse_scaling(value: Any, where: str) -> float:
    """Return a velocity or acceleration scaling factor, checked to lie in [MIN_SCALING, 1]."""
    factor = number(value, where)
    if not is_scaling(factor):
        raise ConfigError(f"{where}: expected a scaling factor in [{MIN_SCALING:g}, 1], got {value!r}")
    return factor


def parse_goal(entry: dict[str, Any], where: str) -> Goal:
    """Return the one goal of a step or start entry, checked for shape."""
    kinds = [k for k in GOAL_KINDS if k in entry]
    if len(kinds) != 1:
        raise ConfigError(f"{where}: give exactly one goal of: {', '.join(GOAL_KINDS)}")
    kind = kinds[0]
    value = entry[kind]
    if kind == "pose":
        return parse_pose(mapping(value, f"{where}.pose"), f"{where}.pose")
    if kind == "shift":
        return parse_shift(mapping(value, f"{where}.shift"), f"{where}.shift")
    if kind == "named":
        if not isinstance(value, str):
            raise ConfigError(f"{where}.named: expected a group_state name, got {value!r}")
        return NamedGoal(value)
    if isinstance(value, list):
        read = [angle(v, f"{where}.joints[{i}]") for i, v in enumerate(value)]
        return JointGoal(tuple(v for v, _ in read), degrees=tuple(d for _, d in read), source=f"{where}.joints")
    if isinstance(value, dict):
        named = {str(k): angle(v, f"{where}.joints.{k}") for k, v in value.items()}
        return JointGoal.by_name({k: v for k, (v, _) in named.items()}, [d for _, d in named.values()],
                                 f"{where}.joints")
    raise ConfigError(f"{where}.joints: expected a list of values or a mapping joint: value, got {value!r}")


def parse_pose(entry: dict[str, Any], where: str) -> PoseGoal:
    """Return a pose goal of `link` in `frame` (xyz, rpy | quat), numbers checked; missing keys are None.

    Angles of `rpy` are radians, pi expressions or degrees (`90deg`); a unitless one beyond 2*pi is refused.
    """
    check_keys(entry, _POSE_KEYS, where)
    names: dict[str, Any] = {key: entry.get(key) for key in ("frame", "link")}
    for key, name in names.items():
        if name is not None and not isinstance(name, str):
            raise ConfigError(f"{where}.{key}: expected a frame or link name, got {name!r}")
    vectors: dict[str, Any] = {}
    for key, size in (("xyz", 3), ("rpy", 3), ("quat", 4)):
        value = entry.get(key, [0.0, 0.0, 0.0] if key == "xyz" else None)
        if value is None:
            continue
        if not isinstance(value, list) or len(value) != size:
            raise ConfigError(f"{where}.{key}: expected a list of {size} numbers, got {value!r}")
        # A quaternion is normalised: any scale is fine.
        read = coordinate if key == "xyz" else pose_angle if key == "rpy" else number
        vectors[key] = tuple(read(v, f"{where}.{key}[{i}]") for i, v in enumerate(value))
    if "rpy" in vectors and "quat" in vectors:
        raise ConfigError(f"{where}: give rpy or quat, not both")
    if "quat" in vectors and sum(v * v for v in vectors["quat"]) < 1e-12:
        raise ConfigError(f"{where}.quat: a quaternion [x, y, z, w] of zero norm is not a rotation")
    return PoseGoal(**vectors, **names)


def parse_shift(entry: dict[str, Any], where: str) -> ShiftGoal:
    """Return a shift goal: displacement per axis (x, y, z in [m]; roll, pitch, yaw in [rad] or `deg`) and frame."""
    check_keys(entry, {*SHIFT_AXES, "frame"}, where)
    offsets = {axis: (coordinate if axis in ("x", "y", "z") else pose_angle)(entry[axis], f"{where}.{axis}")
               for axis in SHIFT_AXES if axis in entry}
    if not offsets:
        raise ConfigError(f"{where}: give at least one of {', '.join(SHIFT_AXES)}")
    frame = entry.get("frame", "tool")
    if not isinstance(frame, str):
        raise ConfigError(f"{where}.frame: expected tool, base, moveit or a frame name, got {frame!r}")
    return ShiftGoal.of(offsets, frame)


def _start(entry: dict[str, Any], folder: Path, where: str) -> Start:
    """Return a task's start: a previous plan file (relative to the task), a joints or a named goal."""
    check_keys(entry, {"named", "joints", "from"}, where)
    if "from" in entry:
        return StartFrom(folder / str(entry["from"]))
    if not entry:
        return None
    goal = parse_goal(entry, where)
    assert isinstance(goal, JointGoal | NamedGoal), "the keys are checked above"
    return goal


def _motion(entry: dict[str, Any], where: str) -> MotionSettings:
    """Return the motion settings a task's defaults or one of its steps sets."""
    scalings = {key: parse_scaling(entry[key], f"{where}.{key}")
                for key in ("velocity_scaling", "acceleration_scaling") if key in entry}
    planner = entry.get("planner")
    if planner is not None and not isinstance(planner, str):
        raise ConfigError(f"{where}.planner: expected a planner name, got {planner!r}")
    planning_time = None
    if "planning_time" in entry:
        planning_time = number(entry["planning_time"], f"{where}.planning_time", positive=True, bound=MAX_MAGNITUDE)
    return MotionSettings(planner, planning_time, **scalings)


def _robot(beside: Path | None, written: str | None) -> Path | None:
    """Return a task's robot: `beside` (`written` in the task's folder) if it exists, else the shipped config `written`.

    A bare name thus finds what `--robot NAME` finds, the task's folder standing in for the
    working directory. Anything else is left as `beside`, for loading the robot to report
    (exit 3, with the shipped configs' names), as a missing path is.
    """
    if beside is None or beside.exists() or written is None:
        return beside
    return shipped_config(written) or beside


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
        return folder / str(top[key])

    start = _start(mapping(top.get("start"), f"{source}: start"), folder, f"{source}: start")
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
        linear = entry.get("linear", False)
        if not isinstance(linear, bool):
            raise ConfigError(f"{where}.linear: expected true or false, got {linear!r}")
        min_fraction = None
        if "min_fraction" in entry:
            min_fraction = number(entry["min_fraction"], f"{where}.min_fraction")
            if not 0.0 <= min_fraction <= 1.0:
                raise ConfigError(f"{where}.min_fraction: expected a number in [0, 1], got {min_fraction!r}")
        goal = parse_goal(entry, where)
        if linear and isinstance(goal, JointGoal | NamedGoal):
            raise ConfigError(f"{where}: linear applies to pose and shift goals, not {goal.kind}")
        constraints = (path_constraints(entry["path_constraints"], f"{where}.path_constraints")
                       if "path_constraints" in entry else None)
        arc = _arc(entry["arc"], f"{where}.arc") if "arc" in entry else None
        tolerances = (parse_goal_tolerances(entry["tolerances"], f"{where}.tolerances")
                      if "tolerances" in entry else None)
        steps.append(StepSpec(name=name, goal=goal, linear=linear, min_fraction=min_fraction,
                              motion=_motion(entry, where), constraints=constraints, arc=arc,
                              tolerances=tolerances))
    names = [s.name for s in steps]
    for name in names:
        if names.count(name) > 1:
            raise ConfigError(f"{source}: step name '{name}' is used twice")
    seed = top.get("seed")
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED):
        shown = repr(seed) if len(repr(seed)) <= 40 else f"{repr(seed)[:37]}..."
        raise ConfigError(f"{source}: seed: expected an integer in 0..{MAX_SEED}, got {shown}")
    group = top.get("group")
    return TaskFile(
        source=path,
        robot=_robot(relative("robot"), top.get("robot")),
        scene=relative("scene"),
        group=str(group) if group is not None else None,
        start=start,
        defaults=_motion(defaults, f"{source}: defaults"),
        steps=tuple(steps),
        seed=seed,
        raw=read_input(path),
    )
