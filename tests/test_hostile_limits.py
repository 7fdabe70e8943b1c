"""Hostile input that never ends: a device, a FIFO or a folder given where a file is read.

Each is refused before it is read, with one line naming it (exit 3), and no output is written
(docs/formats.md, Limits).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest
from conftest import SAMPLES, UR10E, Cli

from moveplan.core.config.fields import read_input
from moveplan.core.errors import ConfigError

SHIPPED_PLAN = SAMPLES / "recordings" / "tool_up_plan.mcap"
NOT_FILES = ["/dev/zero", "/dev/urandom", "FIFO", "FOLDER"]


@pytest.fixture()
def not_a_file(tmp_path: Path, request: pytest.FixtureRequest) -> str:
    """Return the path of what the test's parameter names: a device, or a FIFO or folder made in tmp_path."""
    kind = request.param
    if kind == "FIFO":
        os.mkfifo(tmp_path / "fifo.yaml")  # no writer: reading it would wait forever
        return str(tmp_path / "fifo.yaml")
    if kind == "FOLDER":
        (tmp_path / "folder.yaml").mkdir()
        return str(tmp_path / "folder.yaml")
    return kind


def _command(kind: str, path: str, tmp_path: Path) -> list[object]:
    """Return the command line reading `path` as the input `kind`."""
    shutil.copy(SHIPPED_PLAN, tmp_path / "p.mcap")
    out = tmp_path / "out"
    return {
        "scene": ["plan", "--robot", UR10E, "--scene", path, "--named", "home", "-o", out],
        "request": ["plan", "--robot", UR10E, "--request", path, "-o", out],
        "task": ["plan", path, "-o", out],
        "controllers": ["execute", tmp_path / "p.mcap", "--fake", "--controllers", path, "-o", out],
        "tune-pid controllers": ["tune-pid", tmp_path / "p.mcap", "--controllers", path, "-o", out],
        "state scene": ["state", "--robot", UR10E, "--scene", path],
    }[kind]


@pytest.mark.parametrize("not_a_file", NOT_FILES, indirect=True)
@pytest.mark.parametrize("kind", ["scene", "request", "task", "controllers", "tune-pid controllers", "state scene"])
def test_a_device_fifo_or_folder_given_as_an_input_file_is_refused_at_once(
    cli: Cli, tmp_path: Path, not_a_file: str, kind: str
) -> None:
    result = cli(*_command(kind, not_a_file, tmp_path), "-q")
    assert result.exit_code == 3, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"moveplan: error: {not_a_file}"), result.stderr
    assert "not a regular file" in lines[0] or "a folder, not a file" in lines[0]
    assert not (tmp_path / "out").exists()


def test_a_file_is_read_no_further_than_the_limit_whatever_it_claims(tmp_path: Path) -> None:
    big = tmp_path / "big.yaml"
    big.write_bytes(b"a: 1\n" * 100)
    assert read_input(big, limit=500) == b"a: 1\n" * 100
    with pytest.raises(ConfigError, match=r"big.yaml: more than 499 bytes; moveplan reads files of at most 499"):
        read_input(big, limit=499)


def test_a_trajectory_beyond_the_control_cycle_limit_is_refused_before_it_is_simulated(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A plan of hours at a kHz rate would take gigabytes: the limit is stated, and raised by the variable."""
    monkeypatch.setenv("MOVEPLAN_MAX_CONTROL_CYCLES", "100")
    result = cli("execute", SHIPPED_PLAN, "--fake", "-o", tmp_path / "e.mcap")
    assert result.exit_code == 3
    line = result.stderr.strip()
    assert line.startswith(f"moveplan: error: {SHIPPED_PLAN}: step 'up': a ") and "\n" not in line
    assert "control cycles; moveplan simulates at most 100 per trajectory (MOVEPLAN_MAX_CONTROL_CYCLES" in line
    assert not (tmp_path / "e.mcap").exists()
    monkeypatch.setenv("MOVEPLAN_MAX_CONTROL_CYCLES", "10000000")
    assert cli("execute", SHIPPED_PLAN, "--fake", "-o", tmp_path / "e.mcap", "-q").exit_code == 0


def test_a_control_cycle_limit_that_is_no_number_is_a_usage_error(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("MOVEPLAN_MAX_CONTROL_CYCLES", "lots")
    result = cli("execute", SHIPPED_PLAN, "--fake", "-o", tmp_path / "e.mcap")
    assert result.exit_code == 2
    assert result.stderr == ("moveplan: error: MOVEPLAN_MAX_CONTROL_CYCLES='lots': expected a positive number of "
                             "control cycles\n")


@pytest.mark.parametrize("kind", ["--robot", "inspect", "task robot", "--scene"])
def test_a_name_too_long_for_the_system_is_bad_input_naming_it_shortened(cli: Cli, tmp_path: Path, kind: str) -> None:
    name = "x" * 300  # beyond NAME_MAX (255): the system refuses to look it up
    if kind == "task robot":
        (tmp_path / "task.yaml").write_text(f"robot: {name}\nsteps:\n  - {{name: home, named: home}}\n")
        args: list[object] = ["plan", tmp_path / "task.yaml", "-o", tmp_path / "out"]
    elif kind == "inspect":
        args = ["inspect", name]
    else:
        args = ["plan", "--robot", UR10E if kind == "--scene" else name, *([kind, name] if kind == "--scene" else []),
                "--named", "home", "-o", tmp_path / "out"]
    result = cli(*args)
    assert result.exit_code == 3, result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "internal error" not in lines[0] and len(lines[0]) < 400, result.stderr
    assert lines[0].endswith("File name too long")


def test_control_characters_from_a_file_reach_the_terminal_escaped(cli: Cli, tmp_path: Path) -> None:
    task = tmp_path / "task.yaml"
    task.write_text('"\\x1b[31mred\\x07": 1\nsteps: []\n')  # an escape sequence and a bell as a key
    result = cli("plan", task, "-o", tmp_path / "out")
    assert result.exit_code == 3
    assert r"unknown key '\x1b[31mred\x07'" in result.stderr and "\x1b" not in result.stderr


def test_a_scene_coordinate_beyond_the_bound_is_refused_naming_it(cli: Cli, tmp_path: Path) -> None:
    """A box at 1e18 m broke coal's bounding volumes (an internal error); 1e300 was called a collision."""
    scene = tmp_path / "scene.yaml"
    scene.write_text("objects:\n  - {name: box, frame: base_link, xyz: [0.6, 1.0e18, 0.2], box: [0.1, 0.1, 0.1]}\n")
    result = cli("plan", "--robot", UR10E, "--scene", scene, "--named", "home", "-o", tmp_path / "out")
    assert result.exit_code == 3
    assert "scene.yaml: objects[0].xyz[1]: 1e+18 is out of range; values are limited to |value| <= 1,000,000" \
        in result.stderr


@pytest.mark.parametrize("group", ["{manipulator: 1}", "[manipulator]"])
def test_a_planning_group_that_is_no_name_is_refused(cli: Cli, tmp_path: Path, group: str) -> None:
    config = tmp_path / "ur10e"
    shutil.copytree(UR10E, config)
    manifest = config / "moveplan.yaml"
    manifest.write_text(manifest.read_text().replace("group: manipulator", f"group: {group}"))
    result = cli("robot", config)
    assert result.exit_code == 3
    assert "moveplan.yaml: planning.group: expected a name, got" in result.stderr


def test_a_huge_goal_duration_margin_is_refused_before_memory_is_spent(cli: Cli, tmp_path: Path) -> None:
    """MoveIt's duration monitor waits the margin out: 1e12 s asked for terabytes of control cycles."""
    controllers = tmp_path / "moveit_controllers.yaml"
    controllers.write_text("trajectory_execution: {allowed_goal_duration_margin: 1.0e12}\n")
    config = tmp_path / "ur10e"
    shutil.copytree(UR10E, config)
    shutil.copy(controllers, config / "moveit_controllers.yaml")
    plan = tmp_path / "plan.mcap"
    assert cli("plan", "--robot", config, "--start-joints", "0,-1,-1,0,0,0", "--named", "home", "-o", plan,
               "-q").exit_code == 0
    result = cli("execute", plan, "--fake", "-o", tmp_path / "e.mcap")
    assert result.exit_code == 3
    assert "control cycles; moveplan simulates at most 1,000,000 per trajectory" in result.stderr
