"""README.md's example commands run as written from the clone, exit as the README says, and write outside it.

An example is a line of a plain fenced block that holds a `moveplan` command (with its `\\`
continuations and the comment lines under it), or an inline `moveplan ...` span with arguments
and no placeholder (`moveplan robot CONFIG` is a synopsis). The quick start's block holds no
line starting with `moveplan` and is left out. The README's scratch folder, /tmp/moveplan-demo,
becomes a folder under tmp_path; `~/ws/src` (the user's colcon workspace) becomes the real
MoveIt workspace of the realworld tier.
"""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import pytest
from conftest import REALWORLD, ROOT

README = ROOT / "README.md"
SCRATCH = "/tmp/moveplan-demo"
WORKSPACE = "~/ws/src"
OUTPUT_OPTIONS = {"-o", "--output", "--plot", "--csv", "--html"}
_FENCE = re.compile(r"^```(\w*)\n(.*?)^```", re.MULTILINE | re.DOTALL)
_INLINE = re.compile(r"`(moveplan [^`]+)`")
_PLACEHOLDER = re.compile(r"\b[A-Z][A-Z_.]+\b")
# The README marks an example that fails on purpose with "exits N" in its comment.
_EXPECTED_EXIT = re.compile(r"#.*\bexits (\d)\b", re.DOTALL)


@dataclass(frozen=True)
class Example:
    """One example command: its text as the README shows it (comments included) and its arguments."""

    text: str
    argv: tuple[str, ...]

    @property
    def expected_exit(self) -> int:
        """Return the exit code the README gives in the example's comment, 0 where it gives none."""
        found = _EXPECTED_EXIT.search(self.text)
        return int(found.group(1)) if found else 0


def readme_examples(text: str) -> list[Example]:
    """Return the README's example commands in the order they appear."""
    found: list[tuple[int, str]] = []
    for block in _FENCE.finditer(text):
        if block.group(1) or not any(line.startswith("moveplan ") for line in block.group(2).splitlines()):
            continue
        found.extend((block.start() + k, command) for k, command in enumerate(_commands(block.group(2))))
    # Blanked, not removed, so that positions keep the README's order.
    prose = _FENCE.sub(lambda block: " " * len(block.group(0)), text)
    for span in _INLINE.finditer(prose):
        command = " ".join(span.group(1).split())
        if len(command.split()) > 2 and not _PLACEHOLDER.search(command):
            found.append((span.start(), command))
    return [Example(command, tuple(shlex.split(command.replace("\\\n", " "), comments=True)))
            for _, command in sorted(found)]


def _commands(block: str) -> list[str]:
    """Return a block's commands, each joined across `\\` continuations with the comment lines under it."""
    commands: list[str] = []
    continued = False
    for line in block.splitlines():
        if continued:
            commands[-1] += "\n" + line
        elif line.strip().startswith("#") and commands:
            commands[-1] += "\n" + line
        elif line.strip():
            commands.append(line)
        continued = line.rstrip().endswith("\\")
    return commands


def _run_in_order(examples: list[Example], scratch: Path) -> tuple[list[str], list[str]]:
    """Run the examples one after another from the repository root; return the failures and the timings."""
    failures, timings = [], []
    for example in examples:
        argv = [arg.replace(SCRATCH, str(scratch)).replace(WORKSPACE, str(REALWORLD)) for arg in example.argv]
        if argv[0] == "moveplan":
            argv = [sys.executable, "-m", "moveplan.cli.app", *argv[1:]]
        start = time.perf_counter()
        result = subprocess.run(argv, cwd=ROOT, capture_output=True, text=True, timeout=300)
        timings.append(f"{time.perf_counter() - start:6.2f} s  {' '.join(example.argv)}")
        if result.returncode != example.expected_exit:
            last = (result.stderr.strip().splitlines() or ["(no stderr)"])[-1]
            failures.append(f"{' '.join(example.argv)}: exit {result.returncode}, README says "
                            f"{example.expected_exit}: {last}")
    return failures, timings


def _check_outputs_go_to_the_scratch_folder(examples: list[Example]) -> None:
    """Fail on an example that writes anywhere but the README's scratch folder."""
    for example in examples:
        for option, value in zip(example.argv, example.argv[1:], strict=False):
            if option in OUTPUT_OPTIONS:
                assert value.startswith(SCRATCH + "/"), f"{' '.join(example.argv)}: writes {value}"


def test_readme_examples_run_as_written_and_exit_as_documented(tmp_path: Path) -> None:
    examples = [e for e in readme_examples(README.read_text()) if WORKSPACE not in e.text]
    # The Commands block makes the scratch folder before any example writes into it.
    assert examples[0].argv == ("mkdir", "-p", SCRATCH)
    assert any(e.expected_exit == 5 for e in examples)
    _check_outputs_go_to_the_scratch_folder(examples)
    in_root = set(ROOT.iterdir())
    failures, timings = _run_in_order(examples, tmp_path / "moveplan-demo")
    assert not failures, "\n".join(failures + ["timings:"] + timings)
    assert set(ROOT.iterdir()) - in_root == set()


@pytest.mark.realworld
def test_readme_moveit_config_examples_run_on_the_real_workspace(tmp_path: Path) -> None:
    examples = [e for e in readme_examples(README.read_text()) if WORKSPACE in e.text]
    assert examples
    _check_outputs_go_to_the_scratch_folder(examples)
    # The Commands block's first line makes the scratch folder these examples write into.
    scratch = tmp_path / "moveplan-demo"
    scratch.mkdir()
    in_root = set(ROOT.iterdir())
    failures, timings = _run_in_order(examples, scratch)
    assert not failures, "\n".join(failures + ["timings:"] + timings)
    assert set(ROOT.iterdir()) - in_root == set()
