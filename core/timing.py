"""Time parameterisation of a joint-space path with TOPPRA, within velocity and acceleration limits.

TOPPRA times a spline through the path; its joint accelerations jump at grid
points, and the controller's quintic between sampled points can overshoot
them. So the sampled trajectory is checked densely, as the controller
interpolates it, and re-timed against tighter limits until it holds.
"""

from __future__ import annotations

import logging

import numpy as np
import toppra
import toppra.algorithm
import toppra.constraint
import toppra.parametrizer
from numpy.typing import NDArray

from moveplan.core.errors import PlanningFailed
from moveplan.core.trajectory import peak_rates
from moveplan.core.types import JointTrajectory

__all__ = ["resample_path", "time_parameterize"]

logger = logging.getLogger(__name__)
# TOPPRA logs its numerical trouble itself; we report failures as PlanningFailed instead.
logging.getLogger("toppra").setLevel(logging.CRITICAL)

_ATTEMPTS = 6
_GRID_INTERVALS = 100


def resample_path(waypoints: NDArray[np.float64], max_step: float) -> NDArray[np.float64]:
    """Return the polyline through `waypoints` with no joint moving more than `max_step` per step."""
    points = [waypoints[:1]]
    for a, b in zip(waypoints[:-1], waypoints[1:], strict=True):
        count = max(1, int(np.ceil(np.max(np.abs(b - a)) / max_step)))
        points.append(a + (b - a) * (np.arange(1, count + 1) / count)[:, None])
    return np.concatenate(points)


def time_parameterize(
    joint_names: tuple[str, ...],
    waypoints: NDArray[np.float64],
    max_velocity: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
    sample_period_s: float = 0.01,
    max_step: float = 0.05,
) -> JointTrajectory:
    """Return the time-optimal trajectory along `waypoints` within the (already scaled) limits.

    The result starts and ends at rest (velocity and acceleration exactly 0), its
    times are whole nanoseconds, and its quintic interpolation stays within the limits.
    """
    path = resample_path(waypoints, max_step)
    keep = np.concatenate(([True], np.any(np.abs(np.diff(path, axis=0)) > 1e-12, axis=1)))
    path = path[keep]
    if len(path) == 1:
        zeros = np.zeros_like(path)
        return JointTrajectory(joint_names, [0.0], path, zeros, zeros)
    # TOPPRA's optimum touches the limits between its grid points and its time law is
    # smoothed into a spline, so the result peaks up to ~1 % above the velocity limits and
    # ~20 % above the acceleration limits; the overshoot scales with the limit given.
    velocity_margin, acceleration_margin = 0.99, 0.86
    for _ in range(_ATTEMPTS):
        trajectory = _toppra(joint_names, path, max_velocity * velocity_margin,
                             max_acceleration * acceleration_margin, sample_period_s)
        peak_v, peak_a = peak_rates(trajectory)
        excess_v = float(np.max(peak_v / max_velocity))
        excess_a = float(np.max(peak_a / max_acceleration))
        if excess_v <= 1.0 and excess_a <= 1.0:
            return trajectory
        logger.debug("timing peaks at %.3f of velocity, %.3f of acceleration limits; retrying",
                     excess_v, excess_a)
        velocity_margin *= min(1.0, 0.995 / excess_v)
        acceleration_margin *= min(1.0, 0.995 / excess_a)
    raise PlanningFailed("time parameterisation could not keep the interpolated trajectory within the limits")


def _gridpoints(count: int) -> NDArray[np.float64]:
    """Return path parameters in [0, 1]: uniform, refined geometrically towards both ends."""
    # Finer than 1e-5 of the path, TOPPRA's solver loses its footing (infeasible sets).
    ends = np.geomspace(1e-5, 2.0 / count, 30)
    return np.unique(np.concatenate((np.linspace(0.0, 1.0, count + 1), ends, 1.0 - ends)))


def _soft_ends(grid: NDArray[np.float64], sd: NDArray[np.float64], ramp_s: float) -> NDArray[np.float64]:
    """Return path speeds capped so the path acceleration fades to 0 at both ends.

    TOPPRA brakes at full deceleration D right up to the goal, so the acceleration
    jumps to 0 at the last point and the controller's quintic overshoots the limit.
    Capping the speed squared by 4/3 D x^1.5 / sqrt(delta) within distance delta of an
    end (x the distance, beyond it 2 D x - 2/3 D delta) makes the deceleration fall
    as sqrt(x) to 0, never exceed D, and still stop in the finite time `ramp_s`.
    """
    speed2 = sd**2
    for x, side in ((1.0 - grid, slice(-6, None)), (grid, slice(0, 6))):
        window = grid[side]
        decel = np.abs(np.diff(speed2[side])) / (2 * np.diff(window))
        rate = float(np.max(decel))
        if rate <= 0.0:
            continue
        delta = rate * ramp_s**2 / 12.0
        cap = np.where(x < delta, 4.0 / 3.0 * rate * x**1.5 / np.sqrt(delta), 2 * rate * x - 2.0 / 3.0 * rate * delta)
        speed2 = np.minimum(speed2, cap)
    return np.sqrt(np.maximum(speed2, 0.0))


def _toppra(
    joint_names: tuple[str, ...],
    path: NDArray[np.float64],
    max_velocity: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
    sample_period_s: float,
) -> JointTrajectory:
    arc = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))))
    spline = toppra.SplineInterpolator(arc / arc[-1], path)
    constraints = [
        toppra.constraint.JointVelocityConstraint(np.stack([-max_velocity, max_velocity], axis=1)),
        toppra.constraint.JointAccelerationConstraint(np.stack([-max_acceleration, max_acceleration], axis=1)),
    ]
    grid = _gridpoints(max(_GRID_INTERVALS, 4 * len(path)))
    algorithm = toppra.algorithm.TOPPRA(constraints, spline, gridpoints=grid)
    _, sd, _ = algorithm.compute_parameterization(0.0, 0.0)
    if sd is None or not np.all(np.isfinite(sd)):
        raise PlanningFailed("TOPPRA found no feasible time parameterisation of the path")
    sd = _soft_ends(grid, sd, 10 * sample_period_s)
    timed = toppra.parametrizer.ParametrizeSpline(spline, grid, sd)
    duration = float(timed.duration)
    times = np.linspace(0.0, duration, max(2, int(np.ceil(duration / sample_period_s)) + 1))
    return _sampled(joint_names, timed, times, path)


def _sampled(
    joint_names: tuple[str, ...],
    timed: toppra.parametrizer.ParametrizeSpline,
    times: NDArray[np.float64],
    path: NDArray[np.float64],
) -> JointTrajectory:
    """Return `timed` sampled at `times`, rounded to whole nanoseconds, starting and ending at rest."""
    # Whole nanoseconds, so the times written to a message are exactly the times checked here.
    times = np.unique(np.round(times * 1e9)) / 1e9
    positions, velocities, accelerations = timed(times), timed(times, 1), timed(times, 2)
    positions[0], positions[-1] = path[0], path[-1]
    for rates in (velocities, accelerations):
        rates[0], rates[-1] = 0.0, 0.0
    return JointTrajectory(joint_names, times, positions, velocities, accelerations)
