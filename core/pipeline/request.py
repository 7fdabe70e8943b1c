"""What one `moveplan plan` run is asked: the plan command's options, their rules, and their precedence.

`PlanFlags` holds the options as typed values and enforces the rules between them;
`resolve_request` applies precedence in one place: flag > MoveIt request > task file
(> robot config > built-in default, applied when planning).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TypeVar

from ..config import (
    MAX_MAGNITUDE,
    MIN_SCALING,
    JointGoal,
    MotionPlanRequest,
    MotionSettings,
    NamedGoal,
    PoseGoal,
    RobotConfig,
    ShiftGoal,
    Start,
    StartFrom,
    StepSpec,
    TaskFile,
    is_planning_time,
    is_scaling,
    layered,
    load_motion_plan_request,
    load_robot_config,
)
from ..errors import UsageError

__all__ = ["PlanFlags", "PlanRequest", "RobotSource", "check_planning_time", "resolve_request"]

_T = TypeVar("_T")


def check_planning_time(seconds: float, flag: str = "--planning-time") -> float:
    """Return `seconds` if it is a positive, finite planning time of at most MAX_MAGNITUDE, else raise UsageError."""
    if not is_planning_time(seconds):
        raise UsageError(f"{flag}: expected a positive number of seconds up to {MAX_MAGNITUDE:g}, got {seconds:g}")
    return seconds


@dataclass(frozen=True)
class RobotSource:
    """What loads a robot config: --robot and the flags that complete it, as load_robot_config takes them.

    Picklable, so that a benchmark's worker processes load the same robot.

    Attributes:
        robot: A shipped name, a moveplan.yaml or its folder, a MoveIt config package, a URDF or SRDF.
        package_paths: --package-path folders.
        xacro_args: --xacro-arg values, name -> value.
        urdf, srdf: --urdf and --srdf: a file or `package://pkg/path`, replacing the config's.
        strict_limits: --strict-limits: a missing acceleration limit is an error.
        joint_limits: --joint-limits: MoveIt's joint_limits.yaml, a file or `package://pkg/path`.
        launch: --launch: the one launch file of a MoveIt package to read.
        launch_args: --launch-arg values, name -> value.
        strict: --strict: a parameter a controller does not declare is an error.
    """

    robot: str | Path
    package_paths: tuple[Path, ...] = ()
    xacro_args: Mapping[str, str] = field(default_factory=dict)
    urdf: str | None = None
    srdf: str | None = None
    strict_limits: bool = False
    joint_limits: str | None = None
    launch: str | None = None
    launch_args: Mapping[str, str] = field(default_factory=dict)
    strict: bool = False

    def load(self) -> RobotConfig:
        """Return the robot config these arguments name."""
        return load_robot_config(self.robot, self.package_paths, self.xacro_args, urdf=self.urdf, srdf=self.srdf,
                                 strict_limits=self.strict_limits, joint_limits=self.joint_limits,
                                 launch=self.launch, launch_args=self.launch_args, strict=self.strict)


@dataclass(frozen=True)
class PlanFlags:
    """The options of `moveplan plan` as values, None where not given; the rules between them hold.

    At most one start flag and one goal flag; `frame` and `link` go with `pose`, `shift_frame`
    with `shift`, `linear` with `pose` or `shift`; numbers lie in their ranges. A violation
    is a UsageError (exit 2).

    Attributes:
        robot: Robot config: a moveplan.yaml, its folder, or a MoveIt config package.
        scene: Scene file, moveplan's or a MoveIt PlanningScene.
        request: MoveIt MotionPlanRequest file.
        group: Planning group.
        start_joints, start_named, start_from: Where the plan starts (one of them).
        joints, named, pose, shift: The goal of a single step (one of them). `pose` and
            `shift` carry the flag's numbers; their frame and link come from the flags below.
        frame: Frame `pose` is given in.
        link: Link `pose` moves.
        shift_frame: Axes of `shift` (default "tool").
        linear: Move the tip along a straight line.
        min_fraction: With `linear`, the smallest fraction of the line that is a success, in [0, 1].
        motion: --planner, --planning-time (seconds the planner may search per step,
            positive: a budget of work), --velocity-scaling and --acceleration-scaling
            (fractions of the limits, in [MIN_SCALING, 1]).
        timeout: Wall-clock safety limit of each search in [s], positive.
        seed: Random seed.
        package_paths: Folders searched for package:// URIs.
        xacro_args: xacro arguments, name -> value.
        urdf, srdf: The URDF and SRDF (a file or `package://pkg/path`), replacing the config's.
        strict_limits: A missing acceleration limit is an error instead of the default.
        joint_limits: MoveIt's joint_limits.yaml (a file or `package://pkg/path`), replacing the config's.
        launch, launch_args: --launch and --launch-arg: which launch file of a MoveIt package to read,
            with which arguments.
        strict: --strict: a parameter a controller does not declare is an error.
    """

    robot: Path | None = None
    scene: Path | None = None
    request: Path | None = None
    group: str | None = None
    start_joints: JointGoal | None = None
    start_named: str | None = None
    start_from: Path | None = None
    joints: JointGoal | None = None
    named: str | None = None
    pose: PoseGoal | None = None
    frame: str | None = None
    link: str | None = None
    shift: ShiftGoal | None = None
    shift_frame: str | None = None
    linear: bool = False
    min_fraction: float | None = None
    motion: MotionSettings = MotionSettings()
    timeout: float | None = None
    seed: int | None = None
    package_paths: tuple[Path, ...] = ()
    xacro_args: Mapping[str, str] = field(default_factory=dict)
    urdf: str | None = None
    srdf: str | None = None
    strict_limits: bool = False
    joint_limits: str | None = None
    launch: str | None = None
    launch_args: Mapping[str, str] = field(default_factory=dict)
    strict: bool = False

    def __post_init__(self) -> None:
        starts = [k for k in ("start_joints", "start_named", "start_from") if getattr(self, k) is not None]
        goals = [k for k in ("joints", "named", "pose", "shift") if getattr(self, k) is not None]
        if len(starts) > 1 or len(goals) > 1:
            given = ", ".join(_flag(k) for k in starts + goals)
            raise UsageError(f"give one start flag and one goal flag, got {given}")
        for name, needs in (("frame", "pose"), ("link", "pose"), ("shift_frame", "shift")):
            if getattr(self, name) is not None and getattr(self, needs) is None:
                raise UsageError(f"{_flag(name)} goes with {_flag(needs)}")
        if self.linear and self.pose is None and self.shift is None:
            raise UsageError("--linear goes with --pose or --shift")
        if self.min_fraction is not None and not 0.0 <= self.min_fraction <= 1.0:
            raise UsageError(f"--min-fraction: expected a number in [0, 1], got {self.min_fraction:g}")
        if self.motion.planning_time is not None:
            check_planning_time(self.motion.planning_time)
        if self.timeout is not None:
            check_planning_time(self.timeout, "--timeout")
        for name in ("velocity_scaling", "acceleration_scaling"):
            factor = getattr(self.motion, name)
            if factor is not None and not is_scaling(factor):
                raise UsageError(f"{_flag(name)}: expected a factor in [{MIN_SCALING:g}, 1], got {factor:g}")

    @property
    def start(self) -> Start:
        """Return where the start flags put the robot, None without a start flag."""
        if self.start_named is not None:
            return NamedGoal(self.start_named)
        if self.start_from is not None:
            return StartFrom(self.start_from)
        return self.start_joints

    @property
    def step(self) -> StepSpec | None:
        """Return the one step the goal flags ask for, None without a goal flag."""
        if self.joints is not None:
            return StepSpec("goal", self.joints)
        if self.named is not None:
            return StepSpec(self.named, NamedGoal(self.named))
        if self.pose is not None:
            return StepSpec("pose", replace(self.pose, frame=self.frame, link=self.link), linear=self.linear)
        if self.shift is not None:
            return StepSpec("shift", replace(self.shift, frame=self.shift_frame or "tool"), linear=self.linear)
        return None


@dataclass(frozen=True)
class PlanRequest:
    """Everything one `moveplan plan` run needs, after precedence has been applied.

    None leaves a setting to the robot config (or, per step, to the step's own value).
    """

    robot: Path
    steps: tuple[StepSpec, ...]
    scene: Path | None = None
    group: str | None = None
    start: Start = None
    motion: MotionSettings = MotionSettings()
    timeout: float | None = None
    seed: int = 0
    min_fraction: float = 1.0
    package_paths: tuple[Path, ...] = ()
    xacro_args: Mapping[str, str] = field(default_factory=dict)
    task: TaskFile | None = None
    motion_request: MotionPlanRequest | None = None
    urdf: str | None = None
    srdf: str | None = None
    strict_limits: bool = False
    joint_limits: str | None = None
    launch: str | None = None
    launch_args: Mapping[str, str] = field(default_factory=dict)
    strict: bool = False


def resolve_request(task: TaskFile | None, flags: PlanFlags) -> PlanRequest:
    """Return the request that flags, a MoveIt request (`flags.request`) and a task give together.

    A flag wins over the MoveIt request, which wins over the task. A goal by flag replaces the
    request's goal; a request's goal and a task's steps conflict, as a flag goal and task steps do.
    The request's start state, when it has one, replaces the task's start.
    """
    motion = load_motion_plan_request(flags.request) if flags.request else None
    steps = _steps(task, motion, flags)
    robot = _first(flags.robot, task.robot if task else None)
    if robot is None:
        raise UsageError("no robot: give --robot or a task file naming one")
    start = flags.start
    if start is None and task is not None and not (motion is not None and motion.start):
        start = task.start
    return PlanRequest(
        robot=Path(robot), steps=steps, scene=_first(flags.scene, task.scene if task else None),
        group=_first(flags.group, motion.group_name if motion else None, task.group if task else None), start=start,
        motion=layered(flags.motion, motion.motion if motion else MotionSettings(),
                       task.defaults if task else MotionSettings()),
        timeout=flags.timeout,
        seed=_first(flags.seed, task.seed if task else None) or 0,
        min_fraction=1.0 if flags.min_fraction is None else flags.min_fraction,
        package_paths=flags.package_paths, xacro_args=dict(flags.xacro_args), task=task, motion_request=motion,
        urdf=flags.urdf, srdf=flags.srdf, strict_limits=flags.strict_limits, joint_limits=flags.joint_limits,
        launch=flags.launch, launch_args=dict(flags.launch_args), strict=flags.strict,
    )


def _steps(task: TaskFile | None, motion: MotionPlanRequest | None, flags: PlanFlags) -> tuple[StepSpec, ...]:
    """Return the steps to plan: the flags' goal, else the request's, else the task's."""
    flag_step = flags.step
    if flag_step is not None and task is not None and task.steps:
        raise UsageError(f"{task.source} has steps; give a goal by flag or by task, not both")
    if flag_step is not None:
        return (flag_step,)
    if motion is not None and motion.goal is not None:
        if task is not None and task.steps:
            raise UsageError(f"{task.source} has steps and {motion.source} has goal_constraints; give one of them")
        return (motion.goal,)
    if task is not None and task.steps:
        return task.steps
    raise UsageError("no goal: give --joints, --named, --pose, --shift, a --request with goal_constraints, "
                     "or a task file with steps")


def _first(*values: _T | None) -> _T | None:
    """Return the first value that is not None (the one of highest precedence), else None."""
    return next((value for value in values if value is not None), None)


def _flag(name: str) -> str:
    return "--" + name.replace("_", "-")
