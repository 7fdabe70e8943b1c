"""TOPPRA timing: rest to rest, within the limits as the controller interpolates, near time-optimal."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import dense_peaks

from moveplan.core.timing import time_parameterize

NAMES = tuple(f"j{i}" for i in range(6))
V_MAX = np.array([2.094, 2.094, 3.142, 3.142, 3.142, 3.142])
A_MAX = np.full(6, 5.0)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("scaling", [1.0, 0.1])
def test_random_paths_stay_within_limits_and_end_at_rest(seed: int, scaling: float) -> None:
    waypoints = np.random.default_rng(seed).uniform(-2, 2, (3 + seed % 3, 6))
    trajectory = time_parameterize(NAMES, waypoints, V_MAX * scaling, A_MAX * scaling)
    peak_v, peak_a = dense_peaks(trajectory)
    assert np.all(peak_v <= V_MAX * scaling) and np.all(peak_a <= A_MAX * scaling)
    np.testing.assert_array_equal(trajectory.positions[[0, -1]], waypoints[[0, -1]])
    assert not trajectory.velocities[[0, -1]].any() and not trajectory.accelerations[[0, -1]].any()
    assert np.all(np.diff(trajectory.times_s) > 0)
    np.testing.assert_array_equal(trajectory.times_s, np.round(trajectory.times_s * 1e9) / 1e9)


def test_single_joint_move_takes_near_the_bang_bang_time() -> None:
    # 1 rad at 1 rad/s, 1 rad/s^2: the optimum is 2 s with an instant switch from full
    # acceleration to full braking; the smooth switch and soft stops cost at most ~17 %.
    waypoints = np.array([[0.0], [1.0]])
    trajectory = time_parameterize(("j",), waypoints, np.array([1.0]), np.array([1.0]))
    assert 2.0 <= trajectory.duration_s <= 2.35


def test_path_of_one_point_is_a_single_point_trajectory() -> None:
    trajectory = time_parameterize(NAMES, np.zeros((2, 6)), V_MAX, A_MAX)
    assert len(trajectory.times_s) == 1 and trajectory.duration_s == 0.0


@pytest.mark.parametrize("seed", range(3))
def test_exact_peaks_bound_dense_sampling_and_are_reached(seed: int) -> None:
    from moveplan.core.trajectory import peak_rates

    waypoints = np.random.default_rng(seed).uniform(-2, 2, (4, 6))
    trajectory = time_parameterize(NAMES, waypoints, V_MAX, A_MAX)
    exact_v, exact_a = peak_rates(trajectory)
    dense_v, dense_a = dense_peaks(trajectory, per_segment=400)
    assert np.all(exact_v >= dense_v - 1e-12) and np.all(exact_a >= dense_a - 1e-12)
    np.testing.assert_allclose(exact_v, dense_v, rtol=1e-4)
    np.testing.assert_allclose(exact_a, dense_a, rtol=1e-3)
