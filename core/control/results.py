"""How an execution ends: result codes, the failed checks, and the verdict that carries them."""

from __future__ import annotations

from dataclasses import dataclass, field

from .quality import JointTracking

__all__ = [
    "GOAL_TOLERANCE_VIOLATED",
    "INCOMPLETE",
    "PATH_TOLERANCE_VIOLATED",
    "START_STATE_INVALID",
    "SUCCESSFUL",
    "TIMED_OUT",
    "ExecutionResult",
    "ExecutionSummary",
    "ToleranceReport",
    "Violation",
    "result_of",
]

SUCCESSFUL = 0
PATH_TOLERANCE_VIOLATED = -4
GOAL_TOLERANCE_VIOLATED = -5
TIMED_OUT = -6
START_STATE_INVALID = -26
INCOMPLETE = -100
_NAMES = {
    SUCCESSFUL: "SUCCESSFUL",
    PATH_TOLERANCE_VIOLATED: "PATH_TOLERANCE_VIOLATED",
    GOAL_TOLERANCE_VIOLATED: "GOAL_TOLERANCE_VIOLATED",
    TIMED_OUT: "TIMED_OUT",
    START_STATE_INVALID: "START_STATE_INVALID",
    INCOMPLETE: "INCOMPLETE",
}


@dataclass(frozen=True)
class ExecutionResult:
    """How an execution ended: a numeric code, its name, and a message.

    Codes 0, -4 and -5 are control_msgs/FollowJointTrajectory result codes, as the
    JointTrajectoryController returns them. The two outcomes MoveIt decides use
    moveit_msgs/MoveItErrorCodes, whose values do not collide with those: TIMED_OUT (-6)
    is what MoveIt reports when its duration monitor stops an execution. MoveIt reports a
    start state too far from the plan's first point as ABORTED / CONTROL_FAILED (-4),
    which would read as a path violation here, so it is START_STATE_INVALID (-26), the
    MoveIt code for an unusable start state, with MoveIt's "start point deviates" message.
    INCOMPLETE (-100) is moveplan's own, outside both ranges (control_msgs uses 0 to -5,
    MoveItErrorCodes 1, 99999 and -1 to -31): a recording that cuts an execution off
    before the controller or MoveIt decided it, so there is no verdict to report.
    """

    code: int
    name: str
    message: str


def result_of(code: int, message: str) -> ExecutionResult:
    """Return the result with `code`, named as its code is."""
    return ExecutionResult(code, _NAMES[code], message)


@dataclass(frozen=True)
class Violation:
    """One failed check: which, where and when, with the numbers compared.

    `check` is one of path, goal, goal_time, stopped_velocity, start_tolerance, timeout.
    For state checks, values are positions in [rad] or [m] (velocities for
    stopped_velocity) and `error` is reference - actual. For the time checks
    (goal_time, timeout) `joint` is "", `reference` is the planned end time, `actual`
    the time the execution was stopped, `error` their difference and `tolerance` the
    lateness allowed, all in [s]. Times are from the trajectory's start.
    """

    check: str
    joint: str
    time_s: float
    reference: float
    actual: float
    error: float
    tolerance: float


@dataclass(frozen=True)
class ToleranceReport:
    """The verdict on one execution.

    Attributes:
        result: How it ended.
        violations: The failed checks on the cycle it ended (empty on success).
        margins: Per joint with a nonzero position tolerance, the smallest tolerance - |error|
            in [rad]: over all path-checked cycles, and of the goal check on the final cycle.
        end_index: Index of the cycle on which it ended.
        tracking: Per joint how it tracked its reference (quality.tracking), where computed.
    """

    result: ExecutionResult
    violations: tuple[Violation, ...]
    margins: dict[str, float]
    end_index: int
    tracking: dict[str, JointTracking] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        """Return True if the execution succeeded."""
        return self.result.code == SUCCESSFUL


@dataclass(frozen=True)
class ExecutionSummary:
    """What a simulated execution decided, without its per-cycle samples: what a plan keeps of each step.

    Attributes:
        ok: True if the goal succeeded.
        result: How it ended.
        violations: The failed checks on the cycle it ended.
        margins: Per joint with a nonzero tolerance, the smallest tolerance - |error| in [rad].
        duration_s: Simulated time until the result in [s].
        joint_names: The controller's joints, in its order.
        cycles: Control cycles run; 0 if it never started.
        output_interface: The command interface the plant was driven through.
        tracking: Per joint how it tracked its reference (quality.tracking), where computed.
    """

    ok: bool
    result: ExecutionResult
    violations: tuple[Violation, ...]
    margins: dict[str, float]
    duration_s: float
    joint_names: tuple[str, ...]
    cycles: int
    output_interface: str = "position"
    tracking: dict[str, JointTracking] = field(default_factory=dict)
