"""benchmarks/roboplan_compare.py and vamp_compare.py without their tools: what the worker gets, a wrong --X-python."""

from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from moveplan.core.config.robot_config import load_robot_config
from moveplan.core.model.robot import Robot

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
MBM = Path(__file__).resolve().parents[1] / "data" / "mbm"


def _module(name: str):
    """Return the benchmark script `name` imported from its file."""
    if str(BENCHMARKS) not in sys.path:
        sys.path.insert(0, str(BENCHMARKS))  # roboplan_compare imports pyroboplan_compare by name
    spec = importlib.util.spec_from_file_location(name, BENCHMARKS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize(("tool", "lacking", "install"), [
    ("roboplan", "roboplan", "roboplan==0.7.0"), ("vamp", "VAMP's Panda", "vamp-planner==0.6.4")])
def test_a_python_without_the_tool_is_one_line_naming_the_flag(tool: str, lacking: str, install: str) -> None:
    result = subprocess.run([sys.executable, str(BENCHMARKS / f"{tool}_compare.py"), f"--{tool}-python",
                             sys.executable, "--count", "1"], capture_output=True, text=True, timeout=120)
    assert result.returncode == 1
    assert result.stderr.strip().splitlines() == [
        f"{tool}_compare: --{tool}-python {sys.executable}: not a python with {lacking} "
        f"(python3.11 -m venv VENV && VENV/bin/pip install {install}; see benchmarks/README.md)"]
    assert result.stdout == ""


def test_the_worker_gets_the_problems_scene_group_joints_and_limits() -> None:
    compare, shared = _module("roboplan_compare"), _module("pyroboplan_compare")
    problems = shared.load_problems(MBM / "problems", 1)
    robot = Robot(load_robot_config(MBM / "panda_robot"), "panda_arm")
    job = compare.job_of(problems, robot, 3, argparse.Namespace(mbm=MBM, time_limit=2.0))
    assert job["seed"] == 3 and job["time_limit_s"] == 2.0 and job["group"] == "panda_arm"
    box = job["problems"][[p.name for p in problems].index("box_panda/0001")]
    assert box["joints"] == [f"panda_joint{k}" for k in range(1, 8)]
    assert box["start"] == [0, -0.785, 0, -2.356, 0, 1.571, 0.785]
    # The Panda's published limits (joint_limits.yaml), not the URDF's, nor unbounded accelerations.
    assert job["limits"]["panda_joint2"] == {"max_velocity": [2.175], "max_acceleration": [1.875]}
    can = next(o for o in box["objects"] if o["name"] == "Can1")
    # box_panda scene0001: cylinder [height 0.14, radius 0.03] at its primitive pose in `world`.
    assert can["shape"] == {"kind": "cylinder", "radius": 0.03, "length": 0.14}
    np.testing.assert_allclose(np.asarray(can["transform"])[:3, 3], [0.5408380884576693, 0.3580155146897772,
                                                                      -0.3762264457751537])
    assert ["panda_hand", "panda_leftfinger"] in box["allowed"]
