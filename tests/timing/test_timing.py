"""Timing: rest to rest, within the limits as the controller interpolates, near time-optimal, near the polyline."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import dense_peaks

from moveplan.core.timing.parameterize import time_parameterize
from moveplan.core.trajectory import peak_rates, sample
from moveplan.core.types import JointTrajectory

NAMES = tuple(f"j{i}" for i in range(6))
V_MAX = np.array([2.094, 2.094, 3.142, 3.142, 3.142, 3.142])
A_MAX = np.full(6, 5.0)


def polyline_distance(trajectory: JointTrajectory, waypoints: np.ndarray, per_segment: int = 64) -> float:
    """Largest distance [rad] of the interpolated trajectory, sampled densely, from the waypoints' polyline."""
    knots = trajectory.times_s
    fractions = np.linspace(0.0, 1.0, per_segment + 1)
    times = np.unique((knots[:-1, None] + np.diff(knots)[:, None] * fractions).ravel())
    positions, _, _ = sample(trajectory, times)
    a, b = waypoints[:-1], waypoints[1:]
    t = np.clip(np.einsum("psn,sn->ps", positions[:, None] - a, b - a) / np.sum((b - a) ** 2, axis=1), 0, 1)
    return float(np.max(np.min(np.linalg.norm(positions[:, None] - (a + t[..., None] * (b - a)), axis=2), axis=1)))


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("scaling", [1.0, 0.1])
def test_random_paths_stay_within_limits_and_end_at_rest(seed: int, scaling: float) -> None:
    waypoints = np.random.default_rng(seed).uniform(-2, 2, (3 + seed % 3, 6))
    trajectory = time_parameterize(NAMES, waypoints, V_MAX * scaling, A_MAX * scaling)
    peak_v, peak_a = dense_peaks(trajectory)
    assert np.all(peak_v <= V_MAX * scaling) and np.all(peak_a <= A_MAX * scaling)
    np.testing.assert_array_equal(trajectory.positions[[0, -1]], waypoints[[0, -1]])
    assert not trajectory.velocities[[0, -1]].any() and not trajectory.accelerations[[0, -1]].any()
    assert trajectory.times_s[0] == 0.0 and np.all(np.diff(trajectory.times_s) > 0)
    np.testing.assert_array_equal(trajectory.times_s, np.round(trajectory.times_s * 1e9) / 1e9)


def test_single_joint_move_takes_near_the_bang_bang_time() -> None:
    # 1 rad at 1 rad/s, 1 rad/s^2: the optimum is 2 s with an instant switch from full
    # acceleration to full braking; ramping the switch and both ends over 5 ms adds 5 ms.
    waypoints = np.array([[0.0], [1.0]])
    trajectory = time_parameterize(("j",), waypoints, np.array([1.0]), np.array([1.0]))
    assert 2.0 <= trajectory.duration_s <= 2.0 * 1.0025 + 1e-4


def test_straight_move_with_cruise_takes_the_trapezoid_time() -> None:
    # The third joint leads: 3 rad at 3.142 rad/s, 5 rad/s^2 ramps up for 0.628 s, cruises, ramps down.
    waypoints = np.array([np.zeros(6), [1.0, 0.5, 3.0, 0.0, -1.0, 0.2]])
    trajectory = time_parameterize(NAMES, waypoints, V_MAX, A_MAX)
    optimum = 3.0 / 3.142 + 3.142 / 5.0
    assert optimum <= trajectory.duration_s <= optimum * 1.0025 + 1e-4
    assert polyline_distance(trajectory, waypoints) < 1e-9


@pytest.mark.parametrize("max_step", [0.05, 0.01])
def test_corners_stay_within_the_blend_bound_of_the_polyline(max_step: float) -> None:
    # A blend takes at most 0.44 of a step, at most max_step in every joint: h <= 0.44 max_step
    # sqrt(6) of arc, and strays by at most 3/16 h |d_out - d_in| <= 3/8 h.
    waypoints = np.random.default_rng(7).uniform(-2, 2, (6, 6))
    trajectory = time_parameterize(NAMES, waypoints, V_MAX, A_MAX, max_step=max_step)
    deviation = polyline_distance(trajectory, waypoints)
    assert 0.0 < deviation <= 3 / 8 * 0.44 * max_step * np.sqrt(6)


def test_smaller_max_step_keeps_closer_to_the_polyline() -> None:
    waypoints = np.random.default_rng(3).uniform(-2, 2, (5, 6))
    coarse, fine = (time_parameterize(NAMES, waypoints, V_MAX, A_MAX, max_step=step) for step in (0.05, 0.01))
    assert polyline_distance(fine, waypoints) < polyline_distance(coarse, waypoints) / 4
    assert fine.duration_s > coarse.duration_s


def test_reversal_goes_back_along_the_segment_within_limits() -> None:
    waypoints = np.array([[0.0, 0.0], [1.0, 0.5], [0.2, 0.1]])
    limits_v, limits_a = np.array([1.0, 1.0]), np.array([2.0, 2.0])
    trajectory = time_parameterize(("a", "b"), waypoints, limits_v, limits_a)
    peak_v, peak_a = peak_rates(trajectory)
    assert np.all(peak_v <= limits_v) and np.all(peak_a <= limits_a)
    assert polyline_distance(trajectory, waypoints) < 1e-9


@pytest.mark.parametrize("size", [1e-10, 1e-6, 1e-3])
def test_tiny_moves_reach_the_goal_within_limits(size: float) -> None:
    waypoints = np.array([np.zeros(6), np.full(6, size), np.full(6, size) * [1, 2, 1, 2, 1, 2]])
    trajectory = time_parameterize(NAMES, waypoints, V_MAX, A_MAX)
    peak_v, peak_a = peak_rates(trajectory)
    assert np.all(peak_v <= V_MAX) and np.all(peak_a <= A_MAX)
    np.testing.assert_array_equal(trajectory.positions[-1], waypoints[-1])


def test_repeated_and_collinear_waypoints_change_nothing() -> None:
    waypoints = np.array([np.zeros(6), np.full(6, 0.5), np.full(6, 1.0)])
    plain = time_parameterize(NAMES, waypoints[[0, 2]], V_MAX, A_MAX)
    padded = time_parameterize(NAMES, waypoints[[0, 0, 1, 1, 2, 2]], V_MAX, A_MAX)
    np.testing.assert_allclose(padded.duration_s, plain.duration_s, rtol=1e-9)


def test_same_input_gives_the_same_trajectory() -> None:
    waypoints = np.random.default_rng(11).uniform(-2, 2, (5, 6))
    first, second = (time_parameterize(NAMES, waypoints, V_MAX, A_MAX) for _ in range(2))
    for field in ("times_s", "positions", "velocities", "accelerations"):
        np.testing.assert_array_equal(getattr(first, field), getattr(second, field))


def test_path_of_one_point_is_a_single_point_trajectory() -> None:
    trajectory = time_parameterize(NAMES, np.zeros((2, 6)), V_MAX, A_MAX)
    assert len(trajectory.times_s) == 1 and trajectory.duration_s == 0.0


@pytest.mark.parametrize("seed", range(3))
def test_exact_peaks_bound_dense_sampling_and_are_reached(seed: int) -> None:
    waypoints = np.random.default_rng(seed).uniform(-2, 2, (4, 6))
    trajectory = time_parameterize(NAMES, waypoints, V_MAX, A_MAX)
    exact_v, exact_a = peak_rates(trajectory)
    dense_v, dense_a = dense_peaks(trajectory, per_segment=400)
    assert np.all(exact_v >= dense_v - 1e-12) and np.all(exact_a >= dense_a - 1e-12)
    np.testing.assert_allclose(exact_v, dense_v, rtol=1e-4)
    np.testing.assert_allclose(exact_a, dense_a, rtol=1e-3)


@pytest.mark.parametrize("seed", range(3))
def test_some_joint_reaches_its_limit(seed: int) -> None:
    # Time-optimal up to the final uniform slow-down: some limit is met, not just respected.
    waypoints = np.random.default_rng(seed).uniform(-2, 2, (4, 6))
    trajectory = time_parameterize(NAMES, waypoints, V_MAX, A_MAX)
    peak_v, peak_a = peak_rates(trajectory)
    assert max(np.max(peak_v / V_MAX), np.max(peak_a / A_MAX)) > 0.999
