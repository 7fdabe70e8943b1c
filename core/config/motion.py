"""The four settings a motion is planned with, and the one rule that layers them.

A motion's planner, planning time and velocity and acceleration scaling come from several
places: a step of a task, a flag, a MoveIt MotionPlanRequest, a task's defaults, the
commander's setters, the robot config. Each place gives a MotionSettings with what it sets
(None: not set there), and `layered` gives, per setting, the first place that sets it.
Values are checked where they are read, so that the error names the flag or file key.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

__all__ = ["MotionSettings", "Resolved", "layered", "resolved"]


@dataclass(frozen=True)
class MotionSettings:
    """What one place sets of a motion's settings; None leaves a setting to the places below it.

    Attributes:
        planner: OMPL planner name.
        planning_time: Seconds the planner may search: a budget of work.
        velocity_scaling, acceleration_scaling: Fractions of the joint limits, in (0, 1].
    """

    planner: str | None = None
    planning_time: float | None = None
    velocity_scaling: float | None = None
    acceleration_scaling: float | None = None


@dataclass(frozen=True)
class Resolved:
    """A motion's settings with every one decided (the robot config's defaults at the bottom)."""

    planner: str
    planning_time: float
    velocity_scaling: float
    acceleration_scaling: float


def layered(*places: MotionSettings) -> MotionSettings:
    """Return, per setting, the value of the first of `places` (highest precedence first) that sets it."""
    return MotionSettings(**{
        f.name: next((value for place in places if (value := getattr(place, f.name)) is not None), None)
        for f in fields(MotionSettings)
    })


def resolved(*places: MotionSettings, defaults: Resolved) -> Resolved:
    """Return the settings `places` give (highest precedence first), each unset one taken from `defaults`."""
    given = layered(*places)
    return Resolved(**{f.name: getattr(defaults, f.name) if getattr(given, f.name) is None else getattr(given, f.name)
                       for f in fields(Resolved)})
