"""What `moveplan --version` and `--help` tell a user before anything runs."""

from __future__ import annotations

import subprocess
import sys
from importlib.metadata import version


def _moveplan(*args: str) -> subprocess.CompletedProcess[str]:
    """Return a run of the moveplan command line in a fresh interpreter."""
    return subprocess.run([sys.executable, "-m", "moveplan.cli.app", *args], capture_output=True, text=True,
                          timeout=120)


def test_version_prints_the_installed_version_and_exits_0() -> None:
    result = _moveplan("--version")
    assert result.returncode == 0
    assert result.stdout == f"moveplan {version('moveplan')}\n"


def test_top_level_help_lists_every_exit_code() -> None:
    result = _moveplan("--help")
    assert result.returncode == 0
    text = " ".join(result.stdout.split())
    for code in ("0 success", "1 internal error", "2 usage error", "3 bad input file", "4 no plan",
                 "5 tolerances violated"):
        assert code in text
