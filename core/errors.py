"""The one error hierarchy of moveplan: what went wrong, with what the user needs to fix it.

Each class carries the process exit code the CLI maps it to (docs/cli.md):
2 usage, 3 bad input, 4 no plan. Messages name the file, key or joint and list
valid alternatives where there are any.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any, Self

__all__ = [
    "ConfigError",
    "CorruptData",
    "FrameNotFound",
    "GoalInCollision",
    "GoalOutsideLimits",
    "OutsideLimits",
    "StartOutsideLimits",
    "GoalUnreachable",
    "GoalViolatesConstraints",
    "StartViolatesConstraints",
    "SolutionsCollide",
    "InCollision",
    "InputError",
    "MoveplanError",
    "NoPlan",
    "PlanningFailed",
    "PlanningTimeExceeded",
    "StartInCollision",
    "UnknownName",
    "UnsupportedJoint",
    "UsageError",
    "known",
]


def known(names: Iterable[str], limit: int = 30) -> str:
    """Return a comma-separated, sorted list of names, shortened after `limit` entries."""
    items = sorted(set(names))
    text = ", ".join(items[:limit])
    if len(items) > limit:
        text += f", ... ({len(items) - limit} more)"
    return text or "(none)"


class MoveplanError(Exception):
    """Base of every error moveplan raises on purpose.

    Attributes:
        step: Name of the plan step the error happened in, None outside a step; when set,
            the message begins with it: "step 'approach': ...".
        partial: What the command had done before the error, for its report (a plan's steps
            planned before the failing one: a pipeline.plan.PlanResult); None if nothing.
    """

    exit_code = 1
    step: str | None = None
    partial: Any = None

    @property
    def kind(self) -> str:
        """Return the error's class name, as reported in JSON output."""
        return type(self).__name__

    def in_step(self, step: str) -> Self:
        """Return this error, marked as raised while planning `step`; an error already marked keeps its step."""
        if self.step is None:
            self.step = step
        return self

    def __str__(self) -> str:
        message = super().__str__()
        return message if self.step is None else f"step '{self.step}': {message}"


class UsageError(MoveplanError):
    """A flag or argument is malformed (not a number, out of range, conflicting)."""

    exit_code = 2


class InputError(MoveplanError):
    """An input file is missing, unreadable or invalid."""

    exit_code = 3


class ConfigError(InputError):
    """A robot, scene or task file is invalid; the message names file and key."""


class CorruptData(InputError):
    """A structural error inside a recording, or a malformed message in it.

    The bag reader turns it into an InputError naming the file; one that escapes is still
    bad input (exit 3), never an internal error.
    """


class UnsupportedJoint(InputError):
    """The robot has a joint kind a model does not handle (the sphere filter: planar, free-flyer ...).

    The collision district catches it and falls back to exact checks; one that escapes is
    bad input (exit 3): a robot description moveplan cannot use, not a bug.
    """


class UnknownName(InputError):
    """A joint, group, link or named state that the robot does not have."""

    def __init__(self, what: str, name: str, source: str, valid: Iterable[str]) -> None:
        self.what, self.name, self.source = what, name, source
        self.valid = tuple(sorted(set(valid)))
        super().__init__(f"{what} '{name}' not found in {source}; known: {known(self.valid)}")


class FrameNotFound(UnknownName):
    """A frame that neither the scene nor the robot defines."""

    def __init__(self, name: str, source: str, valid: Iterable[str]) -> None:
        super().__init__("frame", name, source, valid)


class NoPlan(MoveplanError):
    """No motion could be produced for a valid request."""

    exit_code = 4


class InCollision(NoPlan):
    """A robot state collides; names the colliding pair and which state it is."""

    def __init__(self, pair: tuple[str, str], where: str) -> None:
        self.pair, self.where = pair, where
        super().__init__(f"{where} is in collision: {pair[0]} touches {pair[1]}")


class StartInCollision(InCollision):
    """The start state collides (or, with `where="every state"`, a pair that never moves touches)."""

    def __init__(self, pair: tuple[str, str], where: str = "start state") -> None:
        super().__init__(pair, where)


class GoalInCollision(InCollision):
    """The goal state collides; names the colliding pair."""

    def __init__(self, pair: tuple[str, str]) -> None:
        super().__init__(pair, "goal state")


class StartViolatesConstraints(NoPlan):
    """The start state violates the motion's path constraints (MoveIt: START_STATE_VIOLATES_PATH_CONSTRAINTS)."""


class GoalViolatesConstraints(NoPlan):
    """The goal state violates the motion's path constraints (MoveIt: GOAL_VIOLATES_PATH_CONSTRAINTS)."""


class OutsideLimits(NoPlan):
    """A joint value of a start or goal lies outside the joint's position limits."""

    what = "value"

    def __init__(self, joint: str, value: float, lower: float, upper: float, origin: str = "") -> None:
        self.joint, self.value, self.lower, self.upper = joint, value, lower, upper
        where = f"; the value comes from {origin}" if origin else ""
        super().__init__(
            f"{self.what} for joint '{joint}' is {value:.6g} rad, outside its limits "
            f"[{lower:.6g}, {upper:.6g}]{where}"
        )


class GoalOutsideLimits(OutsideLimits):
    """A goal joint value lies outside the joint's position limits."""

    what = "goal"


class StartOutsideLimits(OutsideLimits):
    """A start joint value lies outside the joint's position limits."""

    what = "start"


class GoalUnreachable(NoPlan):
    """No inverse-kinematics solution reaches the requested pose."""


class SolutionsCollide(GoalUnreachable):
    """Inverse kinematics reaches the requested pose, but every solution found is in collision."""


class PlanningFailed(NoPlan):
    """The planner found no path (or a linear path was incomplete)."""


class PlanningTimeExceeded(PlanningFailed):
    """A search reached its wall-clock safety limit (--timeout) before its budget of checked motions.

    Never caught to try something else: what a plan does next must not depend on the clock.
    """
