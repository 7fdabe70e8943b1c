"""A MoveIt 1 config starts where its fake controllers start it: fake_controllers.yaml's `initial:` poses.

MoveIt 1's moveit_resources panda_moveit_config (config/fake_controllers.yaml) starts the arm at
`ready` and the hand `open`: without it, the Panda would start at zeros, in self-collision.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from conftest import ROOT

from moveplan.core.config import load_robot_config
from moveplan.core.errors import UnknownName

PANDA = ROOT / "tests" / "data" / "mbm" / "panda_robot"


def _with_fake_controllers(tmp_path: Path, text: str) -> Path:
    folder = tmp_path / "panda"
    shutil.copytree(PANDA, folder)
    (folder / "fake_controllers.yaml").write_text(text)
    return folder


def test_the_initial_poses_of_fake_controllers_are_the_start(tmp_path: Path) -> None:
    folder = _with_fake_controllers(tmp_path, "controller_list: []\ninitial:\n  - group: panda_arm\n    pose: ready\n")
    config = load_robot_config(folder)
    assert config.initial_positions["panda_joint4"] == pytest.approx(-2.356)
    assert config.initial_sources["panda_joint4"] == f"the initial poses of {folder / 'fake_controllers.yaml'}"


def test_an_initial_pose_the_srdf_lacks_is_named(tmp_path: Path) -> None:
    folder = _with_fake_controllers(tmp_path, "initial:\n  - group: panda_arm\n    pose: nowhere\n")
    with pytest.raises(UnknownName, match="named state 'nowhere'.*initial\\[0\\].pose"):
        load_robot_config(folder)
