"""Goals and starts of plan steps as typed values: what a task file, the flags or a MoveIt request ask for.

Each boundary (task file, flags, MoveIt request) parses its input into one of these once;
the layers above dispatch on the type. `describe()` gives the goal as the plan JSON
reports it: {"joints": ...}, {"named": ...}, {"pose": ...} or {"shift": ...}.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

__all__ = [
    "GOAL_KINDS", "SHIFT_AXES", "Goal", "JointGoal", "NamedGoal", "PoseGoal", "ShiftGoal", "Start", "StartFrom",
]

GOAL_KINDS = ("joints", "named", "pose", "shift")
SHIFT_AXES = ("x", "y", "z", "roll", "pitch", "yaw")


@dataclass(frozen=True)
class JointGoal:
    """Joint values for the planning group, complete or partial.

    Attributes:
        values: In [rad] or [m]: one per group joint in group order when `joints` is None,
            else one per joint of `joints`.
        joints: Names of the joints a partial goal sets (the others keep their start
            values); None for a complete goal.
        degrees: Per value, whether it was written in degrees (`90deg`; `values` holds it in
            [rad]); empty when none was.
        source: Where the values were written, for messages: a flag (`--joints`) or a file's
            key path (`task.yaml: steps[0].joints`); "" for values from a MoveIt message or a
            plan file, which are in [rad] by convention (config/joint_units.py check_joint_units
            checks the others against the robot's joints).
    """

    kind: ClassVar[str] = "joints"
    values: tuple[float, ...]
    joints: tuple[str, ...] | None = None
    degrees: tuple[bool, ...] = field(default=(), compare=False)
    source: str = field(default="", compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "values", tuple(self.values))
        object.__setattr__(self, "degrees", tuple(self.degrees))
        if self.joints is not None:
            object.__setattr__(self, "joints", tuple(self.joints))
            assert len(self.joints) == len(self.values), "one value per named joint"
        assert not self.degrees or len(self.degrees) == len(self.values), "one unit flag per value"

    @classmethod
    def by_name(cls, values: Mapping[str, float], degrees: Sequence[bool] = (), source: str = "") -> JointGoal:
        """Return a partial goal setting each named joint to its value."""
        return cls(tuple(values.values()), tuple(values), tuple(degrees), source)

    @property
    def named_values(self) -> dict[str, float] | None:
        """Return joint -> value of a partial goal, None for a complete one."""
        return None if self.joints is None else dict(zip(self.joints, self.values, strict=True))

    def describe(self) -> dict[str, Any]:
        """Return the goal as the plan JSON reports it: {"joints": [values] | {joint: value}}."""
        named = self.named_values
        return {"joints": list(self.values) if named is None else named}


@dataclass(frozen=True)
class NamedGoal:
    """An SRDF group_state of the planning group, by name."""

    kind: ClassVar[str] = "named"
    name: str

    def describe(self) -> dict[str, Any]:
        """Return the goal as the plan JSON reports it: {"named": name}."""
        return {"named": self.name}


@dataclass(frozen=True)
class PoseGoal:
    """A pose of a link, expressed in a frame; what the pose leaves out is the frame's own.

    Attributes:
        xyz: Position in [m] in `frame`.
        rpy: Orientation as fixed-axis X-Y-Z angles in [rad], or None.
        quat: Orientation as a quaternion [x, y, z, w], or None (neither: the frame's).
        frame: A scene frame or robot link; None for the planning frame.
        link: The link to move; None for the group's tip.
        also: Poses of other links, reached at the same time (MoveIt's pose targets for several
            end-effectors of one group, a dual arm's two hands).
    """

    kind: ClassVar[str] = "pose"
    xyz: tuple[float, float, float] = (0.0, 0.0, 0.0)
    rpy: tuple[float, float, float] | None = None
    quat: tuple[float, float, float, float] | None = None
    frame: str | None = None
    link: str | None = None
    also: tuple[PoseGoal, ...] = ()

    def __post_init__(self) -> None:
        for name in ("xyz", "rpy", "quat", "also"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, tuple(value))

    def describe(self) -> dict[str, Any]:
        """Return the goal as the plan JSON reports it: {"pose": {frame, link, xyz, rpy, quat[, also]}}."""
        pose: dict[str, Any] = {"frame": self.frame, "link": self.link, "xyz": list(self.xyz),
                                "rpy": _listed(self.rpy), "quat": _listed(self.quat)}
        if self.also:
            pose["also"] = [other.describe()["pose"] for other in self.also]
        return {"pose": pose}


@dataclass(frozen=True)
class ShiftGoal:
    """A move of the tip from where it is, along and about the axes of a frame.

    Attributes:
        x, y, z: Displacements in [m]; None where not given (no move).
        roll, pitch, yaw: Rotations in [rad] about the frame's x, y, z; None where not given.
        frame: "tool" (the tip's own axes), "base" or "planning" (the planning frame's),
            "moveit" (as MoveGroupCommander.shift_pose_target), or any scene frame or link.
    """

    kind: ClassVar[str] = "shift"
    x: float | None = None
    y: float | None = None
    z: float | None = None
    roll: float | None = None
    pitch: float | None = None
    yaw: float | None = None
    frame: str = "tool"

    @classmethod
    def of(cls, offsets: Mapping[str, float], frame: str = "tool") -> ShiftGoal:
        """Return the shift by `offsets` (axis -> value, axes of SHIFT_AXES) along `frame`."""
        return cls(**{axis: offsets[axis] for axis in SHIFT_AXES if axis in offsets}, frame=frame)

    @property
    def offsets(self) -> dict[str, float]:
        """Return axis -> value of the axes given, in SHIFT_AXES order."""
        return {axis: value for axis in SHIFT_AXES if (value := getattr(self, axis)) is not None}

    def translation(self) -> tuple[float, float, float]:
        """Return (x, y, z) in [m], 0 where not given."""
        return _given(self.x), _given(self.y), _given(self.z)

    def rotation(self) -> tuple[float, float, float]:
        """Return (roll, pitch, yaw) in [rad], 0 where not given."""
        return _given(self.roll), _given(self.pitch), _given(self.yaw)

    def describe(self) -> dict[str, Any]:
        """Return the goal as the plan JSON reports it: {"shift": {axis: value, ..., "frame": frame}}."""
        return {"shift": {**self.offsets, "frame": self.frame}}


@dataclass(frozen=True)
class StartFrom:
    """Start where a previous plan file's last step ends."""

    plan: Path


Goal = JointGoal | NamedGoal | PoseGoal | ShiftGoal
"""One step's goal."""

Start = JointGoal | NamedGoal | StartFrom | None
"""Where a plan starts, on top of the initial positions; None: at the initial positions."""


def _given(value: float | None) -> float:
    return 0.0 if value is None else value


def _listed(values: Iterable[float] | None) -> list[float] | None:
    return None if values is None else list(values)
