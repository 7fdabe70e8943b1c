"""Timing is total: any polyline a planner returns, within any limits, gives a valid trajectory or a named error."""

from __future__ import annotations

import logging
import math
import re
from collections.abc import Callable

import numpy as np
import pytest
import toppra
from hypothesis import HealthCheck, assume, example, given, seed, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from moveplan.core.errors import PlanningFailed
from moveplan.core.timing import time_parameterize
from moveplan.core.trajectory import peak_rates, sample
from moveplan.core.types import JointTrajectory

logging.getLogger("toppra").setLevel(logging.CRITICAL)

Case = tuple[np.ndarray, np.ndarray, np.ndarray]

MAX_STEP = 0.05  # [rad] time_parameterize's default
RATE_TOLERANCE = 1e-6  # relative, on the exact peaks of the controller's quintics
# Between knots the controller's quintic can leave the motion it samples (where the path's
# third derivative jumps, at the end of a corner blend): by up to 4e-6 rad past the waypoints'
# range in 2 x 10^4 random cases like those below, 3.3e-5 rad in CORNER_DIP.
RANGE_SLACK = 1e-4  # [rad]

# A fixed seed and no example database: every checkout, wherever it lies, runs the same cases
# (derandomize hashes the test's location, so a clone in another folder drew others).
# These budgets keep the whole file near 20 s on a 2-core machine.
PROPERTIES = settings(deadline=None, database=None, max_examples=800,
                      suppress_health_check=[HealthCheck.too_slow])


def names(n: int) -> tuple[str, ...]:
    return tuple(f"j{i}" for i in range(n))


def corner_bound(n: int, max_step: float = MAX_STEP) -> float:
    """A blend strays at most 3/16 h |d_out - d_in| <= 3/8 h, h <= 0.44 of a step <= max_step in every joint."""
    return 3 / 8 * 0.44 * max_step * math.sqrt(n)


def dense_positions(trajectory: JointTrajectory, per_interval: int = 16) -> np.ndarray:
    """Positions of the controller's interpolation, `per_interval` samples between knots."""
    knots = trajectory.times_s
    if len(knots) == 1:
        return trajectory.positions
    fractions = np.linspace(0.0, 1.0, per_interval + 1)
    times = np.unique((knots[:-1, None] + np.diff(knots)[:, None] * fractions).ravel())
    positions, _, _ = sample(trajectory, times, derivatives=0)
    return positions


def polyline_distance(positions: np.ndarray, waypoints: np.ndarray) -> float:
    """Largest distance [rad] of `positions` from the waypoints' polyline (repeats and one point allowed)."""
    a, b = (waypoints[:-1], waypoints[1:]) if len(waypoints) > 1 else (waypoints, waypoints)
    along = b - a
    length2 = np.sum(along**2, axis=1)
    t = np.einsum("psn,sn->ps", positions[:, None] - a, along) / np.where(length2 > 0.0, length2, 1.0)
    nearest = a + np.clip(t, 0.0, 1.0)[..., None] * along
    return float(np.max(np.min(np.linalg.norm(positions[:, None] - nearest, axis=2), axis=1)))


def assert_valid(trajectory: JointTrajectory, waypoints: np.ndarray, max_velocity: np.ndarray,
                 max_acceleration: np.ndarray) -> None:
    """Assert every promise of time_parameterize about `trajectory` along `waypoints`."""
    times = trajectory.times_s
    assert times[0] == 0.0 and np.all(np.diff(times) > 0.0)
    np.testing.assert_array_equal(times, np.rint(times * 1e9) / 1e9)  # whole nanoseconds
    np.testing.assert_array_equal(trajectory.positions[[0, -1]], waypoints[[0, -1]])
    assert not trajectory.velocities[[0, -1]].any() and not trajectory.accelerations[[0, -1]].any()
    peak_v, peak_a = peak_rates(trajectory)
    assert np.all(peak_v <= max_velocity * (1 + RATE_TOLERANCE)), peak_v / max_velocity
    assert np.all(peak_a <= max_acceleration * (1 + RATE_TOLERANCE)), peak_a / max_acceleration
    positions = dense_positions(trajectory)
    assert polyline_distance(positions, waypoints) <= corner_bound(waypoints.shape[1])
    low, high = waypoints.min(axis=0), waypoints.max(axis=0)
    # The knots lie on the rounded polyline, inside the waypoints' range but for rounding.
    rounding = 1e-12 * (1.0 + np.abs(waypoints).max())
    assert np.all(trajectory.positions >= low - rounding) and np.all(trajectory.positions <= high + rounding)
    assert np.all(positions >= low - RANGE_SLACK) and np.all(positions <= high + RANGE_SLACK)


def unit_direction(draw: st.DrawFn, n: int) -> np.ndarray:
    """A direction whose largest joint component is 1 in size."""
    direction = draw(hnp.arrays(np.float64, n, elements=st.floats(-1.0, 1.0)))
    size = np.abs(direction).max()
    if size < 1e-3:
        direction, size = np.eye(n)[0], 1.0
    return direction / size


MOVES = ("step", "step", "repeat", "back", "onward", "part back", "one joint")


@st.composite
def polylines(draw: st.DrawFn, shortest: float = 1e-6, longest: float = 20.0, at_limits: bool = True) -> np.ndarray:
    """Waypoints as planners return them: repeats, exact reversals, collinear points, one joint alone.

    Each step moves its largest joint by `shortest` to `longest` [rad], a path's steps by
    `shortest` up to a drawn scale, log-uniformly; some paths move one joint alone, and with
    `at_limits` some sit at a joint limit for a while (clipped to the middle 60 % of each
    joint's range, which can shorten steps below `shortest`).
    """
    n = draw(st.integers(2, 9))
    low = math.log10(shortest)
    high = draw(st.floats(low, math.log10(longest)))
    offset = draw(st.sampled_from([1.0, 10.0]))  # positions near 0, or tens of rad away
    alone = draw(st.one_of(st.none(), st.integers(0, n - 1)))
    points = [draw(hnp.arrays(np.float64, n, elements=st.floats(-3.0, 3.0))) * offset]

    def length() -> float:
        return 10.0 ** draw(st.floats(low, high))

    for move in draw(st.lists(st.sampled_from(MOVES), min_size=1, max_size=8)):
        last = points[-1]
        previous = points[-2] if len(points) > 1 else None
        if move == "repeat":
            points.append(last.copy())
        elif move == "back" and previous is not None:
            points.append(previous.copy())  # a cusp: back exactly the way it came
        elif move in ("onward", "part back") and previous is not None and np.any(last != previous):
            along = (last - previous) / np.abs(last - previous).max()
            points.append(last + along * length() * (1.0 if move == "onward" else -1.0))
        elif move == "one joint" or alone is not None:
            joint = draw(st.integers(0, n - 1)) if alone is None else alone
            points.append(last + np.eye(n)[joint] * length() * draw(st.sampled_from([-1.0, 1.0])))
        else:
            points.append(last + unit_direction(draw, n) * length())
    waypoints = np.array(points)
    if at_limits and draw(st.booleans()):
        low, high = waypoints.min(axis=0), waypoints.max(axis=0)
        waypoints = np.clip(waypoints, low + 0.2 * (high - low), high - 0.2 * (high - low))
    return waypoints


@st.composite
def limits(draw: st.DrawFn, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Velocity [rad]/[s] and acceleration [rad]/[s]^2 limits, equal or strongly unequal per joint."""
    exponents = st.floats(-1.0, 1.0)
    velocity = 10.0 ** draw(st.floats(-1.5, 1.0)) * 10.0 ** (
        draw(hnp.arrays(np.float64, n, elements=exponents)) * draw(st.sampled_from([0.0, 1.0, 2.0])))
    acceleration = 10.0 ** draw(st.floats(-1.5, 2.0)) * 10.0 ** (
        draw(hnp.arrays(np.float64, n, elements=exponents)) * draw(st.sampled_from([0.0, 1.0, 2.0])))
    return velocity, acceleration


@st.composite
def cases(draw: st.DrawFn, shortest: float = 1e-6, at_limits: bool = True) -> Case:
    """A polyline and limits for its joints."""
    waypoints = draw(polylines(shortest, at_limits=at_limits))
    return (waypoints, *draw(limits(waypoints.shape[1])))


# The smallest polylines that showed each defect these tests found, and what the code did before.
SLOW_JOINT = ([[0.0], [1.0]], [3e-5], [1.0])  # a knot dropped before a long quintic: 7.5e9 s, 5.8e4 rad off
REVERSAL = ([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0]], [0.1, 1.0], [100.0, 1.0])  # velocity peak inside: 25.3 s
SLOW_CORNER = ([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]], [1e-4, 1e-4], [1.0, 1.0])  # digits lost: 3.3e5 s
REPEATS = ([[0.0, 0.0], [0.9e-12, 0.0], [1.8e-12, 0.0]], [1.0, 1.0], [1.0, 1.0])  # ValueError
NUDGE = ([[0.0, 0.0], [5e-13, 0.0]], [1.0, 1.0], [1.0, 1.0])  # ended 5e-13 rad short
HUGE_ACCELERATION = ([[0.0, 0.0], [1.0, 0.0]], [1.0, 1.0], [1e20, 1e20])  # "path blocked"
LONG = ([[0.0, 0.0], [1.0, 0.5], [2.0, 0.0]], [3e-7, 3e-7], [1.0, 1.0])  # 77 days, still whole nanoseconds
CORNER_DIP = ([[0.0, 0.0], [1.0, 0.0], [1.0001, 0.0], [1.1001, 0.1], [2.1001, 0.1], [3.1001, 0.1]],
              [1.0, 0.17782794], [31.6227766, 31.6227766])  # dips 3.3e-5 rad below j1's range
ROUNDING = ([[-6.370732752985129], [-6.370836567216275], [-6.370837523938305]],  # knots 1e-4 s apart peak
            [19.44967878254027], [0.00263400883138655])  # at 1.00002 of the limit once rounded


def as_case(case: tuple[list[list[float]], list[float], list[float]]) -> Case:
    return np.array(case[0]), np.array(case[1]), np.array(case[2])


def hand_picked(test: Callable[[Case], None]) -> Callable[[Case], None]:
    """Return `test` with the hand-picked cases above added to hypothesis's."""
    for case in (SLOW_JOINT, REVERSAL, SLOW_CORNER, REPEATS, NUDGE, HUGE_ACCELERATION, ROUNDING, LONG, CORNER_DIP):
        test = example(as_case(case))(test)
    return test


@PROPERTIES
@seed(20261125)
@given(cases())
@hand_picked
def test_any_polyline_within_any_limits_gives_a_valid_trajectory(case: Case) -> None:
    waypoints, max_velocity, max_acceleration = case
    trajectory = time_parameterize(names(waypoints.shape[1]), waypoints, max_velocity, max_acceleration)
    assert_valid(trajectory, waypoints, max_velocity, max_acceleration)


@settings(PROPERTIES, max_examples=300)
@seed(20261125)
@given(cases())
@hand_picked
def test_the_compiled_twins_give_the_same_trajectory_to_the_bit(case: Case) -> None:
    # A plan's file must not depend on whether the sphere filter had loaded numba.
    waypoints, max_velocity, max_acceleration = case
    joints = names(waypoints.shape[1])
    try:
        reference = time_parameterize(joints, waypoints, max_velocity, max_acceleration)
    except PlanningFailed as exc:
        with pytest.raises(PlanningFailed, match=re.escape(str(exc))):
            time_parameterize(joints, waypoints, max_velocity, max_acceleration, compiled=True)
        return
    twin = time_parameterize(joints, waypoints, max_velocity, max_acceleration, compiled=True)
    for field in ("times_s", "positions", "velocities", "accelerations"):
        assert np.array_equal(getattr(twin, field), getattr(reference, field)), field


def stop_at_every_waypoint_s(waypoints: np.ndarray, max_velocity: np.ndarray, max_acceleration: np.ndarray) -> float:
    """Return the duration [s] of timing each segment on its own, from rest to rest."""
    joints = names(waypoints.shape[1])
    return sum(time_parameterize(joints, waypoints[k : k + 2], max_velocity, max_acceleration).duration_s
               for k in range(len(waypoints) - 1))


# Rounding corners instead of stopping at them saves time, less what the smoothing and the final
# uniform slow-down cost: at most 6 % more in 8000 random cases with steps >= 0.01 rad (99 % of
# them within 0.1 %). Paths with shorter steps can be slower: a blend crossed faster than the
# 1-10 ms smoothing window takes in the speed of its neighbours, and the slow-down that brings
# it within the limits applies to the whole motion (up to 7x the stops' duration with steps of
# 1e-6 rad, 2x with 1e-4 rad, 1.14x with 1e-3 rad). The same holds where a joint reaches full
# speed in much less than the window: 0 -> -2 rad reversing by 0.01 rad with 0.32 rad/s and
# 1000 rad/s^2 (0.3 ms to full speed) takes 1.12x the stops. The property is asserted for
# joints that take 10 ms or more to reach full speed, as robot arms do.
STOPPING_RATIO = 1.10


@PROPERTIES
@seed(20261125)
@given(cases(shortest=0.01, at_limits=False))
@example(as_case(SLOW_JOINT))
@example(as_case(REVERSAL))  # 1.27 before
@example(as_case(SLOW_CORNER))  # 1.67 before
def test_rounding_corners_is_no_slower_than_stopping_at_them(case: Case) -> None:
    waypoints, max_velocity, max_acceleration = case
    assume(bool(np.all(max_acceleration <= 100.0 * max_velocity)))
    trajectory = time_parameterize(names(waypoints.shape[1]), waypoints, max_velocity, max_acceleration)
    assert trajectory.duration_s <= STOPPING_RATIO * stop_at_every_waypoint_s(waypoints, max_velocity,
                                                                              max_acceleration)


@pytest.mark.parametrize(("waypoints", "max_velocity", "max_acceleration", "max_step", "match"), [
    ([[0.0, 0.0], [np.nan, 1.0]], [1.0, 1.0], [1.0, 1.0], 0.05, "waypoint 1 has a non-finite position for joint 'j0'"),
    ([[0.0, 0.0], [1.0, np.inf]], [1.0, 1.0], [1.0, 1.0], 0.05, "waypoint 1 .* joint 'j1': inf"),
    ([[0.0, 0.0], [1.0, 1.0]], [1.0, 0.0], [1.0, 1.0], 0.05, "max_velocity of joint 'j1' is 0.0"),
    ([[0.0, 0.0], [1.0, 1.0]], [-1.0, 1.0], [1.0, 1.0], 0.05, "max_velocity of joint 'j0' is -1.0"),
    ([[0.0, 0.0], [1.0, 1.0]], [1.0, 1.0], [np.nan, 1.0], 0.05, "max_acceleration of joint 'j0' is nan"),
    ([[0.0, 0.0], [1.0, 1.0]], [1.0, 1.0], [1.0, np.inf], 0.05, "max_acceleration of joint 'j1' is inf"),
    ([[0.0, 0.0], [1.0, 1.0]], [1.0, 1.0], [1.0, 1.0], 0.0, "max_step is 0.0"),
    ([[0.0, 0.0], [1.0, 1.0]], [1.0, 1.0, 1.0], [1.0, 1.0], 0.05, r"max_velocity has shape \(3,\)"),
    ([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]], [1.0, 1.0], [1.0, 1.0], 0.05, r"shape \(m >= 1, 2\).*got shape \(2, 3\)"),
    (np.zeros((0, 2)), [1.0, 1.0], [1.0, 1.0], 0.05, r"got shape \(0, 2\)"),
])
def test_invalid_input_fails_naming_the_cause(waypoints: object, max_velocity: list[float],
                                               max_acceleration: list[float], max_step: float, match: str) -> None:
    with pytest.raises(PlanningFailed, match=match):
        time_parameterize(names(2), waypoints, np.array(max_velocity), np.array(max_acceleration), max_step)


@pytest.mark.parametrize(("max_velocity", "max_acceleration"), [(1e-300, 1.0), (1e-12, 1.0), (1.0, 1e-300)])
def test_motion_longer_than_104_days_fails_naming_its_duration(max_velocity: float, max_acceleration: float) -> None:
    waypoints = np.array([[0.0, 0.0], [1.0, 1.0], [0.0, 2.0]])
    with pytest.raises(PlanningFailed, match=r"would last .* s at these limits, longer than the 9.01e\+06 s"):
        time_parameterize(names(2), waypoints, np.full(2, max_velocity), np.full(2, max_acceleration))


@pytest.mark.parametrize("max_velocity", [1e50, 1e300])
def test_huge_limits_count_as_large_ones(max_velocity: float) -> None:
    waypoints = np.array([[0.0, 0.0], [1.0, 1.0], [0.0, 2.0]])
    velocity, acceleration = np.full(2, max_velocity), np.full(2, 1e300)
    assert_valid(time_parameterize(names(2), waypoints, velocity, acceleration), waypoints, velocity, acceleration)


def test_one_point_or_repeats_of_one_point_give_a_single_point() -> None:
    for waypoints in (np.ones((1, 3)), np.ones((4, 3))):
        trajectory = time_parameterize(names(3), waypoints, np.ones(3), np.ones(3))
        assert trajectory.times_s.tolist() == [0.0]
        np.testing.assert_array_equal(trajectory.positions, waypoints[:1])


def toppra_duration(waypoints: np.ndarray, max_velocity: np.ndarray, max_acceleration: np.ndarray,
                    max_step: float = MAX_STEP) -> float:
    """Return TOPP-RA's optimal duration [s] on a cubic spline through the waypoints resampled at `max_step`.

    As benchmarks/timing_speed.py: not-a-knot spline by chord length, TOPP-RA (toppra, seidel
    solver) on 16 and 32 grid intervals per resampled step, extrapolated to a step of 0.
    """
    points = [waypoints[:1]]
    for a, b in zip(waypoints[:-1], waypoints[1:], strict=True):
        count = max(1, int(np.ceil(np.max(np.abs(b - a)) / max_step)))
        points.append(a + (b - a) * (np.arange(1, count + 1) / count)[:, None])
    path = np.concatenate(points)
    arc = np.concatenate(([0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))))
    arc /= arc[-1]
    spline = toppra.SplineInterpolator(arc, path)
    constraints = [
        toppra.constraint.JointVelocityConstraint(np.stack([-max_velocity, max_velocity], axis=1)),
        toppra.constraint.JointAccelerationConstraint(np.stack([-max_acceleration, max_acceleration], axis=1)),
    ]
    durations = []
    for per_interval in (16, 32):
        grid = np.unique(np.concatenate([np.linspace(a, b, per_interval + 1) for a, b in zip(arc[:-1], arc[1:],
                                                                                              strict=True)]))
        algorithm = toppra.algorithm.TOPPRA(constraints, spline, gridpoints=grid, solver_wrapper="seidel")
        _, sd, _ = algorithm.compute_parameterization(0.0, 0.0)
        assert sd is not None, "toppra found no parameterisation"
        durations.append(float(np.sum(2 * np.diff(grid) / (sd[:-1] + sd[1:]))))
    # The discrete optimum converges linearly in the grid step: extrapolate to step 0 (Richardson).
    return 2 * durations[1] - durations[0]


@st.composite
def smooth_paths(draw: st.DrawFn) -> Case:
    """A planner's path after shortcutting: 2-6 waypoints along a 0.5-3 rad move, up to 0.3 rad off it.

    Limits 0.5-3 rad/s and 1-10 rad/s^2 per joint, scaled by 1, 0.3 or 0.1, like robot
    limits under MoveIt's velocity and acceleration scaling.
    """
    n = draw(st.integers(2, 9))
    start = draw(hnp.arrays(np.float64, n, elements=st.floats(-2.0, 2.0)))
    move = unit_direction(draw, n) * draw(st.floats(0.5, 3.0))
    count = draw(st.integers(2, 6))
    waypoints = start + np.linspace(0.0, 1.0, count)[:, None] * move
    waypoints[1:-1] += draw(hnp.arrays(np.float64, (count - 2, n), elements=st.floats(-0.3, 0.3)))
    scaling = draw(st.sampled_from([1.0, 0.3, 0.1]))
    velocity = draw(hnp.arrays(np.float64, n, elements=st.floats(0.5, 3.0))) * scaling
    acceleration = draw(hnp.arrays(np.float64, n, elements=st.floats(1.0, 10.0))) * scaling
    return waypoints, velocity, acceleration


# Ours / TOPP-RA's, measured on 800 random draws of smooth_paths: median 1.0025, 95th percentile
# 1.009, largest 1.040, smallest 0.964 (and on 1300 similar numpy-drawn paths: largest 1.047).
# Not quite the same path: ours rounds corners within 0.44 of a step, the spline overshoots them
# (ours can be faster); ours is smoothed (+0.25 %, 1-10 ms) and then slowed uniformly by the
# largest excess of its quintics over a limit (0.5 % typically, 1.5 % at worst seen), so the
# whole motion pays for its worst corner. 6 % leaves room above the worst seen.
TOPPRA_RATIO = 1.06


@settings(deadline=None, database=None, max_examples=40)
@seed(20261125)
@given(smooth_paths())
def test_duration_is_within_six_percent_of_toppra_on_smooth_paths(case: Case) -> None:
    waypoints, max_velocity, max_acceleration = case
    trajectory = time_parameterize(names(waypoints.shape[1]), waypoints, max_velocity, max_acceleration)
    assert_valid(trajectory, waypoints, max_velocity, max_acceleration)
    assert trajectory.duration_s <= TOPPRA_RATIO * toppra_duration(waypoints, max_velocity, max_acceleration)
