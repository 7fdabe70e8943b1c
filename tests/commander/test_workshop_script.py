"""samples/ur10e_workshop.py: the MoveIt workshop script, run as a user runs it, lands where the CLI samples do."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, SAMPLES, Cli
from rosbags.highlevel import AnyReader

from moveplan.core.config import load_task
from moveplan.core.pipeline.plan import plan
from moveplan.core.pipeline.request import PlanFlags, resolve_request

SCRIPT = SAMPLES / "ur10e_workshop.py"

# Each CLI sample's steps, and the motions of the script that do the same, by index in the saved file.
SAME_MOTIONS = {
    "ur10e_joint_goals": (1, 2, 3),
    "ur10e_tool_up": (5,),
    "ur10e_to_target": (7,),
    "ur10e_tilted_approach": (9,),
    "ur10e_tool_x_shift": (11,),
    "ur10e_pick_and_place": (13, 14, 15, 16, 17),
}


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("workshop") / "workshop.mcap"
    run = subprocess.run([sys.executable, SCRIPT, out], capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert run.returncode == 0, run.stderr
    assert run.stdout == ""  # the script prints nothing, and neither does the API
    return out


def planned_trajectories(path: Path) -> list:
    """Return every /planned_trajectory message of a plan file, read with rosbags."""
    with AnyReader([path]) as reader:
        connections = [c for c in reader.connections if c.topic == "/planned_trajectory"]
        return [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(connections=connections)]


def test_every_exercise_lands_where_its_cli_sample_does(saved: Path) -> None:
    motions = planned_trajectories(saved)
    assert len(motions) == 18
    for sample, indices in SAME_MOTIONS.items():
        steps = plan(resolve_request(load_task(SAMPLES / f"{sample}.yaml"), PlanFlags())).steps
        for step, index in zip(steps, indices, strict=True):
            np.testing.assert_allclose(motions[index].points[-1].positions, step.trajectory.positions[-1],
                                       atol=1e-4, err_msg=f"{sample}: {step.name}")


def test_the_saved_file_opens_with_inspect_and_replays_with_execute(saved: Path, tmp_path: Path) -> None:
    cli = Cli()
    inspected = cli("inspect", saved)
    assert inspected.exit_code == 0, inspected.stderr
    assert "cartesian_4" in inspected.stdout and "home_5" in inspected.stdout
    executed = cli("execute", saved, "--fake", "-o", tmp_path / "executed.mcap")
    assert executed.exit_code == 0, executed.stderr
    assert "executed 18 of 18 steps" in executed.stderr + executed.stdout
    checked = cli("check-tolerances", saved, tmp_path / "executed.mcap")
    assert checked.exit_code == 0, checked.stderr


def test_the_saved_scene_holds_the_scripts_objects_and_frames(saved: Path) -> None:
    with AnyReader([saved]) as reader:
        connections = {c.topic: c for c in reader.connections}
        [(_, _, markers)] = list(reader.messages(connections=[connections["/planning_scene_markers"]]))
        [(_, _, statics)] = list(reader.messages(connections=[connections["/tf_static"]]))
        markers = reader.deserialize(markers, connections["/planning_scene_markers"].msgtype)
        statics = reader.deserialize(statics, connections["/tf_static"].msgtype)
    assert [m.text for m in markers.markers] == ["table", "post", "cube"]
    assert {t.child_frame_id for t in statics.transforms} >= {"target_1", "target_2", "object"}
