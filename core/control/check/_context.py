"""What every part of a recording check shares, computed once: samples, step profiles, tolerances."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Protocol

from ...config import ControllerConfig, ExecutionConfig
from ...types import JointTrajectory
from ..tolerances import (
    SegmentTolerances,
    goal_segment_tolerances,
    in_controller_order,
    segment_tolerances,
    velocity_error_computable,
)
from ._alignment import ZONE_RAD, StepProfile
from .samples import Samples, SampleSource

__all__ = ["PLAN_PROFILE_SAMPLES", "CheckContext", "CheckedPlan", "CheckedStep"]

PLAN_PROFILE_SAMPLES = 2_000_000
"""The most points the profiles of all a plan's steps have together (32 MB of times and distances)."""


class CheckedStep(Protocol):
    """A step of the plan checked: its name, start on the plan's timeline and trajectory."""

    @property
    def name(self) -> str:
        """The step's name."""

    @property
    def start_s(self) -> float:
        """Where the step starts on the plan's timeline, in [s]."""

    @property
    def trajectory(self) -> JointTrajectory:
        """The step's trajectory, its times from the step's start."""


class CheckedPlan(Protocol):
    """The plan checked: its steps (a PlanFile is one)."""

    @property
    def steps(self) -> Sequence[CheckedStep]:
        """The plan's steps, in order."""


@dataclass(frozen=True)
class CheckContext:
    """Everything the checks share, computed once.

    Attributes:
        samples: The recorded positions (and velocities) in controller order, with their times.
        profiles: Per step of the plan, its trajectory in controller order and how it departs.
        check_velocities: True if JTC computes velocity errors and the recording has velocities.
        controller: The JointTrajectoryController whose tolerances apply.
        execution: MoveIt's trajectory_execution settings.
        tolerances: The controller's tolerances.
        warnings: What the recording lacks: samples too sparse, no velocities.
    """

    samples: Samples
    profiles: tuple[StepProfile, ...]
    check_velocities: bool
    controller: ControllerConfig
    execution: ExecutionConfig
    tolerances: SegmentTolerances
    warnings: tuple[str, ...]
    goal_tolerances: dict[str, SegmentTolerances] = field(default_factory=dict)

    def tolerances_of(self, step: str) -> SegmentTolerances:
        """Return the tolerances of a step's goal: the controller's, or those its goal carries."""
        return self.goal_tolerances.get(step, self.tolerances)

    @staticmethod
    def build(
        plan: CheckedPlan, recording: SampleSource, controller: ControllerConfig,
        execution: ExecutionConfig, continuous_joints: Iterable[str],
    ) -> CheckContext:
        """Return the context of checking `recording` against `plan` with these settings."""
        samples = Samples.build(recording, controller.joints, continuous_joints)
        zone = max(ZONE_RAD, 2.0 * execution.allowed_start_tolerance)
        # One grid for all steps, kept to PLAN_PROFILE_SAMPLES points in all: many long steps are
        # profiled more coarsely, not in gigabytes (a plan under about half an hour keeps 1 ms).
        total_s = sum(step.trajectory.duration_s for step in plan.steps)
        resolution = max(1e-3, total_s / PLAN_PROFILE_SAMPLES)
        # Joints a partial goal leaves out hold where the robot is; it is taken as recorded first.
        hold = samples.rows(0, 1)[0] if samples.count else None
        profiles = tuple(
            StepProfile.build(step.name, in_controller_order(step.trajectory, controller, hold),
                              samples.continuous, zone, resolution)
            for step in plan.steps
        )
        computable = velocity_error_computable(controller)
        warnings = []
        period = samples.period_s
        if period > 1.5 / controller.update_rate_hz:
            warnings.append(
                f"the recording has a sample every {period * 1e3:.3g} ms, the controller checks "
                f"every {1e3 / controller.update_rate_hz:.3g} ms: short excursions between "
                "samples are not seen")
        if not samples.has_velocities and computable:
            warnings.append("the recording carries no velocities: the stopped velocity "
                            "tolerance is not checked")
        defaults = segment_tolerances(controller)
        goals = {step.name: goal_segment_tolerances(defaults, getattr(step, "tolerances", None))
                 for step in plan.steps}
        return CheckContext(samples, profiles, computable and samples.has_velocities, controller,
                            execution, defaults, tuple(warnings), goals)

    def before_recording(self, start: float) -> bool:
        """Return True if a goal started at `start` [s] was sent before the recording's first sample.

        A sample period of slack: an execution recorded from its send time (an executed file)
        is aligned to within a period of its first sample, on either side.
        """
        return start < self.samples.first_time - self.samples.period_s
