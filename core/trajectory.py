"""Trajectory sampling as ros2_controllers' JointTrajectoryController interpolates it.

Between two points carrying positions, velocities and accelerations the
controller uses a quintic polynomial per joint (joint_trajectory_controller
trajectory.cpp, interpolation_method "splines"); after the last point it holds
the last point. Sampling here is what the controller would command.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from moveplan.core.types import JointTrajectory

__all__ = ["peak_rates", "sample"]


def sample(
    trajectory: JointTrajectory, times_s: npt.ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Return positions, velocities and accelerations, each (len(times), n), at `times_s`.

    Times before the first point give the first point; after the last, the last point
    with zero velocity and acceleration, as the controller holds it.
    """
    t = np.atleast_1d(np.asarray(times_s, dtype=float))
    knots = trajectory.times_s
    p, v, a = trajectory.positions, trajectory.velocities, trajectory.accelerations
    if len(knots) == 1:
        return (np.repeat(p[:1], len(t), 0), np.zeros((len(t), p.shape[1])), np.zeros((len(t), p.shape[1])))
    seg = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, len(knots) - 2)
    h = (knots[seg + 1] - knots[seg])[:, None]
    p0, v0, a0 = p[seg], v[seg], a[seg]
    p1, v1, a1 = p[seg + 1], v[seg + 1], a[seg + 1]
    dp = p1 - p0
    c3 = (20 * dp - (8 * v1 + 12 * v0) * h - (3 * a0 - a1) * h**2) / (2 * h**3)
    c4 = (-30 * dp + (14 * v1 + 16 * v0) * h + (3 * a0 - 2 * a1) * h**2) / (2 * h**4)
    c5 = (12 * dp - 6 * (v1 + v0) * h - (a0 - a1) * h**2) / (2 * h**5)
    x = np.clip(t - knots[seg], 0.0, h[:, 0])[:, None]
    pos = p0 + x * (v0 + x * (a0 / 2 + x * (c3 + x * (c4 + x * c5))))
    vel = v0 + x * (a0 + x * (3 * c3 + x * (4 * c4 + x * 5 * c5)))
    acc = a0 + x * (6 * c3 + x * (12 * c4 + x * 20 * c5))
    after = t >= knots[-1]
    pos[after], vel[after], acc[after] = p[-1], 0.0, 0.0
    before = t < knots[0]
    pos[before], vel[before], acc[before] = p[0], 0.0, 0.0
    return pos, vel, acc


def peak_rates(trajectory: JointTrajectory, per_segment: int = 16) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return per joint the largest |velocity| and |acceleration| along the interpolated trajectory."""
    knots = trajectory.times_s
    if len(knots) == 1:
        zeros = np.zeros(len(trajectory.joint_names))
        return zeros, zeros
    fractions = np.linspace(0.0, 1.0, per_segment + 1)[:-1]
    times = (knots[:-1, None] + np.diff(knots)[:, None] * fractions[None, :]).ravel()
    _, vel, acc = sample(trajectory, np.append(times, knots[-1] - 1e-12))
    return np.abs(vel).max(axis=0), np.abs(acc).max(axis=0)
