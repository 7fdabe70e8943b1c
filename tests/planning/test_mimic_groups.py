"""Groups with mimic joints (every gripper): planned as MoveIt plans them, the mimic joint following its leader.

MoveIt's rule (moveit_core RobotState::updateMimicJoints, JointModelGroup::getActiveJointModels):
a mimic joint is a variable of its group but not an active joint; wherever its leader is set,
it is set to multiplier * leader + offset. The panda's `hand` group (panda_finger_joint2 mimics
panda_finger_joint1) is the case MoveIt's own tutorials run.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import Cli
from rosbags.highlevel import AnyReader

from moveplan.core.collision import CollisionChecker
from moveplan.core.collision import _certify as certify
from moveplan.core.config import load_robot_config
from moveplan.core.model import Robot


@pytest.fixture(scope="module")
def panda():  # type: ignore[no-untyped-def]
    return load_robot_config("panda")


def test_a_mimic_joint_is_a_variable_of_its_group_but_not_planned(panda) -> None:  # type: ignore[no-untyped-def]
    hand = Robot(panda, "hand")
    assert hand.variable_names == ("panda_finger_joint1", "panda_finger_joint2")
    assert hand.joint_names == ("panda_finger_joint1",)
    q = hand.configuration([0.02])
    both = [q[hand.model.idx_qs[hand.model.getJointId(j)]] for j in hand.variable_names]
    assert both == [0.02, 0.02]


def test_a_leader_moves_its_followers_in_the_whole_arm_group(panda) -> None:  # type: ignore[no-untyped-def]
    arm_hand = Robot(panda, "panda_arm_hand")
    assert arm_hand.dof == 8 and "panda_finger_joint2" not in arm_hand.joint_names
    values = np.zeros(8)
    values[7] = 0.03
    q = arm_hand.configuration(values)
    left, right = (arm_hand.frame_pose(q, link)[:3, 3] for link in ("panda_leftfinger", "panda_rightfinger"))
    assert np.linalg.norm(left - right) == pytest.approx(0.06, abs=1e-9)  # each finger 3 cm from the middle


def test_certified_motion_of_a_leader_counts_what_its_followers_move(panda) -> None:  # type: ignore[no-untyped-def]
    # Two prismatic fingers: a point moves as far as its finger, and the follower moves as far as the leader.
    hand = Robot(panda, "hand")
    geometry = CollisionChecker(hand, (), "test").robot_geometry
    assert certify.reach(hand, geometry).tolist() == [2.0]


def test_the_cli_plans_a_gripper_to_its_named_state(cli: Cli, tmp_path) -> None:  # type: ignore[no-untyped-def]
    out = tmp_path / "close.mcap"
    result = cli("plan", "--robot", "panda", "--group", "hand", "--start-named", "open", "--named", "close", "-o", out)
    assert result.exit_code == 0, result.stderr
    with AnyReader([out]) as reader:
        tf = [c for c in reader.connections if c.topic == "/tf"]
        fingers = {t.child_frame_id: t.transform.translation.y for c, _, raw in reader.messages(connections=tf)
                   for t in reader.deserialize(raw, c.msgtype).transforms if "finger" in t.child_frame_id}
    closed = pytest.approx(0.0, abs=1e-9)
    assert fingers == {"panda_leftfinger": closed, "panda_rightfinger": closed}
