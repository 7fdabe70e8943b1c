"""Rotations in ROS's convention: [x, y, z, w] quaternions with w >= 0, rpy about the fixed x, y, z axes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from moveplan.commander.ros.tf import transformations
from moveplan.core import rotations
from moveplan.core.rotations import (
    matrix_from_quaternion,
    matrix_from_rotation_vector,
    matrix_from_rpy,
    quaternion_from_matrix,
    quaternions_xyzw,
    rotation_angle,
    rotation_vector,
    rpy_from_matrix,
)


def test_rpy_is_about_the_fixed_axes_yaw_last_as_urdf_and_tf() -> None:
    # R = Rz(yaw) Ry(pitch) Rx(roll): roll first, about the fixed x axis (x stays, y goes to z), then yaw
    # about the fixed z axis (x goes to y; z stays).
    rotation = matrix_from_rpy(math.pi / 2, 0.0, math.pi / 2)
    np.testing.assert_allclose(rotation @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(rotation @ [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(rotation, transformations.euler_matrix(math.pi / 2, 0.0, math.pi / 2)[:3, :3],
                               atol=1e-15)


def test_a_known_rpy_gives_the_known_matrix_and_ros_quaternion() -> None:
    # Roll then yaw a quarter turn each: x goes to y, y to z, z to x, a third of a turn about (1, 1, 1).
    rotation = matrix_from_rpy(math.pi / 2, 0.0, math.pi / 2)
    np.testing.assert_allclose(rotation, [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], atol=1e-15)
    np.testing.assert_allclose(quaternion_from_matrix(rotation), (0.5, 0.5, 0.5, 0.5), atol=1e-15)
    np.testing.assert_allclose(rotation_angle(rotation), 2 * math.pi / 3, atol=1e-15)


def test_a_known_rotation_has_the_ros_quaternion_with_w_first_positive() -> None:
    half_turn_about_z = matrix_from_rpy(0.0, 0.0, math.pi)
    np.testing.assert_allclose(quaternion_from_matrix(half_turn_about_z), (0.0, 0.0, 1.0, 0.0), atol=1e-15)
    minus_quarter = matrix_from_quaternion([0.0, 0.0, -math.sin(math.pi / 4), -math.cos(math.pi / 4)])
    x, y, z, w = quaternion_from_matrix(minus_quarter)
    assert w > 0 and z > 0  # -q is the same rotation; the one handed out has w >= 0


def test_round_trips_and_the_vectorised_path_agree() -> None:
    rng = np.random.default_rng(7)
    transforms = np.tile(np.eye(4), (50, 1, 1))
    for k in range(50):
        roll, pitch, yaw = rng.uniform(-3.0, 3.0), rng.uniform(-1.5, 1.5), rng.uniform(-3.0, 3.0)
        rotation = matrix_from_rpy(roll, pitch, yaw)
        np.testing.assert_allclose(rpy_from_matrix(rotation), (roll, pitch, yaw), atol=1e-12)
        np.testing.assert_allclose(matrix_from_quaternion(quaternion_from_matrix(rotation)), rotation, atol=1e-12)
        np.testing.assert_allclose(matrix_from_rotation_vector(rotation_vector(rotation)), rotation, atol=1e-12)
        assert rotation_angle(rotation) == pytest.approx(float(np.linalg.norm(rotation_vector(rotation))), abs=1e-7)
        transforms[k, :3, :3] = rotation
    one_by_one = np.array([quaternion_from_matrix(t[:3, :3]) for t in transforms])
    np.testing.assert_allclose(quaternions_xyzw(transforms), one_by_one, atol=1e-12)


@given(st.lists(st.tuples(*[st.floats(-1.0, 1.0)] * 4, st.sampled_from(["any", "axis", "half turn"])),
                min_size=1, max_size=80))
@settings(max_examples=200, deadline=None)
def test_a_few_transforms_get_the_same_quaternions_to_the_bit_as_many(
    quaternions: list[tuple[float, float, float, float, str]],
) -> None:
    """A plan's static frames and markers are a few transforms; its /tf samples many. Both ways, the same bits."""
    transforms = np.tile(np.eye(4), (len(quaternions), 1, 1))
    for k, (x, y, z, w, kind) in enumerate(quaternions):
        q = np.array([x, y, z, w])
        if kind == "axis":  # a rotation about one axis, or none: the branches' ties
            q[np.argsort(np.abs(q))[:2]] = 0.0
        elif kind == "half turn":  # w = 0: the trace is -1, every diagonal branch in play
            q[3] = 0.0
        if np.linalg.norm(q) < 1e-3:
            q = np.array([0.0, 0.0, 0.0, 1.0])
        transforms[k, :3, :3] = matrix_from_quaternion(q / np.linalg.norm(q))
    few = [quaternions_xyzw(t[None]) for t in transforms]  # one at a time: plain floats
    many = quaternions_xyzw(np.concatenate([transforms] * (rotations._FEW // len(transforms) + 1)))  # numpy's way
    assert len(many) > rotations._FEW
    assert np.concatenate(few).tobytes() == many[: len(transforms)].tobytes()
    assert quaternions_xyzw(transforms).tobytes() == many[: len(transforms)].tobytes()


def test_a_quaternion_of_any_length_is_normalised_and_a_zero_one_is_no_rotation() -> None:
    np.testing.assert_allclose(matrix_from_quaternion([0.0, 0.0, 0.0, 5.0]), np.eye(3))
    with pytest.raises(ValueError, match="zero norm"):
        matrix_from_quaternion([0.0, 0.0, 0.0, 0.0])
