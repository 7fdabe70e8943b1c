"""Collision checking: self and scene, pair names, batch answers agree with single checks."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from conftest import ROOT, TABLE_SCENE, Cli

from moveplan.core.collision.checker import CollisionChecker
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.errors import StartInCollision
from moveplan.core.model.robot import Robot
from moveplan.core.model.scene_file import load_scene
from moveplan.core.types import CollisionObject, Shape


@pytest.fixture(scope="module")
def checker(ur10e: Robot) -> CollisionChecker:
    return CollisionChecker(ur10e, load_scene(TABLE_SCENE, ur10e).objects)


def test_named_states_are_free_and_arm_in_table_names_the_pair(checker: CollisionChecker, ur10e: Robot) -> None:
    assert checker.colliding_pair(ur10e.configuration([0, -np.pi / 2, -np.pi / 2, 0, 0, 0])) is None
    assert checker.colliding_pair(ur10e.configuration([0, 0.3, 0, 0, 0, 0])) == ("upper_arm_link", "table")


def test_folded_elbow_collides_with_the_arm_itself(checker: CollisionChecker, ur10e: Robot) -> None:
    pair = checker.colliding_pair(ur10e.configuration([0, -np.pi / 2, 3.1, 0, 0, 0]))
    assert pair is not None and "table" not in pair


def test_batch_agrees_with_single_checks(checker: CollisionChecker, ur10e: Robot) -> None:
    values = np.random.default_rng(0).uniform(ur10e.lower / 2, ur10e.upper / 2, (300, 6))
    batch = checker.free_batch(ur10e.configurations(values))
    single = [not checker.in_collision(ur10e.configuration(v)) for v in values]
    assert batch.tolist() == single
    assert 0 < batch.sum() < len(batch)


def test_object_through_the_fixed_base_is_reported_once_at_load(ur10e: Robot) -> None:
    post = CollisionObject("post", Shape("cylinder", (0.05, 1.0)), np.eye(4))
    with pytest.raises(StartInCollision, match="post"):
        CollisionChecker(ur10e, (post,))


def test_a_hull_sinking_a_fraction_of_a_millimetre_into_a_box_collides_as_its_mesh_does() -> None:
    robot = Robot(load_robot_config(ROOT / "configs" / "panda"))
    scene = load_scene(ROOT / "tests" / "data" / "mbm" / "table_pick_scene0060.yaml", robot)
    # The hand 62 um inside the box Object4: coal, asked with no margin, called its hull free here.
    values = np.array([-0.03891427999411499, 1.1206303043892154, -1.7833035197227367, -1.278975843379327,
                       -0.11043559560381563, 2.8973192103494365, -0.19995617263938992])
    q = robot.configuration(values, robot.neutral())
    for geometry in ("convex", "exact"):
        checker = CollisionChecker(robot, scene.objects, scene.source, geometry=geometry, allowed=scene.allowed)
        assert not checker.free_batch(q[:, None])[0], geometry
        assert checker.colliding_pair(q) == ("panda_hand", "Object4")


@pytest.mark.parametrize("geometry", ["convex", "exact"])
def test_a_margin_finds_what_is_nearer_than_it_as_coals_distance_says(geometry: str) -> None:
    """free_batch(margin=m) is "every checked pair at least m apart": the broadphase widens its boxes by m."""
    robot = Robot(load_robot_config(ROOT / "configs" / "panda"))
    q = robot.configuration(np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.6, 0.8]), robot.neutral())
    hand = robot.frame_pose(q, "panda_hand")[:3, 3]
    place = np.eye(4)
    place[:3, 3] = hand + [0.0, 0.0, -0.15]  # a plate a few centimetres below the fingertips
    plate = CollisionObject("plate", Shape("box", (0.3, 0.3, 0.01)), place)
    checker = CollisionChecker(robot, (plate,), geometry=geometry)
    pin.computeDistances(robot.model, robot.data, checker.geometry, checker.data, q)
    distance = min(result.min_distance for result in checker.data.distanceResults)
    assert 0.001 < distance < 0.1
    assert checker.free_batch(q[:, None], margin=0.99 * distance)[0]
    assert not checker.free_batch(q[:, None], margin=1.01 * distance)[0]
    assert checker.free_batch(q[:, None])[0]  # the margin is the call's own


def test_a_robot_without_collision_geometry_plans(cli: Cli, tmp_path: Path) -> None:
    """A bare kinematic model (no <collision> anywhere) has nothing to collide: MoveIt plans it."""
    source = Path(__file__).parents[1] / "data" / "controller_substitutions" / "prefixed_arm"
    shutil.copytree(source, tmp_path / "arm")
    urdf = tmp_path / "arm" / "arm.urdf.xacro"
    urdf.write_text(re.sub(r"<collision>.*?</collision>", "", urdf.read_text(), flags=re.S))
    result = cli("plan", "--robot", tmp_path / "arm", "--joints", "left_shoulder_joint=0.5", "-o", tmp_path / "p.mcap")
    assert result.exit_code == 0, result.stderr
    assert (tmp_path / "p.mcap").stat().st_size > 0
