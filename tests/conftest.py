"""Shared fixtures: the repo's shipped configs and samples, robots loaded once, CLI runners, the real-world tier."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from mcap.writer import CompressionType, Writer
from typer.testing import CliRunner

from moveplan.cli.app import app
from moveplan.core.config.robot_config import RobotConfig, load_robot_config
from moveplan.core.model.robot import Robot
from moveplan.core.trajectory import sample
from moveplan.core.types import JointTrajectory

ROOT = Path(__file__).resolve().parents[1]
UR10E = ROOT / "configs" / "ur10e"
SAMPLES = ROOT / "samples"
TABLE_SCENE = SAMPLES / "ur10e_table_scene.yaml"
# Real MoveIt 2 config packages as a colcon workspace's src/ (tools/get_realworld.sh builds one).
REALWORLD = Path(os.environ.get("MOVEPLAN_REALWORLD") or ROOT.parent / "shared" / "realworld" / "src").resolve()
# MoveIt 1's moveit_resources (fanuc, panda, dual panda), where MoveIt's Python tests run; part of that tier.
NOETIC = Path(os.environ.get("MOVEPLAN_NOETIC")
              or ROOT.parent / "shared" / "peers" / "moveit_resources_noetic").resolve()



def fleet_manifest(folder: Path, column: str, values: tuple[str, str, str, str, str]) -> Path:
    """Return a manifest in `folder` of five items (a pass, a violation, a corrupt file, a missing one, a glob's
    match), its third column `column` holding `values`; the recordings it names are copied beside it."""
    import shutil

    for name in ("tool_up_plan", "tool_up_ok", "tool_up_path_violation", "tool_up_goal_missed"):
        shutil.copy(SAMPLES / "recordings" / f"{name}.mcap", folder / f"{name}.mcap")
    (folder / "corrupt.mcap").write_bytes(b"\x89MCAP0\r\n" + b"\x00" * 40)
    recordings = ("tool_up_ok.mcap", "tool_up_path_violation.mcap", "corrupt.mcap", "missing.mcap",
                  "tool_up_goal_*.mcap")
    manifest = folder / "fleet.csv"
    manifest.write_text(f"plan,recording,{column}\n" + "".join(
        f"tool_up_plan.mcap,{recording},{value}\n" for recording, value in zip(recordings, values, strict=True)))
    return manifest

def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Leave out the real-world tier where its workspace is missing; under CI=true, fail the run instead."""
    tier = [item for item in items if item.get_closest_marker("realworld")]
    missing = [folder for folder in (REALWORLD, NOETIC) if not folder.is_dir()]
    if not tier or not missing:
        return
    if os.environ.get("CI", "").lower() == "true":
        raise pytest.UsageError(f"{', '.join(map(str, missing))}: the real-world MoveIt workspace is missing, and "
                                f"CI=true requires its {len(tier)} tests; {_HOW_TO_GET_REALWORLD}")
    config.hook.pytest_deselected(items=tier)
    items[:] = [item for item in items if not item.get_closest_marker("realworld")]
    config.stash[_LEFT_OUT] = len(tier)


_LEFT_OUT = pytest.StashKey[int]()
_HOW_TO_GET_REALWORLD = ("`bash tools/get_realworld.sh DIR` builds it from the public repositories "
                         "(network needed), then set MOVEPLAN_REALWORLD=DIR/src and "
                         "MOVEPLAN_NOETIC=DIR/peers/moveit_resources_noetic")


def pytest_terminal_summary(terminalreporter: Any, exitstatus: int, config: pytest.Config) -> None:
    """Say in one line that the real-world tier did not run, and how to get its workspace."""
    left_out = config.stash.get(_LEFT_OUT, 0)
    if left_out:
        terminalreporter.write_line(f"real-world tier not run ({left_out} tests): no MoveIt workspace at "
                                    f"{REALWORLD} or {NOETIC}; {_HOW_TO_GET_REALWORLD}")


@pytest.fixture(scope="session")
def ur10e_config() -> RobotConfig:
    return load_robot_config(UR10E)


@pytest.fixture(scope="session")
def ur10e(ur10e_config: RobotConfig) -> Robot:
    return Robot(ur10e_config)


class Cli:
    """Runs moveplan in-process and returns exit code, stdout, stderr (and parsed JSON if asked)."""

    def __init__(self) -> None:
        self.runner = CliRunner()

    def __call__(self, *args: Any) -> Any:
        result = self.runner.invoke(app, [str(a) for a in args])
        return result

    def json(self, *args: Any) -> tuple[int, dict[str, Any]]:
        result = self(*args, "--json")
        return result.exit_code, json.loads(result.stdout)


@pytest.fixture()
def cli() -> Cli:
    return Cli()


FILTERED_PLAN = ("import sys\nfrom pathlib import Path\nfrom moveplan.cli.options import setup_logging\n"
                 "from moveplan.core.bag import write_plan\nfrom moveplan.core.config.tasks import load_task\n"
                 "from moveplan.core.pipeline.plan import PlanFlags, plan, resolve_request\n"
                 "setup_logging(False, False)\n"
                 "request = resolve_request(load_task(Path(sys.argv[1])), PlanFlags(seed=0))\n"
                 "write_plan(Path(sys.argv[2]), plan(request, filter_after=0))\n")
"""Code for `python -c`: plan the task file argv[1] (seed 0) into argv[2], logging as `moveplan plan` does, with the
sphere filter built at once, as `moveplan benchmark` builds it, so that its caches are used: a one-shot plan builds it
only past FILTER_AFTER_STATES (core/pipeline/_checks.py)."""


def run_process(*args: Any) -> subprocess.CompletedProcess[str]:
    """Run moveplan as its own process, as a user's shell would."""
    return subprocess.run([sys.executable, "-m", "moveplan.cli.app", *map(str, args)],
                          capture_output=True, text=True, timeout=300)


def dense_peaks(trajectory: JointTrajectory, per_segment: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """Largest |velocity| and |acceleration| per joint, sampled densely (independent of peak_rates)."""
    knots = trajectory.times_s
    fractions = np.linspace(0.0, 1.0, per_segment + 1)
    times = np.unique((knots[:-1, None] + np.diff(knots)[:, None] * fractions).ravel())
    _, velocities, accelerations = sample(trajectory, times)
    return np.abs(velocities).max(axis=0), np.abs(accelerations).max(axis=0)


MSGS = ROOT / "core" / "bag" / "cdr" / "msgs" / "jazzy"
SCHEMAS = {
    "sensor_msgs/msg/JointState": (MSGS / "sensor_msgs__msg__JointState.msg").read_bytes(),
    "std_msgs/msg/String": (MSGS / "std_msgs__msg__String.msg").read_bytes(),
}


def write_bag(path: Path, messages: Iterable[tuple[str, str, int, bytes]], *,
              compression: CompressionType = CompressionType.ZSTD, chunk_size: int = 4096,
              use_chunking: bool = True) -> Path:
    """Write (topic, type, log time [ns], payload) messages as a ros2 MCAP file."""
    with path.open("wb") as stream:
        writer = Writer(stream, chunk_size=chunk_size, compression=compression,
                        use_chunking=use_chunking)
        writer.start("ros2", "test")
        channels: dict[str, int] = {}
        for topic, msgtype, log_time, data in messages:
            if topic not in channels:
                schema = writer.register_schema(msgtype, "ros2msg", SCHEMAS[msgtype])
                channels[topic] = writer.register_channel(topic, "cdr", schema)
            writer.add_message(channels[topic], log_time, data, log_time)
        writer.finish()
    return path


@pytest.fixture(scope="session")
def ray_address() -> Iterator[str]:
    """Return the address of a Ray cluster on this machine: a head and a worker node, one CPU each."""
    from ray.cluster_utils import Cluster

    os.environ["RAY_USAGE_STATS_ENABLED"] = "0"
    cluster = Cluster(initialize_head=True, head_node_args={"num_cpus": 1, "include_dashboard": False})
    cluster.add_node(num_cpus=1)
    try:
        cluster.wait_for_nodes()
        yield cluster.address
    finally:
        cluster.shutdown()
