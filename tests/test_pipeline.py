"""The plan pipeline's guarantees that no single command shows: the last-resort timing stays on the path."""

from __future__ import annotations

import numpy as np
from conftest import dense_peaks

from moveplan.core.timing import rest_to_rest
from moveplan.core.trajectory import sample


def test_rest_to_rest_timing_keeps_every_joint_on_the_checked_segments() -> None:
    waypoints = np.array([[0.0, 0.0, 0.0], [1.0, 0.5, 0.0], [1.0, 1.0, 1.0], [0.2, 1.0, 1.0]])
    limits_v, limits_a = np.array([1.0, 1.0, 1.0]), np.array([2.0, 2.0, 2.0])
    trajectory = rest_to_rest(("a", "b", "c"), waypoints, limits_v, limits_a)
    positions, _, _ = sample(trajectory, np.linspace(0.0, trajectory.duration_s, 5000))

    def distance_to_path(q: np.ndarray) -> float:
        best = np.inf
        for a, b in zip(waypoints[:-1], waypoints[1:], strict=True):
            s = np.clip((q - a) @ (b - a) / ((b - a) @ (b - a)), 0.0, 1.0)
            best = min(best, float(np.linalg.norm(q - (a + s * (b - a)))))
        return best

    assert max(distance_to_path(q) for q in positions) < 1e-12
    peak_v, peak_a = dense_peaks(trajectory)
    assert np.all(peak_v <= limits_v) and np.all(peak_a <= limits_a)
    np.testing.assert_allclose(trajectory.positions[[0, -1]], waypoints[[0, -1]], atol=1e-12)
    assert np.all(np.diff(trajectory.times_s) > 0)
