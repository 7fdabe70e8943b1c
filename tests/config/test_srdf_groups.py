"""SRDF groups as MoveIt builds them: virtual joints, <link> members, subgroups in any order, chains."""

from __future__ import annotations

import logging
import shutil
from pathlib import Path

import pytest
from conftest import REALWORLD, Cli

from moveplan.core.config._urdf import parse_urdf
from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.config.srdf import parse_srdf
from moveplan.core.errors import ConfigError, UnknownName

# A PR2-like mobile manipulator: planar virtual joint named in groups, <link> groups, subgroups.
PR2_LIKE = Path(__file__).parents[1] / "data" / "srdf_groups" / "pr2_like"
SRDF = (PR2_LIKE / "pr2_like.srdf").read_text()
URDF_JOINTS = parse_urdf((PR2_LIKE / "pr2_like.urdf").read_text(), PR2_LIKE / "pr2_like.urdf")
LEFT_ARM = ("l_shoulder_pan_joint", "l_shoulder_lift_joint", "l_wrist_roll_joint")
RIGHT_ARM = ("r_shoulder_pan_joint", "r_shoulder_lift_joint", "r_wrist_roll_joint")


@pytest.fixture(scope="module")
def realworld() -> Path:
    """The workspace of real MoveIt configs."""
    return REALWORLD


def parse(srdf: str, tmp_path: Path) -> object:
    """Parse an SRDF text against the PR2-like URDF, as if read from tmp_path/robot.srdf."""
    return parse_srdf(srdf, tmp_path / "robot.srdf", URDF_JOINTS)


def one_line(result) -> str:  # noqa: ANN001 - click's Result
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    return lines[0]


def pr2_copy(tmp_path: Path, old: str, new: str) -> Path:
    """A copy of the PR2-like config whose SRDF has `old` replaced by `new`."""
    folder = tmp_path / "pr2_like"
    shutil.copytree(PR2_LIKE, folder)
    assert old in SRDF
    (folder / "pr2_like.srdf").write_text(SRDF.replace(old, new, 1))
    return folder


# --- loading: every group, as MoveIt builds it ---------------------------------------------------


def test_a_config_whose_groups_name_the_virtual_joint_loads_and_lists_every_group(cli: Cli) -> None:
    code, document = cli.json("robot", PR2_LIKE)
    assert code == 0, document
    groups = document["groups"]
    assert list(groups) == ["left_arm", "right_arm", "base", "whole_body", "arms", "torso", "head", "left_gripper"]
    assert groups["base"]["joints"] == []
    assert groups["left_arm"] == {"joints": list(LEFT_ARM), "base": "torso_lift_link", "tip": "l_wrist_roll_link"}


def test_link_members_bring_the_joint_above_each_link() -> None:
    config = load_robot_config(PR2_LIKE)
    assert config.srdf.groups["head"].joints == ("head_pan_joint", "head_tilt_joint")
    # the palm hangs from a fixed joint; the right finger's joint mimics the left one's
    assert config.srdf.groups["left_gripper"].joints == ("l_gripper_l_finger_joint", "l_gripper_r_finger_joint")


def test_a_subgroup_may_be_defined_after_the_group_that_uses_it() -> None:
    whole_body = load_robot_config(PR2_LIKE).srdf.groups["whole_body"]
    assert whole_body.joints == ("torso_lift_joint", *LEFT_ARM, *RIGHT_ARM)
    assert whole_body.base_joints == {"world_joint": "planar"}


def test_group_joints_come_depth_first_through_the_tree_whatever_the_srdf_order() -> None:
    # `arms` names right_arm first; MoveIt orders the branches below the torso by joint name
    assert load_robot_config(PR2_LIKE).srdf.groups["arms"].joints == (*LEFT_ARM, *RIGHT_ARM)


def test_the_virtual_joints_values_in_a_group_state_are_checked_and_not_kept() -> None:
    srdf = load_robot_config(PR2_LIKE).srdf
    assert srdf.group_states["whole_body"]["at_origin"] == {"torso_lift_joint": 0.1}
    assert srdf.virtual_joints["world_joint"].parent_frame == "odom_combined"


def test_a_chain_from_one_wrist_to_the_other_runs_through_their_common_link(tmp_path: Path) -> None:
    srdf = parse(SRDF.replace('<group name="torso">', '<group name="wrist_to_wrist">'
                              '<chain base_link="l_wrist_roll_link" tip_link="r_wrist_roll_link"/></group>'
                              '<group name="torso">'), tmp_path)
    # as in MoveIt, the joint above the common link (the torso's) belongs to the chain too
    assert srdf.groups["wrist_to_wrist"].joints == ("torso_lift_joint", *LEFT_ARM, *RIGHT_ARM)


# --- planning: an arm of a mobile manipulator, not its base ---------------------------------------


def test_planning_an_arm_of_the_mobile_manipulator_writes_a_plan(cli: Cli, tmp_path: Path) -> None:
    output = tmp_path / "left.mcap"
    result = cli("plan", "--robot", PR2_LIKE, "--group", "left_arm", "--joints", "l_shoulder_pan_joint=0.5",
                 "-o", output, "--quiet")
    assert result.exit_code == 0, result.stderr
    assert output.is_file()


def test_a_group_moving_the_base_is_refused_naming_the_group_and_the_joint() -> None:
    config = load_robot_config(PR2_LIKE)
    with pytest.raises(ConfigError) as error:
        config.srdf.plannable("whole_body", config.srdf_path)
    assert str(error.value) == (
        f"{config.srdf_path}: group 'whole_body' moves the robot's base through its planar virtual joint "
        "'world_joint'; moveplan plans fixed-base arms: plan with a group without it "
        "(arms, head, left_arm, left_gripper, right_arm, torso)")
    assert config.srdf.plannable("left_arm", config.srdf_path).joints == LEFT_ARM


def test_a_fixed_virtual_joint_in_a_group_adds_nothing(tmp_path: Path) -> None:
    folder = pr2_copy(tmp_path, 'type="planar"', 'type="fixed"')
    config = load_robot_config(folder)
    whole_body = config.srdf.plannable("whole_body", config.srdf_path)
    assert whole_body.base_joints == {}
    assert whole_body.joints == ("torso_lift_joint", *LEFT_ARM, *RIGHT_ARM)


def test_a_link_group_of_the_root_link_takes_the_virtual_joint(tmp_path: Path) -> None:
    srdf = parse(SRDF.replace('<joint name="world_joint"/>', '<link name="base_footprint"/>'), tmp_path)
    assert srdf.groups["base"].base_joints == {"world_joint": "planar"}


def test_a_virtual_joint_off_the_root_link_is_skipped_with_a_warning(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.WARNING):
        srdf = parse(SRDF.replace('child_link="base_footprint"', 'child_link="torso_lift_link"'), tmp_path)
    assert srdf.groups["whole_body"].base_joints == {}
    assert ("virtual joint 'world_joint' is skipped, as MoveIt skips it: only the first one on the URDF root link "
            "(base_footprint) counts") in caplog.text


# --- bad files: one line naming the file -----------------------------------------------------------


def test_a_bad_value_for_the_virtual_joint_in_a_group_state_exits_3(cli: Cli, tmp_path: Path) -> None:
    folder = pr2_copy(tmp_path, 'value="0 0 0"', 'value="0 0 x"')
    result = cli("robot", folder)
    assert result.exit_code == 3
    assert one_line(result).endswith("pr2_like.srdf: group_state 'at_origin' joint 'world_joint': "
                                     "value='0 0 x' is not a list of finite numbers")


def test_an_unknown_virtual_joint_type_is_taken_as_fixed_with_a_warning(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    with caplog.at_level(logging.WARNING):
        srdf = parse(SRDF.replace('type="planar"', 'type="holonomic"'), tmp_path)
    assert srdf.groups["whole_body"].base_joints == {}
    assert ("virtual joint 'world_joint': type 'holonomic' is not one of fixed, floating, planar; taken as fixed, "
            "as MoveIt takes it") in caplog.text


def test_a_virtual_joint_without_a_name_is_skipped_as_moveit_skips_it(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    # ABB's IRB 1200 SRDF writes <virtual_joint type="floating" parent_frame="world" child_link="base_link"/>
    nameless = SRDF.replace('<virtual_joint name="world_joint" ', "<virtual_joint ").replace(
        '<group name="base">\n    <joint name="world_joint"/>\n  </group>', "").replace('<group name="base"/>', "")
    with caplog.at_level(logging.WARNING):
        srdf = parse(nameless.replace('<joint name="world_joint" value="0 0 0"/>', ""), tmp_path)
    assert srdf.virtual_joints == {}
    assert srdf.groups["whole_body"].joints == ("torso_lift_joint", *LEFT_ARM, *RIGHT_ARM)
    assert "a <virtual_joint> has no name; skipped, as MoveIt skips it" in caplog.text


def test_subgroups_that_include_each_other_are_an_error(tmp_path: Path) -> None:
    looped = SRDF.replace('<group name="torso">\n    <joint name="torso_lift_joint"/>',
                          '<group name="torso">\n    <group name="whole_body"/>')
    with pytest.raises(ConfigError, match="groups whole_body, torso include each other as subgroups"):
        parse(looped, tmp_path)


def test_an_unknown_subgroup_lists_the_groups(tmp_path: Path) -> None:
    with pytest.raises(UnknownName, match=r"group 'armz' not found in .*robot.srdf group 'whole_body'; known: arms"):
        parse(SRDF.replace('<group name="arms"/>', '<group name="armz"/>'), tmp_path)


def test_an_unknown_joint_in_a_group_lists_urdf_and_virtual_joints(tmp_path: Path) -> None:
    with pytest.raises(UnknownName, match=r"joint 'world_jiont' not found .*head_tilt_joint, .*world_joint"):
        parse(SRDF.replace('<joint name="world_joint"/>', '<joint name="world_jiont"/>'), tmp_path)


# --- real MoveIt configs ----------------------------------------------------------------------------


@pytest.mark.realworld
def test_moveit_resources_panda_hand_group_of_links_and_floating_virtual_joint(realworld: Path) -> None:
    resources = realworld / "moveit_resources"
    urdf = resources / "panda_description" / "urdf" / "panda.urdf"
    srdf_path = resources / "panda_moveit_config" / "config" / "panda.srdf"
    srdf = parse_srdf(srdf_path.read_text(), srdf_path, parse_urdf(urdf.read_text(), urdf))
    assert srdf.groups["hand"].joints == ("panda_finger_joint1", "panda_finger_joint2")
    assert srdf.virtual_joints["virtual_joint"].type == "floating"
    # the virtual joint is in no group: every group can be planned
    assert srdf.plannable("panda_arm_hand", srdf_path).joints[-2:] == ("panda_finger_joint1", "panda_finger_joint2")


@pytest.mark.realworld
def test_moveit_resources_fanuc_fixed_virtual_joint(realworld: Path) -> None:
    resources = realworld / "moveit_resources"
    urdf = resources / "fanuc_description" / "urdf" / "fanuc.urdf"
    srdf_path = resources / "fanuc_moveit_config" / "config" / "fanuc.srdf"
    srdf = parse_srdf(srdf_path.read_text(), srdf_path, parse_urdf(urdf.read_text(), urdf))
    assert srdf.plannable("manipulator", srdf_path).joints == tuple(f"joint_{i}" for i in range(1, 7))


_TOOL_URDF = """<robot name="arm"><link name="base"/><link name="l1"/><link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  <joint name="tool_joint" type="fixed"><parent link="l1"/><child link="tool"/></joint></robot>"""


def test_a_group_without_a_chain_ends_where_moveit_puts_its_end_effector_link(tmp_path: Path) -> None:
    # MoveGroupInterface: the end effector's parent link, else the group's last link, trailing fixed joints included.
    joints = parse_urdf(_TOOL_URDF, tmp_path / "arm.urdf")
    srdf = ('<robot name="arm"><group name="listed"><joint name="j1"/><joint name="tool_joint"/></group>'
            '<group name="bare"><joint name="j1"/></group><group name="held"><joint name="j1"/></group>'
            '<group name="eef"><link name="tool"/></group>'
            '<end_effector name="e" parent_link="tool" group="eef" parent_group="held"/></robot>')
    groups = parse_srdf(srdf, tmp_path / "arm.srdf", joints).groups
    assert (groups["listed"].tip, groups["bare"].tip, groups["held"].tip) == ("tool", "l1", "tool")
