"""Shared fixtures: the repo's shipped configs and samples, robots loaded once, CLI runners."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from moveplan.cli.app import app
from moveplan.core.config import RobotConfig, load_robot_config
from moveplan.core.robot import Robot

ROOT = Path(__file__).resolve().parents[1]
UR10E = ROOT / "configs" / "ur10e"
SAMPLES = ROOT / "samples"
TABLE_SCENE = SAMPLES / "ur10e_table_scene.yaml"


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


def run_process(*args: Any) -> subprocess.CompletedProcess[str]:
    """Run moveplan as its own process, as a user's shell would."""
    return subprocess.run([sys.executable, "-m", "moveplan.cli.app", *map(str, args)],
                          capture_output=True, text=True, timeout=300)
