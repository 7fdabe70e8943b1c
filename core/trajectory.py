"""Trajectory sampling as ros2_controllers' JointTrajectoryController (JTC) interpolates it.

Per segment, the spline degree follows the fields present at both ends
(joint_trajectory_controller trajectory.cpp, interpolation_method "splines"):
positions only give a linear segment, positions and velocities a cubic
Hermite, all three a quintic. After the last point the controller holds the
last point. Before the first point it blends from the state it read at its
first sample ("point before") when the first point's time_from_start is > 0,
and jumps to the first point when it is 0.

Sample times are on the controller's timeline: 0 is the first sample, the
trajectory's start (a MoveIt goal has header.stamp 0, "start now").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from moveplan.core.types import JointTrajectory, frozen_array

__all__ = ["PointBefore", "peak_rates", "sample", "shortest_angular_distance"]

Samples = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]


@dataclass(frozen=True)
class PointBefore:
    """The state the controller read at its first sample, which it blends from to the first point.

    Attributes:
        positions: Joint positions in [rad] or [m], shape (n,).
        velocities: In [rad]/[s], or None when the controller has no velocity state interface.
        accelerations: In [rad]/[s]^2, or None without an acceleration state interface.
    """

    positions: NDArray[np.float64]
    velocities: NDArray[np.float64] | None = None
    accelerations: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        positions = frozen_array(self.positions, (None,), "positions")
        object.__setattr__(self, "positions", positions)
        for name in ("velocities", "accelerations"):
            if getattr(self, name) is not None:
                value = frozen_array(getattr(self, name), positions.shape, name)
                object.__setattr__(self, name, value)


def shortest_angular_distance(
    from_rad: npt.ArrayLike, to_rad: npt.ArrayLike
) -> NDArray[np.float64]:
    """Return `to - from` in [rad] wrapped into (-pi, pi], as angles::shortest_angular_distance."""
    difference = np.asarray(to_rad, dtype=np.float64) - np.asarray(from_rad, dtype=np.float64)
    wrapped = np.fmod(difference + np.pi, 2.0 * np.pi)
    return np.where(wrapped <= 0.0, wrapped + np.pi, wrapped - np.pi)


def sample(
    trajectory: JointTrajectory,
    times_s: npt.ArrayLike,
    *,
    has_velocities: bool = True,
    has_accelerations: bool = True,
    point_before: PointBefore | None = None,
    continuous: npt.ArrayLike | None = None,
    derivatives: int = 2,
) -> Samples:
    """Return positions, velocities and accelerations, each (len(times), n), at `times_s` in [s].

    At and after the last point's time the last point is held, with its own velocities and
    accelerations (0 where absent), as JTC holds it.

    Args:
        trajectory: The trajectory as sent to the controller.
        times_s: Sample times on the controller's timeline in [s].
        has_velocities: False if the points carry no velocities (an empty field in the message).
        has_accelerations: False if the points carry no accelerations.
        point_before: The state the controller read at its first sample (time 0), blended
            from if the first point's time is > 0; without it, times before the first point
            give the first point.
        continuous: Per joint, True for URDF continuous joints: the point before is shifted by
            whole turns towards the first point (JTC `wraparound_joint`).
        derivatives: 2 for velocities and accelerations, 1 for velocities only, 0 for neither;
            what is not computed is returned as zeros (checks of long recordings need less).
    """
    knots = trajectory.times_s
    positions = trajectory.positions
    count, n = positions.shape
    velocities = trajectory.velocities if has_velocities else np.zeros((count, n))
    accelerations = trajectory.accelerations if has_accelerations else np.zeros((count, n))
    has_v = np.full(count, has_velocities)
    has_a = np.full(count, has_velocities and has_accelerations)
    if point_before is not None and knots[0] > 0.0:
        start = _wraparound(point_before.positions, positions[0], continuous)
        knots = np.concatenate(([0.0], knots))
        positions = np.vstack((start, positions))
        velocities = np.vstack((_or_zeros(point_before.velocities, n), velocities))
        accelerations = np.vstack((_or_zeros(point_before.accelerations, n), accelerations))
        has_v = np.concatenate(([point_before.velocities is not None], has_v))
        has_a = np.concatenate(([point_before.accelerations is not None and has_v[0]], has_a))
    t = np.atleast_1d(np.asarray(times_s, dtype=np.float64))
    return _sample_points(knots, positions, velocities, accelerations, has_v, has_a, t, derivatives)


def peak_rates(trajectory: JointTrajectory) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return per joint the largest |velocity| and |acceleration| anywhere along the interpolation.

    Exact for the controller's quintic segments: the acceleration of a segment is a
    cubic, largest at an end or where the jerk (a quadratic) is zero; between those
    points it is monotonic, so its zeros, where the velocity peaks, are found by bisection.
    """
    knots, p = trajectory.times_s, trajectory.positions
    if len(knots) == 1:
        return np.abs(trajectory.velocities[0]), np.abs(trajectory.accelerations[0])
    every = np.ones(len(knots), dtype=bool)
    _, c1, c2, c3, c4, c5 = _coefficients(knots, p, trajectory.velocities, trajectory.accelerations, every, every)
    h = np.broadcast_to(np.diff(knots)[:, None], c1.shape)

    def velocity(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return c1 + x * (2 * c2 + x * (3 * c3 + x * (4 * c4 + x * 5 * c5)))

    def acceleration(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return 2 * c2 + x * (6 * c3 + x * (12 * c4 + x * 20 * c5))

    jerk_zeros = [np.where((r >= 0) & (r <= h), r, 0.0) for r in _quadratic_roots(60 * c5, 24 * c4, 6 * c3)]
    bounds = np.sort(np.stack([np.zeros_like(h), *jerk_zeros, h]), axis=0)
    peak_a = np.max(np.abs(np.stack([acceleration(x) for x in bounds])), axis=(0, 1))
    candidates = [velocity(x) for x in bounds]
    for lo, hi in zip(bounds[:-1], bounds[1:], strict=True):
        a_lo = acceleration(lo)
        crossing = np.sign(a_lo) * np.sign(acceleration(hi)) < 0
        lo, hi = lo.copy(), hi.copy()
        for _ in range(32):  # the bracket shrinks to 2^-32 of a segment; near a peak v is flat
            mid = (lo + hi) / 2
            same = np.sign(acceleration(mid)) == np.sign(a_lo)
            lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        candidates.append(np.where(crossing, velocity(lo), 0.0))
    peak_v = np.max(np.abs(np.stack(candidates)), axis=(0, 1))
    return peak_v, peak_a


def _quadratic_roots(
    a: NDArray[np.float64], b: NDArray[np.float64], c: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return the real roots of a x^2 + b x + c elementwise (NaN or inf where there are none)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        root = np.sqrt(b * b - 4 * a * c)
        # The numerically stable form; with a = 0 the second root is the linear one, -c / b.
        q = -0.5 * (b + np.copysign(root, b))
        return q / a, c / q


def _or_zeros(values: NDArray[np.float64] | None, n: int) -> NDArray[np.float64]:
    return np.zeros(n) if values is None else values


def _wraparound(
    start: NDArray[np.float64], first: NDArray[np.float64], continuous: npt.ArrayLike | None
) -> NDArray[np.float64]:
    """Return `start` with continuous joints moved by whole turns to lie nearest to `first`."""
    if continuous is None:
        return start
    distance = shortest_angular_distance(start, first)
    # At exactly half a turn, JTC resolves the tie towards the side the first point lies on.
    tie = np.abs(np.abs(distance) - np.pi) < 1e-9
    distance = np.where(tie, np.where(first > start, np.abs(distance), -np.abs(distance)), distance)
    return np.where(np.asarray(continuous, dtype=bool), first - distance, start)


def _sample_points(
    knots: NDArray[np.float64],
    p: NDArray[np.float64],
    v: NDArray[np.float64],
    a: NDArray[np.float64],
    has_v: NDArray[np.bool_],
    has_a: NDArray[np.bool_],
    t: NDArray[np.float64],
    derivatives: int = 2,
) -> Samples:
    """Return samples of the spline through the points; `has_v`/`has_a`: fields each point has."""
    count, n = p.shape
    if count == 1:
        return _hold(p[0], v[0], a[0], len(t))
    seg = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, count - 2)
    # np.take copies rows contiguously; fancy indexing on axis 1 left strided arrays (2x slower).
    c0, c1, c2, c3, c4, c5 = np.take(_coefficients(knots, p, v, a, has_v, has_a), seg, axis=1)
    h = (knots[seg + 1] - knots[seg])[:, None]
    x = np.clip(t[:, None] - knots[seg][:, None], 0.0, h)
    pos = _horner((c0, c1, c2, c3, c4, c5), x)
    # Zeros from calloc cost nothing until written: long recordings need positions only.
    vel = _horner((c1, 2 * c2, 3 * c3, 4 * c4, 5 * c5), x) if derivatives >= 1 else np.zeros_like(pos)
    acc = _horner((2 * c2, 6 * c3, 12 * c4, 20 * c5), x) if derivatives >= 2 else np.zeros_like(pos)
    after = t >= knots[-1]
    pos[after], vel[after], acc[after] = p[-1], v[-1] if derivatives >= 1 else 0.0, a[-1] if derivatives >= 2 else 0.0
    before = t < knots[0]
    pos[before], vel[before], acc[before] = p[0], 0.0, 0.0
    return pos, vel, acc


def _horner(coefficients: tuple[NDArray[np.float64], ...], x: NDArray[np.float64]) -> NDArray[np.float64]:
    """Return sum_k coefficients[k] x^k, evaluated in place (one array, no temporaries per term)."""
    result = coefficients[-1] * x
    for coefficient in coefficients[-2:0:-1]:
        result += coefficient
        result *= x
    result += coefficients[0]
    return result


def _hold(
    p: NDArray[np.float64], v: NDArray[np.float64], a: NDArray[np.float64], count: int
) -> Samples:
    return np.tile(p, (count, 1)), np.tile(v, (count, 1)), np.tile(a, (count, 1))


def _coefficients(
    knots: NDArray[np.float64],
    p: NDArray[np.float64],
    v: NDArray[np.float64],
    a: NDArray[np.float64],
    has_v: NDArray[np.bool_],
    has_a: NDArray[np.bool_],
) -> NDArray[np.float64]:
    """Return coefficients c0..c5 of powers of time per segment, shape (6, segments, n)."""
    h = np.diff(knots)[:, None]
    p0, v0, a0, p1, v1, a1 = p[:-1], v[:-1], a[:-1], p[1:], v[1:], a[1:]
    dp = p1 - p0
    cubic = (has_v[:-1] & has_v[1:])[:, None]
    quintic = cubic & (has_a[:-1] & has_a[1:])[:, None]
    zeros = np.zeros_like(p0)
    c1 = np.where(cubic, v0, dp / h)
    c2 = np.where(quintic, a0 / 2, np.where(cubic, (3 * dp - (2 * v0 + v1) * h) / h**2, zeros))
    c3 = np.where(
        quintic,
        (20 * dp - (8 * v1 + 12 * v0) * h - (3 * a0 - a1) * h**2) / (2 * h**3),
        np.where(cubic, (-2 * dp + (v0 + v1) * h) / h**3, zeros),
    )
    c4 = np.where(
        quintic, (-30 * dp + (14 * v1 + 16 * v0) * h + (3 * a0 - 2 * a1) * h**2) / (2 * h**4), zeros
    )
    c5 = np.where(quintic, (12 * dp - 6 * (v1 + v0) * h - (a0 - a1) * h**2) / (2 * h**5), zeros)
    return np.stack((p0, c1, c2, c3, c4, c5))
