"""TOPP-RA passes: exact on straight lines, within the limits on curves, converging as the grid refines."""

from __future__ import annotations

import numpy as np
import pytest

from moveplan.core.timing._topp import SpeedProfile, fastest_speeds


def straight_line(length: float, direction: list[float]) -> tuple[np.ndarray, ...]:
    grid = np.array([0.0, length])
    first = np.tile(direction, (3, 1))
    return grid, first, np.zeros_like(first), np.array([True])


def arc(radius: float, count: int) -> tuple[np.ndarray, ...]:
    """A quarter circle, q(s) = radius (cos(s / radius), sin(s / radius)), on a uniform grid."""
    s = np.linspace(0.0, np.pi / 2 * radius, 2 * count + 1)  # grid points and middles
    angle = s / radius
    first = np.stack((-np.sin(angle), np.cos(angle)), axis=1)
    second = -np.stack((np.cos(angle), np.sin(angle)), axis=1) / radius
    return s[::2], first, second, np.zeros(count, dtype=bool)


def duration(profile: SpeedProfile) -> float:
    speed = np.sqrt(profile.squared_speeds)
    return float(np.sum(2 * np.diff(profile.s) / (speed[:-1] + speed[1:])))


def test_straight_line_gives_the_bang_bang_triangle() -> None:
    profile = fastest_speeds(*straight_line(1.0, [1.0]), np.array([10.0]), np.array([1.0]))
    np.testing.assert_allclose(profile.s, [0.0, 0.5, 1.0])
    np.testing.assert_allclose(profile.squared_speeds, [0.0, 1.0, 0.0])


def test_straight_line_with_a_velocity_limit_gives_the_trapezoid() -> None:
    # Joint 1 moves twice as far as joint 0 along the path: it sets both limits.
    direction = np.array([1.0, 2.0]) / np.sqrt(5.0)
    profile = fastest_speeds(*straight_line(1.0, list(direction)), np.array([0.5, 0.5]), np.array([1.0, 1.0]))
    cruise = (0.5 / direction[1]) ** 2  # path speed^2 at which joint 1 reaches 0.5 rad/s
    ramp = 2 * 1.0 / direction[1]  # d(speed^2)/ds at full acceleration
    np.testing.assert_allclose(profile.s, [0.0, cruise / ramp, 1.0 - cruise / ramp, 1.0])
    np.testing.assert_allclose(profile.squared_speeds, [0.0, cruise, cruise, 0.0])


@pytest.mark.parametrize("radius", [0.05, 1.0])
def test_curve_keeps_the_limits_at_the_ends_and_middle_of_each_interval(radius: float) -> None:
    grid, first, second, straight = arc(radius, 60)
    max_v, max_a = np.array([1.0, 0.8]), np.array([2.0, 3.0])
    profile = fastest_speeds(grid, first, second, straight, max_v, max_a)
    x = profile.squared_speeds
    u = np.diff(x) / (2 * np.diff(grid))
    for offset, rows in ((0.0, slice(0, -1, 2)), (0.5, slice(1, None, 2)), (1.0, slice(2, None, 2))):
        squared = x[:-1] + 2 * offset * np.diff(grid) * u
        accelerations = second[rows] * squared[:, None] + first[rows] * u[:, None]
        assert np.all(np.abs(accelerations) <= max_a * (1 + 1e-9))
    assert np.all(np.abs(first[::2]) * np.sqrt(x)[:, None] <= max_v * (1 + 1e-9))
    assert x[0] == 0.0 and x[-1] == 0.0 and np.all(x[1:-1] > 0.0)


def test_curve_duration_converges_as_the_grid_refines() -> None:
    max_v, max_a = np.array([1.0, 0.8]), np.array([2.0, 3.0])
    coarse, fine = (duration(fastest_speeds(*arc(0.3, count), max_v, max_a)) for count in (24, 384))
    assert fine <= coarse <= 1.01 * fine


def test_a_tight_turn_is_taken_slowly() -> None:
    # On a circle of radius r the joint accelerations (x / r, u) in a rotated frame have a
    # norm of at most sqrt(2) a, so x <= sqrt(2) a r; at u = 0 it can reach a r.
    max_v, max_a = np.array([10.0, 10.0]), np.array([1.0, 1.0])
    profile = fastest_speeds(*arc(0.01, 60), max_v, max_a)
    assert 0.01 <= np.max(profile.squared_speeds) <= np.sqrt(2) * 0.01
