"""What `inspect` reports of a plan: each step's peak rates as fractions of the plan's own limits."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from moveplan.core.bag import PlanFile, PlanStepRecord
from moveplan.core.pipeline.inspection import StepPeaks, step_peaks
from moveplan.core.types import JointTrajectory


def test_peak_rates_are_fractions_of_each_joints_limit_and_the_largest_joint_counts() -> None:
    # a at 1 rad/s all along (a straight quintic), b at rest: a's fraction of its limit is the peak.
    trajectory = JointTrajectory(("a", "b"), np.array([0.0, 1.0]), np.array([[0.0, 0.0], [1.0, 0.0]]),
                                 np.array([[1.0, 0.0], [1.0, 0.0]]), np.zeros((2, 2)))
    limits = {"a": {"max_velocity": 4.0, "max_acceleration": 2.0}, "b": {"max_velocity": 0.1, "max_acceleration": 0.1}}
    plan = PlanFile("r", "g", "base", "jazzy", (PlanStepRecord("go", 2.5, trajectory),), {}, {}, limits)
    (peaks,) = step_peaks(plan, Path("plan.mcap"))
    assert peaks == StepPeaks("go", 2.5, 1.0, 2, peaks.peak_velocity_fraction, peaks.peak_acceleration_fraction)
    np.testing.assert_allclose(peaks.peak_velocity_fraction, 0.25, atol=1e-12)
    np.testing.assert_allclose(peaks.peak_acceleration_fraction, 0.0, atol=1e-12)
