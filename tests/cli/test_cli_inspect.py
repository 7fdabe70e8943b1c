"""`moveplan inspect`: topics of any bag; steps, durations and peak rates of a plan file."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import SAMPLES, Cli


@pytest.fixture(scope="module")
def task_plan(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("inspect") / "task.mcap"
    assert Cli()("plan", SAMPLES / "ur10e_joint_goals.yaml", "-o", out).exit_code == 0
    return out


def test_inspect_plan_lists_topics_and_steps_with_peak_fractions(cli: Cli, task_plan: Path) -> None:
    code, document = cli.json("inspect", task_plan)
    assert code == 0
    counts = {t["topic"]: t["count"] for t in document["topics"]}
    assert counts["/planned_trajectory"] == 3 and counts["/robot_description"] == 1
    steps = document["plan"]["steps"]
    assert [s["name"] for s in steps] == ["first", "second", "home"]
    # The task runs its second step at 0.1 of the limits and the others at 0.3.
    assert 0.05 < steps[1]["peak_velocity_fraction"] <= 0.1 + 1e-9 or steps[1]["peak_acceleration_fraction"] <= 0.1
    for step in steps:
        assert step["peak_velocity_fraction"] <= 0.3 + 1e-9 and step["peak_acceleration_fraction"] <= 0.3 + 1e-9


def test_inspect_table_names_each_step(cli: Cli, task_plan: Path) -> None:
    result = cli("inspect", task_plan)
    assert result.exit_code == 0
    assert "second" in result.stdout and "/planned_trajectory" in result.stdout


@pytest.mark.parametrize("content", [b"", b"not an mcap file at all", None])
def test_inspect_bad_file_exits_3_naming_it(cli: Cli, tmp_path: Path, task_plan: Path, content: bytes | None) -> None:
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(task_plan.read_bytes()[:700] if content is None else content)
    result = cli("inspect", bad)
    assert result.exit_code == 3, result.stderr
    assert "bad.mcap" in result.stderr and "Traceback" not in result.stderr
