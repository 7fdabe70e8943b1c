"""Reports read at 80 columns: every joint and step name whole, every unit in its header."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT, SAMPLES, UR10E

UR10E_JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
                "wrist_3_joint")


def _at_80_columns(*args: object) -> subprocess.CompletedProcess[str]:
    """Return a run of moveplan whose terminal is 80 columns wide."""
    return subprocess.run([sys.executable, "-m", "moveplan.cli.app", *map(str, args)], capture_output=True, text=True,
                          cwd=ROOT, env={**os.environ, "COLUMNS": "80"}, timeout=300)


@pytest.fixture(scope="module")
def plan_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Return the UR10e joint-goals sample, planned."""
    path = tmp_path_factory.mktemp("tables") / "plan.mcap"
    assert _at_80_columns("plan", SAMPLES / "ur10e_joint_goals.yaml", "-o", path, "-q").returncode == 0
    return path


def test_violations_name_the_joint_whole_with_units(plan_file: Path) -> None:
    result = _at_80_columns("execute", plan_file, "--fake", "--plant", "pid", "--controllers",
                            SAMPLES / "ur10e_mistuned_controllers.yaml")
    assert result.returncode == 5
    assert "wrist_2_joint error" in " ".join(result.stdout.split())  # the line after the verdict
    assert "…" not in result.stdout
    assert "margin [rad]" in result.stdout and "time [s]" in result.stdout
    for joint in UR10E_JOINTS:
        assert joint in result.stdout


def test_robot_limits_keep_joint_names_and_their_sources_whole() -> None:
    result = _at_80_columns("robot", UR10E)
    assert result.returncode == 0
    assert "…" not in result.stdout
    for joint in UR10E_JOINTS:
        assert f"{joint}:" in result.stdout or f"│ {joint} " in result.stdout
    assert "joint_limits.yaml" in result.stdout


def test_plan_and_inspect_tables_carry_units_and_whole_step_names(plan_file: Path) -> None:
    planned = _at_80_columns("plan", SAMPLES / "ur10e_joint_goals.yaml", "-o", plan_file.parent / "again.mcap")
    inspected = _at_80_columns("inspect", plan_file)
    for result in (planned, inspected):
        assert result.returncode == 0
        assert "…" not in result.stdout
        for step in ("first", "second", "home"):
            assert step in result.stdout
    assert "planning [ms]" in planned.stdout and "duration [s]" in planned.stdout
    assert "duration [s]" in inspected.stdout and "position [m]" in inspected.stdout


def test_piped_inspect_prints_each_topic_whole_on_one_line() -> None:
    recording = SAMPLES / "recordings" / "tool_up_ok.mcap"
    result = _at_80_columns("inspect", recording)
    topics = json.loads(_at_80_columns("inspect", recording, "--json").stdout)["topics"]
    assert result.returncode == 0
    title, *rows = result.stdout.splitlines()
    assert title.startswith(f"{recording}  (ros2, ")
    assert rows == [f"{t['topic']}: type {t['type']}  count {t['count']}  durability {t['durability']}" for t in topics]
    assert "durability transient_local" in result.stdout and max(map(len, rows)) > 80


def test_piped_verdict_and_violations_are_one_line_each_whatever_the_width() -> None:
    args = ("execute", SAMPLES / "recordings" / "tool_up_plan.mcap", "--fake", "--plant", "pid", "--controllers",
            SAMPLES / "ur10e_mistuned_controllers.yaml")
    result = _at_80_columns(*args)
    document = json.loads(_at_80_columns(*args, "--json").stdout)
    assert result.returncode == 5
    lines = result.stdout.splitlines()
    verdict = document["result"]
    assert lines[0] == f"{verdict['name']} ({verdict['code']}): {verdict['message']}" and len(lines[0]) > 80
    for v in document["violations"]:
        assert (f"{v['step']}: check {v['check']}  joint {v['joint']}  time [s] {v['time_s']:.3f}  reference "
                f"{v['reference']:.4f}  actual {v['actual']:.4f}  error {v['error']:.4f}  tolerance "
                f"{v['tolerance']:.4f}  unit {v['unit']}") in lines
