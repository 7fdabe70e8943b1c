"""JTC sampling rules: spline degree per segment, hold, blend from the point before, wraparound."""

import numpy as np
import pytest

from moveplan.core.trajectory import PointBefore, peak_rates, sample, shortest_angular_distance
from moveplan.core.types import JointTrajectory

EPS = 1e-8


def one_joint(times, positions, velocities=None, accelerations=None):
    zeros = np.zeros(len(times))
    return JointTrajectory(
        ("joint1",), times, np.c_[positions],
        np.c_[zeros if velocities is None else velocities],
        np.c_[zeros if accelerations is None else accelerations],
    )


def test_positions_only_blend_from_point_before_is_linear_then_holds_last_point():
    # A1 (test_trajectory.cpp sample_trajectory_positions): from 0, points 1, 2, 3 at 1, 2, 3 s.
    trajectory = one_joint([1.0, 2.0, 3.0], [1.0, 2.0, 3.0])
    pos, vel, acc = sample(trajectory, [0.5, 1.5, 2.5, 3.0, 3.125], has_velocities=False,
                           has_accelerations=False, point_before=PointBefore([0.0]))
    np.testing.assert_allclose(pos[:, 0], [0.5, 1.5, 2.5, 3.0, 3.0], atol=EPS)
    np.testing.assert_allclose(vel[:3, 0], [1.0, 1.0, 1.0], atol=EPS)
    np.testing.assert_allclose(acc[:, 0], 0.0, atol=EPS)


def test_positions_and_velocities_give_cubic_hermite_segment():
    # A2 (interpolation_pos_vel): x^3 - 2x between (t=1, p=0, v=-2) and (t=3, p=4, v=10).
    trajectory = one_joint([1.0, 3.0], [0.0, 4.0], velocities=[-2.0, 10.0])
    pos, vel, acc = sample(trajectory, [1.0 + np.sqrt(2.0), 3.0 - 1e-12], has_accelerations=False)
    np.testing.assert_allclose(pos[:, 0], [0.0, 4.0], atol=EPS)
    np.testing.assert_allclose(vel[:, 0], [4.0, 10.0], atol=EPS)
    np.testing.assert_allclose(acc[:, 0], [6.0 * np.sqrt(2.0), 12.0], atol=1e-6)


def test_all_three_fields_give_quintic_segment():
    # A3 (interpolation_pos_vel_accel): x(x-1)(x-2)(x-3)(x-4) between t=1 and t=3.
    trajectory = one_joint([1.0, 3.0], [0.0, 0.0], velocities=[24.0, 4.0],
                           accelerations=[-100.0, 0.0])
    pos, vel, acc = sample(trajectory, [2.0])
    np.testing.assert_allclose([pos[0, 0], vel[0, 0], acc[0, 0]], [0.0, -6.0, 10.0], atol=EPS)


def test_segment_degree_follows_fields_present_at_both_ends():
    trajectory = one_joint([1.0], [1.0], velocities=[0.0])
    linear = sample(trajectory, [0.5], point_before=PointBefore([0.0]))
    cubic = sample(trajectory, [0.25], point_before=PointBefore([0.0], velocities=[0.0]))
    np.testing.assert_allclose(linear[0][0, 0], 0.5, atol=EPS)
    np.testing.assert_allclose(linear[1][0, 0], 1.0, atol=EPS)
    # Hermite with zero end velocities: 3 s^2 - 2 s^3 at s = 0.25.
    np.testing.assert_allclose(cubic[0][0, 0], 3 * 0.25**2 - 2 * 0.25**3, atol=EPS)


def test_first_point_at_time_zero_jumps_without_blend():
    trajectory = one_joint([0.0, 1.0], [4.0, 5.0])
    pos, _, _ = sample(trajectory, [0.0], point_before=PointBefore([1.1], velocities=[0.0]))
    np.testing.assert_allclose(pos[0, 0], 4.0, atol=EPS)


def test_after_last_point_holds_it_with_its_own_velocity():
    trajectory = one_joint([0.0, 1.0], [0.0, 1.0], velocities=[0.0, 0.5])
    pos, vel, acc = sample(trajectory, [1.0, 5.0], has_accelerations=False)
    np.testing.assert_allclose(pos[:, 0], [1.0, 1.0], atol=EPS)
    np.testing.assert_allclose(vel[:, 0], [0.5, 0.5], atol=EPS)
    np.testing.assert_allclose(acc[:, 0], [0.0, 0.0], atol=EPS)


def test_without_point_before_times_before_first_point_give_first_point():
    trajectory = one_joint([1.0, 2.0], [1.0, 2.0])
    pos, vel, _ = sample(trajectory, [0.0])
    np.testing.assert_allclose([pos[0, 0], vel[0, 0]], [1.0, 0.0], atol=EPS)


def test_single_point_trajectory_holds_its_point():
    pos, vel, _ = sample(one_joint([0.0], [2.0]), [0.0, 3.0])
    np.testing.assert_allclose(pos[:, 0], [2.0, 2.0], atol=EPS)
    np.testing.assert_allclose(vel[:, 0], [0.0, 0.0], atol=EPS)


def test_point_before_of_continuous_joint_moves_whole_turns_towards_first_point():
    # A16 setup: continuous joint at 3.1, first point 6.6 at 0.25 s.
    trajectory = one_joint([0.25], [6.6])
    before = PointBefore([3.1])
    wrapped, _, _ = sample(trajectory, [0.0], point_before=before, continuous=[True])
    plain, _, _ = sample(trajectory, [0.0], point_before=before, continuous=[False])
    np.testing.assert_allclose(wrapped[0, 0], 3.1 + 2 * np.pi, atol=EPS)
    np.testing.assert_allclose(plain[0, 0], 3.1, atol=EPS)


def test_point_before_half_a_turn_away_moves_towards_the_side_of_the_first_point():
    trajectory = one_joint([1.0], [np.pi])
    pos, _, _ = sample(trajectory, [0.0], point_before=PointBefore([2 * np.pi]), continuous=[True])
    np.testing.assert_allclose(pos[0, 0], 2 * np.pi, atol=EPS)


@pytest.mark.parametrize(("start", "end", "expected"), [
    (3.1, 6.6, 6.6 - 3.1 - 2 * np.pi), (0.0, np.pi, np.pi), (0.0, -np.pi, np.pi),
    (-3.0, 3.0, 6.0 - 2 * np.pi),
])
def test_shortest_angular_distance_lies_in_half_open_interval(start, end, expected):
    np.testing.assert_allclose(shortest_angular_distance(start, end), expected, atol=1e-12)


def test_peak_rates_of_linear_quintic_segment():
    trajectory = one_joint([0.0, 2.0], [0.0, 2.0], velocities=[1.0, 1.0])
    peak_v, peak_a = peak_rates(trajectory)
    np.testing.assert_allclose(peak_v, [1.0], atol=EPS)
    np.testing.assert_allclose(peak_a, [0.0], atol=EPS)


def test_peak_rates_of_rest_to_rest_quintic_are_inside_the_segment():
    # 10t^3 - 15t^4 + 6t^5: velocity peaks at t = 1/2 (15/8), acceleration at (3 -+ sqrt 3) / 6 (10/sqrt 3).
    trajectory = one_joint([0.0, 1.0, 2.0], [0.0, 1.0, 1.0])
    peak_v, peak_a = peak_rates(trajectory)
    np.testing.assert_allclose(peak_v, [15 / 8], rtol=1e-12)
    np.testing.assert_allclose(peak_a, [10 / np.sqrt(3)], rtol=1e-12)
