"""Rounded corners: twice differentiable, on the segments away from corners, within the stated bound."""

from __future__ import annotations

import numpy as np
import pytest

from moveplan.core.timing._blends import BlendedPath, blended_path


def polyline_distance(points: np.ndarray, waypoints: np.ndarray) -> np.ndarray:
    a, b = waypoints[:-1], waypoints[1:]
    t = np.clip(np.einsum("psn,sn->ps", points[:, None] - a, b - a) / np.sum((b - a) ** 2, axis=1), 0, 1)
    return np.min(np.linalg.norm(points[:, None] - (a + t[..., None] * (b - a)), axis=2), axis=1)


@pytest.fixture()
def zigzag() -> tuple[np.ndarray, BlendedPath]:
    waypoints = np.array([[0.0, 0.0, 0.0], [1.0, 0.2, 0.0], [1.2, 1.5, -0.3], [0.1, 1.0, 0.4]])
    return waypoints, blended_path(waypoints, 0.1, 0.5)


def test_path_runs_from_first_to_last_waypoint(zigzag: tuple[np.ndarray, BlendedPath]) -> None:
    waypoints, path = zigzag
    positions, _, _ = path(np.array([0.0, path.length]))
    np.testing.assert_allclose(positions, waypoints[[0, -1]], atol=1e-12)


def test_pieces_join_with_equal_position_direction_and_curvature(zigzag: tuple[np.ndarray, BlendedPath]) -> None:
    _, path = zigzag
    joints = path.breaks[1:-1]
    before = path(joints - 1e-7)
    after = path(joints + 1e-7)
    for left, right, tolerance in zip(before, after, (1e-6, 1e-5, 1e-4), strict=True):
        np.testing.assert_allclose(left, right, atol=tolerance)


def test_derivatives_are_those_of_the_full_evaluation(zigzag: tuple[np.ndarray, BlendedPath]) -> None:
    _, path = zigzag
    s = np.linspace(-0.1, path.length + 0.1, 301)
    _, first, second = path(s)
    derivative, curvature = path.derivatives(s)
    np.testing.assert_allclose(derivative, first, rtol=0, atol=1e-12)
    np.testing.assert_allclose(curvature, second, rtol=0, atol=1e-9)


def test_corners_are_blends_and_the_rest_is_straight(zigzag: tuple[np.ndarray, BlendedPath]) -> None:
    waypoints, path = zigzag
    np.testing.assert_array_equal(path.blend, [False, True, False, True, False])
    s = np.linspace(0.0, path.length, 2001)
    positions, first, second = path(s)
    piece = np.searchsorted(path.breaks, s, side="right") - 1
    straight = ~path.blend[np.minimum(piece, len(path.blend) - 1)]
    assert np.all(polyline_distance(positions[straight], waypoints) < 1e-12)
    np.testing.assert_allclose(np.linalg.norm(first[straight], axis=1), 1.0, atol=1e-12)
    assert np.all(second[straight] == 0.0)


def test_blend_strays_at_most_three_sixteenths_of_its_half_length_times_the_turn() -> None:
    for angle in np.linspace(0.1, np.pi, 12):
        waypoints = np.array([[-1.0, 0.0], [0.0, 0.0], [np.cos(angle), np.sin(angle)]])
        path = blended_path(waypoints, 0.2, 0.5)
        h = (path.breaks[2] - path.breaks[1]) / 2
        bound = 3 / 16 * h * np.linalg.norm(waypoints[2] - 2 * waypoints[1] + waypoints[0])
        positions, _, _ = path(np.linspace(0.0, path.length, 4001))
        assert np.max(polyline_distance(positions, waypoints)) <= bound + 1e-12
        middle, _, _ = path(np.array([path.breaks[1] + h]))  # 3/16 h (d_out - d_in) inside the corner
        np.testing.assert_allclose(polyline_distance(middle, waypoints), bound * np.cos(angle / 2), rtol=1e-9)


def test_blend_takes_a_fraction_of_the_shorter_step_from_both_segments() -> None:
    waypoints = np.array([[0.0, 0.0], [2.0, 1.0], [2.0, 3.0]])
    path = blended_path(waypoints, 0.3, 0.5)
    # Both segments move a joint by 2 rad: 7 steps of at most 0.3 rad, sqrt(5) / 7 and 2 / 7 long.
    np.testing.assert_allclose(path.breaks[2] - path.breaks[1], 2 * 0.5 * 2 / 7)


def test_blend_takes_at_most_half_of_a_short_segment() -> None:
    waypoints = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.02], [2.0, 0.02]])
    path = blended_path(waypoints, 0.5, 0.9)
    np.testing.assert_allclose(path.breaks[2] - path.breaks[1], 0.02)
    np.testing.assert_array_equal(path.blend, [False, True, True, False])


def test_reversal_stays_on_the_segment() -> None:
    waypoints = np.array([[0.0, 0.0], [1.0, 1.0], [0.5, 0.5]])
    path = blended_path(waypoints, 0.1, 0.5)
    positions, _, _ = path(np.linspace(0.0, path.length, 2001))
    np.testing.assert_allclose(positions[:, 0], positions[:, 1], atol=1e-12)
    assert np.max(positions) <= 1.0 + 1e-12
    _, turning, _ = path(np.array([(path.breaks[1] + path.breaks[2]) / 2]))
    np.testing.assert_allclose(turning, 0.0, atol=1e-12)  # it turns round in the blend's middle


def test_repeated_waypoints_are_dropped_and_one_point_is_refused() -> None:
    path = blended_path(np.array([[0.0], [0.0], [1.0], [1.0]]), 0.1, 0.5)
    assert len(path.blend) == 1 and path.length == 1.0
    with pytest.raises(ValueError, match="two distinct waypoints"):
        blended_path(np.zeros((3, 2)), 0.1, 0.5)
