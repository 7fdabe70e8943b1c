"""The four settings a motion is planned with, and the one rule that layers them.

A motion's planner, planning time and velocity and acceleration scaling come from several
places: a step of a task, a flag, a MoveIt MotionPlanRequest, a task's defaults, the
commander's setters, the robot config. Each place gives a MotionSettings with what it sets
(None: not set there), and `layered` gives, per setting, the first place that sets it.
What values are valid is decided here (`is_scaling`, `is_planning_time`); each parser applies
that rule where it reads a value, so that the error names the flag or file key.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from .fields import MAX_MAGNITUDE

__all__ = ["MIN_SCALING", "MotionSettings", "Resolved", "is_planning_time", "is_scaling", "layered", "resolved"]

# A motion slowed more than a thousandfold lasts hours for a radian, and the plan's /tf
# samples and an execution's control cycles grow with it (1e-9 asked for terabytes): a typo.
MIN_SCALING = 1e-3


@dataclass(frozen=True)
class MotionSettings:
    """What one place sets of a motion's settings; None leaves a setting to the places below it.

    Attributes:
        planner: OMPL planner name.
        planning_time: Seconds the planner may search: a budget of work.
        velocity_scaling, acceleration_scaling: Fractions of the joint limits, in [MIN_SCALING, 1].
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


def is_scaling(factor: float) -> bool:
    """Return whether `factor` is a velocity or acceleration scaling moveplan plans with: in [MIN_SCALING, 1]."""
    return MIN_SCALING <= factor <= 1.0  # NaN too: it compares false


def is_planning_time(seconds: float) -> bool:
    """Return whether `seconds` is a planning time moveplan plans with: positive, at most MAX_MAGNITUDE."""
    return 0.0 < seconds <= MAX_MAGNITUDE  # NaN too: it compares false
