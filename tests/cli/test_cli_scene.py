"""`moveplan scene`: any scene moveplan reads, written as MoveIt's text `.scene` file, or one line and no file."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml
from conftest import ROOT, TABLE_SCENE, Cli, run_process

from moveplan.core.config import parse_scene_text

SCENES = ROOT / "tests" / "data" / "scenes"
MOVEIT_WRITTEN = ROOT / "tests" / "data" / "moveit_written"


def held_scene(tmp_path: Path) -> Path:
    """Return a moveplan scene with an object in a scene frame and one attached to the tool."""
    path = tmp_path / "held.yaml"
    path.write_text(yaml.safe_dump({
        "frames": [{"name": "fixture", "parent": "base_link", "xyz": [0.6, 0.2, 0.1], "rpy": [0, 0, np.pi / 2]}],
        "objects": [{"name": "pin", "frame": "fixture", "cylinder": {"radius": 0.01, "length": 0.1},
                     "xyz": [0.1, 0, 0]}],
        "attached": [{"name": "gripper", "link": "tool0", "box": [0.05, 0.05, 0.1]}],
    }))
    return path


def assert_failed_on_one_line(result: Any, code: int, output: Path) -> None:
    """Assert a run exited `code` with one line on stderr and left neither `output` nor a temporary file."""
    assert result.exit_code == code, result.stderr
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr
    assert not output.exists() and not list(output.parent.glob(f".{output.name}.*"))


def test_a_scene_yaml_is_written_and_summarised(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "cell.scene"
    result = cli("scene", TABLE_SCENE, "--robot", "ur10e", "-o", out)
    assert result.exit_code == 0, result.stderr
    assert result.stdout.strip() == (f"wrote {out}: scene 'ur10e_table_scene', 3 world objects (table, box_left, "
                                     "box_right), poses in ur10e's planning frame base_link")
    objects = parse_scene_text(out.read_text(), out).objects
    assert [o.name for o in objects] == ["table", "box_left", "box_right"]
    np.testing.assert_allclose(objects[2].transform[:3, 3], [0.6, -0.6, 0.2])


def test_json_names_the_files_the_objects_written_and_the_attached_ones_left_out(
    cli: Cli, tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    out = tmp_path / "held.scene"
    result = cli("scene", held_scene(tmp_path), "--robot", "ur10e", "-o", out, "--json")
    assert result.exit_code == 0, result.stderr
    assert json.loads(result.stdout) == {
        "ok": True, "scene": str(tmp_path / "held.yaml"), "output": str(out), "robot": "ur10e", "name": "held",
        "planning_frame": "base_link", "objects": ["pin"], "skipped": ["gripper"], "error": None}
    assert "attached objects not written (gripper)" in caplog.text
    (pin,) = parse_scene_text(out.read_text(), out).objects
    np.testing.assert_allclose(pin.transform[:3, 3], [0.6, 0.3, 0.1], atol=1e-9)  # 0.1 along the fixture's x: world y


def test_quiet_prints_nothing_and_writes_the_file(cli: Cli, tmp_path: Path) -> None:
    out = tmp_path / "held.scene"
    result = cli("scene", held_scene(tmp_path), "--robot", "ur10e", "-o", out, "--quiet")
    assert result.exit_code == 0 and result.stdout == "" and result.stderr == ""
    assert out.read_text().startswith("held\n* pin\n")


def test_a_planning_scene_with_mesh_files_is_written_by_a_real_process(tmp_path: Path) -> None:
    out = tmp_path / "bin.scene"
    result = run_process("scene", MOVEIT_WRITTEN / "mesh_scene.yaml", "--robot", "panda",
                         "--package-path", MOVEIT_WRITTEN, "-o", out)
    assert result.returncode == 0, result.stderr
    lines = out.read_text().splitlines()
    assert lines[:6] == ["bin_and_post", "* bin", "0.45 -0.35 0.1", "0 0 0 1", "1", "mesh"]
    assert lines[6] == "8 10" and lines[-1] == "."


@pytest.mark.parametrize(("name", "text", "message"), [
    ("bad.scene", "s\n* b\n1\nbox\n0.1 x 0.1\n0 0 0\n0 0 0 1\n0 0 0 0\n.\n", "line 5: object 'b': shape 0: box size"),
    ("bad.yaml", "objects:\n  - {name: ball, sphere: -1}\n", "bad.yaml: objects[0]"),
    ("moving.yaml", "objects:\n  - {name: ball, frame: tool0, sphere: 0.1}\n", "frame 'tool0' moves with link"),
])
def test_a_malformed_scene_exits_3_on_one_line_and_writes_nothing(
    cli: Cli, tmp_path: Path, name: str, text: str, message: str
) -> None:
    scene, out = tmp_path / name, tmp_path / "out.scene"
    scene.write_text(text)
    result = cli("scene", scene, "--robot", "ur10e", "-o", out)
    assert_failed_on_one_line(result, 3, out)
    assert message in result.stderr


def test_a_failed_run_leaves_an_existing_output_as_it_was(cli: Cli, tmp_path: Path) -> None:
    scene, out = tmp_path / "bad.scene", tmp_path / "out.scene"
    scene.write_text("s\n* p\n1\nplane\n0 0 1 0\n0 0 0\n0 0 0 1\n0 0 0 0\n.\n")
    out.write_text("earlier\n.\n")
    code, document = cli.json("scene", scene, "--robot", "ur10e", "-o", out)
    assert code == 3 and document["ok"] is False and document["error"]["kind"] == "ConfigError"
    assert out.read_text() == "earlier\n.\n"


@pytest.mark.parametrize("where", ["missing/out.scene", "a_file/out.scene"])
def test_an_unwritable_output_exits_3_naming_it(cli: Cli, tmp_path: Path, where: str) -> None:
    (tmp_path / "a_file").write_text("")
    out = tmp_path / where
    result = cli("scene", TABLE_SCENE, "--robot", "ur10e", "-o", out)
    assert result.exit_code == 3 and result.stderr.count("\n") == 1
    assert f"{out}: cannot write" in result.stderr and not out.exists()


@pytest.mark.parametrize(("args", "message"), [
    (["-o", "{tmp}/cell.yaml"], "-o '{tmp}/cell.yaml': expected a file name ending in .scene"),
    (["-o", str(SCENES / "rviz_table.scene")], "is also SCENE, read by this command"),
])
def test_usage_errors_exit_2_and_write_nothing(cli: Cli, tmp_path: Path, args: list[str], message: str) -> None:
    before = (SCENES / "rviz_table.scene").read_text()
    args = [a.replace("{tmp}", str(tmp_path)) for a in args]
    result = cli("scene", SCENES / "rviz_table.scene", "--robot", "ur10e", *args)
    assert result.exit_code == 2 and message.replace("{tmp}", str(tmp_path)) in result.stderr
    assert not list(tmp_path.iterdir()) and (SCENES / "rviz_table.scene").read_text() == before


def test_the_robot_is_required(cli: Cli, tmp_path: Path) -> None:
    result = cli("scene", TABLE_SCENE, "-o", tmp_path / "cell.scene")
    assert result.exit_code == 2 and "--robot" in result.stderr and not list(tmp_path.iterdir())
