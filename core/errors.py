"""The one error hierarchy of moveplan: what went wrong, with what the user needs to fix it.

Each class carries the process exit code the CLI maps it to (DESIGN section 1):
2 usage, 3 bad input, 4 no plan. Messages name the file, key or joint and list
valid alternatives where there are any.
"""

from __future__ import annotations

from collections.abc import Iterable

__all__ = [
    "ConfigError",
    "FrameNotFound",
    "GoalInCollision",
    "GoalOutsideLimits",
    "GoalUnreachable",
    "InputError",
    "MoveplanError",
    "NoPlan",
    "PlanningFailed",
    "PlanningTimeExceeded",
    "StartInCollision",
    "UnknownName",
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
    """Base of every error moveplan raises on purpose."""

    exit_code = 1

    @property
    def kind(self) -> str:
        """Return the error's class name, as reported in JSON output."""
        return type(self).__name__


class UsageError(MoveplanError):
    """A flag or argument is malformed (not a number, out of range, conflicting)."""

    exit_code = 2


class InputError(MoveplanError):
    """An input file is missing, unreadable or invalid."""

    exit_code = 3


class ConfigError(InputError):
    """A robot, scene or task file is invalid; the message names file and key."""


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


class StartInCollision(NoPlan):
    """The start state collides; names the colliding pair."""

    def __init__(self, pair: tuple[str, str], where: str = "start state") -> None:
        self.pair = pair
        super().__init__(f"{where} is in collision: {pair[0]} touches {pair[1]}")


class GoalInCollision(StartInCollision):
    """The goal state collides; names the colliding pair."""

    def __init__(self, pair: tuple[str, str]) -> None:
        super().__init__(pair, where="goal state")


class GoalOutsideLimits(NoPlan):
    """A goal joint value lies outside the joint's position limits."""

    def __init__(self, joint: str, value: float, lower: float, upper: float) -> None:
        self.joint, self.value, self.lower, self.upper = joint, value, lower, upper
        super().__init__(
            f"goal for joint '{joint}' is {value:.6g} rad, outside its limits "
            f"[{lower:.6g}, {upper:.6g}]"
        )


class GoalUnreachable(NoPlan):
    """No inverse-kinematics solution reaches the requested pose."""


class PlanningFailed(NoPlan):
    """The planner found no path (or a linear path was incomplete)."""


class PlanningTimeExceeded(PlanningFailed):
    """A search reached the wall-clock planning time before its budget of checked motions.

    Never caught to try something else: what a plan does next must not depend on the clock.
    """
