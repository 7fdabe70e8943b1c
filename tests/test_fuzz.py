"""Fuzzing plan files, recordings and config YAML: whatever the bytes or values, a command ends with its
documented exit code and one line, or with a verdict; never a traceback or an internal error.

Plan files and recordings (samples/recordings) get bytes flipped, overwritten, spliced or cut; the
robot config's YAML files and a task get values replaced by NaN, infinities, huge or negative
numbers, wrong types and junk. Examples are derandomized: the same ones run every time, and none
depends on the clock. MOVEPLAN_FUZZ_EXAMPLES=N runs N per test instead (for a long run by hand).
"""

from __future__ import annotations

import copy
import math
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

import yaml
from conftest import SAMPLES, UR10E, Cli
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

PLAN = SAMPLES / "recordings" / "tool_up_plan.mcap"
RECORDING = SAMPLES / "recordings" / "tool_up_path_violation.mcap"
TASK = SAMPLES / "ur10e_tool_up.yaml"

FUZZ = settings(
    max_examples=int(os.environ.get("MOVEPLAN_FUZZ_EXAMPLES", "15")), deadline=None, derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow, HealthCheck.data_too_large],
)

HOSTILE_VALUES = st.sampled_from([
    math.nan, math.inf, -math.inf, 1e308, -1e308, 2**70, -1, 0, 0.0, -0.5, "", "nan", "x" * 300, None, True,
    [], {}, [1, 2, 3], {"a": {"b": None}}, "$(env MOVEPLAN_FUZZ_UNSET)", "package://nowhere/x.stl", "/dev/zero",
])


@st.composite
def damaged(draw: st.DrawFn, data: bytes) -> bytes:
    """Return `data` with bytes flipped, overwritten or inserted, or cut short."""
    result = bytearray(data)
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["flip", "overwrite", "insert", "cut"]))
        at = draw(st.integers(0, max(len(result) - 1, 0)))
        if kind == "flip" and result:
            result[at] ^= 1 << draw(st.integers(0, 7))
        elif kind == "overwrite":
            chunk = draw(st.binary(min_size=1, max_size=16))
            result[at:at + len(chunk)] = chunk
        elif kind == "insert":
            result[at:at] = draw(st.binary(min_size=1, max_size=64))
        else:
            del result[at:]
    return bytes(result)


@st.composite
def spoiled(draw: st.DrawFn, document: Any) -> Any:
    """Return a copy of a parsed YAML document with one to three values (or keys' values) replaced."""
    result = yaml.safe_load(yaml.safe_dump(document))
    for _ in range(draw(st.integers(1, 3))):
        node, key = None, None
        current = result
        while isinstance(current, dict | list) and current and (node is None or draw(st.booleans())):
            node = current
            key = draw(st.sampled_from(sorted(current, key=str) if isinstance(current, dict) else range(len(current))))
            current = node[key]
        if node is None:
            return copy.deepcopy(draw(HOSTILE_VALUES))
        node[key] = copy.deepcopy(draw(HOSTILE_VALUES))  # the sampled value itself stays as drawn
    return result


def assert_clean(result: Any, codes: set[int]) -> None:
    """Assert a documented exit code among `codes`, at most one line on stderr, and no traceback or internal error."""
    assert result.exit_code in codes, (result.exit_code, result.stderr, result.exception)
    assert "Traceback" not in result.stderr and "internal error" not in result.stderr, result.stderr
    assert len([line for line in result.stderr.splitlines() if line.strip()]) <= 1, result.stderr


@FUZZ
@given(data=st.data())
def test_a_damaged_plan_file_is_executed_inspected_or_refused_in_one_line(cli: Cli, data: st.DataObject) -> None:
    with tempfile.TemporaryDirectory(prefix="moveplan-fuzz-") as folder:
        plan = Path(folder) / "plan.mcap"
        plan.write_bytes(data.draw(damaged(PLAN.read_bytes())))
        assert_clean(cli("inspect", plan), {0, 3})
        out = Path(folder) / "out.mcap"
        result = cli("execute", plan, "--fake", "-o", out, "-q")
        assert_clean(result, {0, 3, 5})
        assert out.exists() == (result.exit_code in (0, 5))


@FUZZ
@given(data=st.data())
def test_a_damaged_recording_is_judged_or_refused_in_one_line(cli: Cli, data: st.DataObject) -> None:
    with tempfile.TemporaryDirectory(prefix="moveplan-fuzz-") as folder:
        recording = Path(folder) / "recording.mcap"
        recording.write_bytes(data.draw(damaged(RECORDING.read_bytes())))
        assert_clean(cli("check-tolerances", PLAN, recording, "-q"), {0, 3, 5})
        assert_clean(cli("check-tolerances", PLAN, recording, "--skip-damaged", "-q"), {0, 3, 5})


@FUZZ
@given(data=st.data())
def test_spoiled_controller_values_execute_or_are_refused_in_one_line(cli: Cli, data: st.DataObject) -> None:
    controllers = yaml.safe_load((UR10E / "ros2_controllers.yaml").read_text())
    with tempfile.TemporaryDirectory(prefix="moveplan-fuzz-") as folder:
        path = Path(folder) / "controllers.yaml"
        path.write_text(yaml.safe_dump(data.draw(spoiled(controllers))))
        assert_clean(cli("execute", PLAN, "--fake", "--controllers", path, "-o", Path(folder) / "e.mcap", "-q"),
                     {0, 3, 5})


@FUZZ
@given(data=st.data(), name=st.sampled_from(["joint_limits.yaml", "initial_positions.yaml", "moveit_controllers.yaml",
                                             "moveplan.yaml"]))
def test_spoiled_robot_config_values_load_or_are_refused_in_one_line(
    cli: Cli, data: st.DataObject, name: str
) -> None:
    document = yaml.safe_load((UR10E / name).read_text())
    with tempfile.TemporaryDirectory(prefix="moveplan-fuzz-") as folder:
        config = Path(folder) / "ur10e"
        shutil.copytree(UR10E, config)
        (config / name).write_text(yaml.safe_dump(data.draw(spoiled(document))))
        assert_clean(cli("robot", config, "-q"), {0, 2, 3})


@FUZZ
@given(data=st.data())
def test_a_spoiled_task_plans_or_is_refused_in_one_line(cli: Cli, data: st.DataObject) -> None:
    task = yaml.safe_load(TASK.read_text())
    task["robot"] = str(UR10E)
    task.pop("scene", None)
    with tempfile.TemporaryDirectory(prefix="moveplan-fuzz-") as folder:
        path = Path(folder) / "task.yaml"
        path.write_text(yaml.safe_dump(data.draw(spoiled(task))))
        assert_clean(cli("plan", path, "--planning-time", "0.05", "-o", Path(folder) / "p.mcap", "-q"), {0, 2, 3, 4})


@FUZZ
@given(data=st.data(), scene=st.sampled_from(["ur10e_table_scene.yaml", "ur10e_workshop_scene.yaml"]))
def test_a_spoiled_scene_loads_or_is_refused_in_one_line(cli: Cli, data: st.DataObject, scene: str) -> None:
    document = yaml.safe_load((SAMPLES / scene).read_text())
    with tempfile.TemporaryDirectory(prefix="moveplan-fuzz-") as folder:
        path = Path(folder) / scene
        path.write_text(yaml.safe_dump(data.draw(spoiled(document))))
        assert_clean(cli("state", "--robot", UR10E, "--scene", path, "-q"), {0, 3})
