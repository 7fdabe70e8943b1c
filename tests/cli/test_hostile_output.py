"""Hostile output: -o naming an input, a link, a device or a folder; unwritable places; signals while
writing; a closed stdout; a damaged or full on-disk cache. A failed command writes and replaces nothing."""

from __future__ import annotations

import errno
import hashlib
import json
import os
import pickle
import resource
import shutil
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
from conftest import FILTERED_PLAN, ROOT, SAMPLES, UR10E, Cli

from moveplan.cli.errors import PIPE_CLOSED
from moveplan.core.bag.container.writer import atomic_file
from moveplan.core.collision import _cache
from moveplan.core.errors import InputError, UsageError
from moveplan.core.pipeline import benchmark as bench

SHIPPED_PLAN = SAMPLES / "recordings" / "tool_up_plan.mcap"  # no planner needed to execute it
QUICK_PLAN = ("--robot", UR10E, "--start-joints", "0,-1,-1,0,0,0", "--named", "home", "--seed", "0")


def snapshot(folder: Path) -> dict[str, Any]:
    """Return every entry of `folder` (hidden ones too) with what it is: the bytes of a file, a link's target."""
    found: dict[str, Any] = {}
    for entry in sorted(folder.rglob("*")):
        key = str(entry.relative_to(folder))
        if entry.is_symlink():
            found[key] = ("link", os.readlink(entry))
        elif entry.is_file():
            found[key] = ("file", hashlib.sha256(entry.read_bytes()).hexdigest())
        else:
            found[key] = ("dir",)
    return found


def one_line_error(result: Any) -> str:
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("moveplan: error: "), lines
    return lines[0]


@pytest.fixture()
def inputs(tmp_path: Path) -> Path:
    """A folder holding a plan, a task, a scene, a request and a controllers file."""
    shutil.copy(SHIPPED_PLAN, tmp_path / "p.mcap")
    shutil.copy(SAMPLES / "ur10e_joint_goals.yaml", tmp_path / "task.yaml")
    shutil.copy(SAMPLES / "ur10e_table_scene.yaml", tmp_path / "scene.yaml")
    shutil.copy(ROOT / "tests" / "data" / "mbm" / "bookshelf_request0093.yaml", tmp_path / "request.yaml")
    shutil.copy(UR10E / "ros2_controllers.yaml", tmp_path / "controllers.yaml")
    os.link(tmp_path / "p.mcap", tmp_path / "hardlink.mcap")
    return tmp_path


# -- 1. -o naming an input, a link, a device, a folder, nothing ------------------------------------------------


@pytest.mark.parametrize(("args", "output", "named"), [
    (["execute", "p.mcap", "--fake"], "p.mcap", "PLAN"),
    (["execute", "p.mcap", "--fake"], "hardlink.mcap", "PLAN"),  # another name of the same file
    (["execute", "p.mcap", "--fake", "--controllers", "controllers.yaml"], "controllers.yaml", "--controllers"),
    (["plan", "task.yaml"], "task.yaml", "TASK"),
    (["plan", "task.yaml", "--scene", "scene.yaml"], "scene.yaml", "--scene"),
    (["plan", "--robot", UR10E, "--request", "request.yaml"], "request.yaml", "--request"),
    (["plan", "--robot", UR10E, "--start-from", "p.mcap", "--named", "home"], "p.mcap", "--start-from"),
    (["plan", "--robot", UR10E / "moveplan.yaml", "--named", "home"], UR10E / "moveplan.yaml", "--robot"),
])
def test_an_output_naming_an_input_is_a_usage_error_and_replaces_nothing(
    cli: Cli, inputs: Path, monkeypatch: pytest.MonkeyPatch, args: list[Any], output: Any, named: str
) -> None:
    monkeypatch.chdir(inputs)
    before, config_before = snapshot(inputs), snapshot(UR10E)
    result = cli(*args, "-o", output)
    assert result.exit_code == 2, result.stderr
    line = one_line_error(result)
    assert f"-o '{output}'" in line and f"is also {named}" in line and "must not replace an input" in line
    assert snapshot(inputs) == before and snapshot(UR10E) == config_before


@pytest.mark.parametrize(("output", "named"), [
    ("scene.yaml", "the scene"),  # named by the task file, not on the command line
    (UR10E / "joint_limits.yaml", "the robot config's joint_limits"),
    (UR10E / "ur10e.urdf", "the robot config's urdf"),
])
def test_an_output_naming_a_file_the_task_or_config_names_replaces_nothing(
    cli: Cli, inputs: Path, monkeypatch: pytest.MonkeyPatch, output: Any, named: str
) -> None:
    monkeypatch.chdir(inputs)
    task = inputs / "task.yaml"
    task.write_text(task.read_text().replace("ur10e_table_scene.yaml", "scene.yaml")
                    .replace("../configs/ur10e", str(UR10E)))
    before, config_before = snapshot(inputs), snapshot(UR10E)
    result = cli("plan", task, "-o", output)
    assert result.exit_code == 2, result.stderr
    line = one_line_error(result)
    assert f"is also {named}" in line and "must not replace an input" in line
    assert snapshot(inputs) == before and snapshot(UR10E) == config_before


def test_benchmark_outputs_may_not_replace_a_problem_or_each_other(cli: Cli, tmp_path: Path) -> None:
    problem = shutil.copy(ROOT / "tests" / "data" / "mbm" / "bookshelf_scene0093.yaml", tmp_path / "scene0001.yaml")
    before = snapshot(tmp_path)
    result = cli("benchmark", problem, "--robot", UR10E, "--csv", problem)
    assert result.exit_code == 2 and "is also PROBLEMS" in one_line_error(result)
    result = cli("benchmark", problem, "--robot", UR10E, "--csv", tmp_path / "r.out", "--plot", tmp_path / "r.out")
    assert result.exit_code == 2 and "is also --csv" in one_line_error(result)
    assert snapshot(tmp_path) == before


def test_output_to_a_symbolic_link_is_refused_and_the_link_and_its_target_stay(
    cli: Cli, inputs: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(inputs)
    (inputs / "elsewhere.mcap").write_bytes(b"someone else's file")
    (inputs / "link.mcap").symlink_to("elsewhere.mcap")
    (inputs / "dangling.mcap").symlink_to("nowhere.mcap")
    before = snapshot(inputs)
    for link in ("link.mcap", "dangling.mcap"):
        result = cli("execute", "p.mcap", "--fake", "-o", link)
        assert result.exit_code == 2, result.stderr
        assert f"-o '{link}': is a symbolic link" in one_line_error(result)
    assert snapshot(inputs) == before


@pytest.mark.skipif(not Path("/dev/null").is_char_device(), reason="needs /dev/null")
def test_output_to_a_device_is_refused_even_as_root(cli: Cli, inputs: Path) -> None:
    before = os.stat("/dev/null")
    result = cli("execute", inputs / "p.mcap", "--fake", "-o", "/dev/null")
    assert result.exit_code == 2, result.stderr
    assert "-o '/dev/null': is a device or special file" in one_line_error(result)
    after = os.stat("/dev/null")
    assert stat.S_ISCHR(after.st_mode) and after.st_ino == before.st_ino
    assert not list(Path("/dev").glob(".null.*.tmp"))


def test_output_to_a_directory_or_an_empty_name_is_refused(
    cli: Cli, inputs: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(inputs)
    (inputs / "folder").mkdir()
    before = snapshot(inputs)
    for output, why in (("folder", "is a directory"), ("", "is empty (or '.')"), (".", "is empty (or '.')")):
        result = cli("execute", "p.mcap", "--fake", "-o", output)
        assert result.exit_code == 2, result.stderr
        assert why in one_line_error(result)
    assert snapshot(inputs) == before


def test_a_refused_output_is_a_json_error_document_with_json(cli: Cli, inputs: Path) -> None:
    code, document = cli.json("execute", inputs / "p.mcap", "--fake", "-o", inputs / "p.mcap")
    assert code == 2
    assert document["ok"] is False and document["error"]["exit_code"] == 2
    assert document["error"]["kind"] == "UsageError" and "must not replace an input" in document["error"]["message"]


def test_the_writer_itself_refuses_what_the_command_line_refuses(tmp_path: Path) -> None:
    (tmp_path / "link").symlink_to("target")
    for path in (tmp_path, tmp_path / "link", Path("/dev/null")):
        with pytest.raises(UsageError), atomic_file(path):
            pytest.fail("opened")
    assert snapshot(tmp_path) == {"link": ("link", "target")}


# -- 2. unwritable places: bad input (exit 3), one line naming the path ------------------------------------------


@pytest.mark.parametrize("where", ["under_a_file", "proc"])
def test_an_unwritable_output_is_bad_input_naming_the_path(
    cli: Cli, inputs: Path, where: str
) -> None:
    # Tests run as root, where a chmod 0o555 folder is still writable: a path under a file, and
    # /proc (which refuses new files even to root), fail the same way a read-only mount does.
    output = inputs / "p.mcap" / "out.mcap" if where == "under_a_file" else Path("/proc/moveplan-test/out.mcap")
    before = snapshot(inputs)
    result = cli("execute", inputs / "p.mcap", "--fake", "-o", output)
    assert result.exit_code == 3, result.stderr
    line = one_line_error(result)
    assert f"{output}: cannot write:" in line and "internal error" not in line
    assert snapshot(inputs) == before


def test_benchmark_files_are_written_atomically_and_unwritable_ones_are_bad_input(tmp_path: Path) -> None:
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="cannot write: Not a directory"):
        bench.write_csv([], tmp_path / "file" / "runs.csv")
    with pytest.raises(UsageError, match="is a directory"):
        bench.write_csv([], tmp_path)
    bench.write_csv([], tmp_path / "runs.csv")
    assert (tmp_path / "runs.csv").read_text().startswith("problem,")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file", "runs.csv"]


def test_an_interrupted_write_leaves_the_old_file_and_no_temporary(tmp_path: Path) -> None:
    target = tmp_path / "out.csv"
    target.write_text("old")
    with pytest.raises(KeyboardInterrupt), atomic_file(target) as stream:
        stream.write(b"half")
        raise KeyboardInterrupt
    assert target.read_text() == "old" and sorted(tmp_path.iterdir()) == [target]


def test_a_stale_temporary_file_of_this_process_id_is_no_obstacle(cli: Cli, inputs: Path) -> None:
    stale = inputs / f".out.mcap.{os.getpid()}.tmp"
    stale.write_bytes(b"left by a killed run")
    result = cli("execute", inputs / "p.mcap", "--fake", "-o", inputs / "out.mcap")
    assert result.exit_code == 0, result.stderr
    assert stale.read_bytes() == b"left by a killed run"  # not ours: left alone
    assert not [p for p in inputs.glob(".out.mcap.*.tmp") if p != stale]
    assert (inputs / "out.mcap").stat().st_size > 0


@pytest.mark.parametrize(("args", "output"), [
    (["execute", "p.mcap", "--fake"], "out.mcap"),
    (["tune-pid", "p.mcap", "--controllers", SAMPLES / "ur10e_velocity_controllers.yaml"], "tuned.yaml"),
])
def test_the_output_gets_the_users_umask_permissions(
    cli: Cli, inputs: Path, args: list[Any], output: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(inputs)
    old = os.umask(0o027)
    try:
        result = cli(*args, "-o", output, "-q")
    finally:
        os.umask(old)
    assert result.exit_code == 0, result.stderr
    assert stat.S_IMODE((inputs / output).stat().st_mode) == 0o640
    assert not list(inputs.glob(".*.tmp"))


# -- 3. signals while writing: cleaned up like Ctrl-C, exit 128 + signal ------------------------------------------

# moveplan's own entry point, with the file write slowed down: it announces that it has started
# writing (the temporary file exists then), and waits there to be signalled.
_SLOW_WRITER = """
import sys, time
from pathlib import Path
from moveplan.core.bag.container._mcap_writer import McapWriter
from moveplan.cli.app import main

started = Path(sys.argv[1])
def slow_metadata(self, *args, **kwargs):
    started.touch()
    time.sleep(120)
McapWriter.add_metadata = slow_metadata
sys.argv = ["moveplan", *sys.argv[2:]]
main()
"""


def _signals_by_default() -> None:
    """Give the child the default SIGINT and SIGHUP: a suite run under nohup or as a background job ignores them.

    moveplan leaves an ignored signal ignored, as a nohup'd command expects (cli/errors.py handle_signals).
    """
    for signum in (signal.SIGINT, signal.SIGHUP):
        signal.signal(signum, signal.SIG_DFL)


@pytest.mark.parametrize(("signum", "command"), [
    (signal.SIGTERM, "plan"), (signal.SIGTERM, "execute"), (signal.SIGHUP, "execute"), (signal.SIGINT, "execute"),
])
def test_a_signal_while_writing_removes_the_temporary_file_and_exits_128_plus_signal(
    tmp_path: Path, signum: int, command: str
) -> None:
    out = tmp_path / "out" / "result.mcap"
    out.parent.mkdir()
    args = [*QUICK_PLAN] if command == "plan" else [SHIPPED_PLAN, "--fake"]
    started = tmp_path / "started"
    process = subprocess.Popen(
        [sys.executable, "-c", _SLOW_WRITER, started, command, *map(str, args), "-o", out],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=_signals_by_default,
    )
    try:
        deadline = time.monotonic() + 120
        while not started.exists():
            assert process.poll() is None, process.communicate()
            assert time.monotonic() < deadline, "the write never started"
            time.sleep(0.05)
        assert len(list(out.parent.glob(".result.mcap.*.tmp"))) == 1  # writing: the temporary file is there
        process.send_signal(signum)
        _, stderr = process.communicate(timeout=60)
    finally:
        process.kill()
    assert process.returncode == 128 + signum, stderr
    lines = stderr.strip().splitlines()
    assert lines[-1].startswith("moveplan: error: interrupted"), stderr
    assert "Traceback" not in stderr
    assert list(out.parent.iterdir()) == []  # neither the output nor its temporary file


# -- 5. a closed stdout: exit 141 quietly -----------------------------------------------------------------------


@pytest.mark.parametrize("args", [
    ["inspect", SHIPPED_PLAN], ["inspect", SHIPPED_PLAN, "--json"], ["robot", UR10E],
    ["execute", SHIPPED_PLAN, "--fake", "--json"],
])
def test_a_reader_that_closed_stdout_gets_exit_141_and_no_traceback(args: list[Any]) -> None:
    reading, writing = os.pipe()
    os.close(reading)  # as `| head -1` does once it has its line
    try:
        result = subprocess.run([sys.executable, "-m", "moveplan.cli.app", *map(str, args)],
                                stdout=writing, stderr=subprocess.PIPE, text=True, timeout=300)
    finally:
        os.close(writing)
    assert result.returncode == PIPE_CLOSED == 141
    assert result.stderr == ""


@pytest.mark.parametrize("args", [["inspect", SHIPPED_PLAN], ["robot", UR10E, "--json"]])
def test_a_full_stdout_is_one_line_and_exit_3_without_traceback(args: list[Any]) -> None:
    with open("/dev/full", "w") as full:  # every write fails with ENOSPC, as on a full disk under `> file`
        result = subprocess.run([sys.executable, "-m", "moveplan.cli.app", *map(str, args)],
                                stdout=full, stderr=subprocess.PIPE, text=True, timeout=300)
    assert result.returncode == 3
    assert result.stderr == "moveplan: error: cannot write to standard output: No space left on device\n"


# -- 4. the on-disk cache: versioned, checksummed, rebuilt with one warning, no partial files ----------------------


@pytest.fixture()
def cache_entry(tmp_path: Path) -> Path:
    where = tmp_path / "entry.pickle"
    _cache.write(where, ("tables", [1.5, 2.5], {"key": b"value"}))
    return where


def test_a_cache_entry_reads_back_what_was_written(cache_entry: Path) -> None:
    assert _cache.read(cache_entry, tuple) == ("tables", [1.5, 2.5], {"key": b"value"})
    assert cache_entry.read_bytes().startswith(b"moveplan-cache %d " % _cache.FORMAT)
    assert sorted(p.name for p in cache_entry.parent.iterdir()) == ["entry.pickle"]


def test_every_flipped_byte_of_a_cache_entry_is_caught_with_one_warning(
    cache_entry: Path, caplog: pytest.LogCaptureFixture
) -> None:
    data = cache_entry.read_bytes()
    for index in range(len(data)):
        for flip in (0x01, 0x80):
            cache_entry.write_bytes(data[:index] + bytes([data[index] ^ flip]) + data[index + 1:])
            caplog.clear()
            assert _cache.read(cache_entry, tuple) is None, (index, flip)
            assert len(caplog.records) == 1 and caplog.records[0].levelname == "WARNING"
            assert str(cache_entry) in caplog.records[0].getMessage()


class _Broken:
    """Pickles to a call that raises TypeError when loaded, as an entry pickled by another version can."""

    def __reduce__(self) -> tuple[Any, ...]:
        return (int, ("1", 2, 3, 4))


@pytest.mark.parametrize("content", [
    b"", b"not a pickle", pickle.dumps(("an old", "format entry")),
    b"moveplan-cache 1 " + hashlib.sha256(b"x").hexdigest().encode() + b"\nx",  # another format
    b"moveplan-cache %d %s\n" % (_cache.FORMAT, hashlib.sha256(pickle.dumps(_Broken())).hexdigest().encode())
    + pickle.dumps(_Broken()),  # a valid checksum over a pickle that raises TypeError
    b"moveplan-cache %d %s\n" % (_cache.FORMAT, hashlib.sha256(pickle.dumps([1])).hexdigest().encode())
    + pickle.dumps([1]),  # the wrong type
])
def test_an_untrustworthy_cache_entry_is_rebuilt_with_one_warning(
    tmp_path: Path, caplog: pytest.LogCaptureFixture, content: bytes
) -> None:
    where = tmp_path / "entry.pickle"
    where.write_bytes(content)
    assert _cache.read(where, tuple) is None
    assert len(caplog.records) == 1 and "recomputing it" in caplog.records[0].getMessage()
    _cache.write(where, ("rebuilt",))
    caplog.clear()
    assert _cache.read(where, tuple) == ("rebuilt",) and not caplog.records


def test_a_missing_entry_is_computed_silently(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    assert _cache.read(tmp_path / "none.pickle", tuple) is None
    assert not caplog.records


def test_a_cache_write_on_a_full_disk_is_skipped_and_leaves_no_partial_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    real_fdopen = os.fdopen

    class Full:
        def __init__(self, descriptor: int, mode: str) -> None:
            self.stream = real_fdopen(descriptor, mode)

        def __enter__(self) -> Full:
            return self

        def __exit__(self, *exc: object) -> None:
            self.stream.close()

        def write(self, data: bytes) -> int:
            raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(_cache.os, "fdopen", Full)
    for _ in range(3):
        _cache.write(tmp_path / "entry.pickle", ("value",))
    assert list(tmp_path.iterdir()) == []


def test_partial_files_left_by_killed_runs_are_swept_when_the_entry_is_written(tmp_path: Path) -> None:
    old = tmp_path / "entry.pickle.1234.partial"  # the old naming, left by a run killed on a full disk
    young = tmp_path / "entry.pickle.k3j4h5.partial"  # perhaps another run writing right now
    for leftover in (old, young):
        leftover.write_bytes(b"half")
    os.utime(old, (time.time() - 7200, time.time() - 7200))
    _cache.write(tmp_path / "entry.pickle", ("value",))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["entry.pickle", young.name]


# `moveplan benchmark` builds the sphere filter at once, so it reads and writes the cache (FILTERED_PLAN too).
CACHE_BENCHMARK = ("benchmark", ROOT / "tests" / "data" / "mbm" / "problems" / "box_panda", "--robot",
                   ROOT / "tests" / "data" / "mbm" / "panda_robot", "--count", "1")


def _plan_process(out: Path, cache: Path, limit: int | None = None, args: tuple[Any, ...] = QUICK_PLAN,
                  filtered: bool = False) -> subprocess.Popen[str]:
    """Return a running `moveplan plan` of `args` to `out` (`filtered`: FILTERED_PLAN), caching in `cache`."""
    def limited() -> None:
        if limit is not None:  # a full disk: writing past `limit` bytes fails with EFBIG (Python ignores SIGXFSZ)
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    command = (["-c", FILTERED_PLAN, str(SAMPLES / "panda_shelf_bays.yaml"), str(out)] if filtered else
               ["-m", "moveplan.cli.app", "plan", *map(str, args), "-o", str(out)])
    return subprocess.Popen([sys.executable, *command], env={**os.environ, "MOVEPLAN_CACHE_DIR": str(cache)},
                            preexec_fn=limited, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def test_a_full_disk_fails_the_plan_as_bad_input_and_leaves_no_partial_files(tmp_path: Path) -> None:
    (tmp_path / "out").mkdir()
    process = _plan_process(tmp_path / "out" / "plan.mcap", tmp_path / "cache", limit=4096)
    _, stderr = process.communicate(timeout=300)
    assert process.returncode == 3, stderr
    assert "plan.mcap: cannot write: File too large" in stderr.strip().splitlines()[-1]
    assert list((tmp_path / "out").iterdir()) == []
    assert not list((tmp_path / "cache").glob("*partial*"))


def test_concurrent_cold_cache_runs_agree_byte_for_byte_with_warm_and_repaired_caches(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    runs = [_plan_process(tmp_path / f"cold{i}.mcap", cache, filtered=True) for i in range(3)]
    for process in runs:
        _, stderr = process.communicate(timeout=300)
        assert process.returncode == 0, stderr
        assert "WARNING" not in stderr
    assert not list(cache.glob("*partial*"))
    entries = sorted(cache.iterdir())
    assert entries and all(_cache.read(e, object) is not None for e in entries)
    for entry in entries:  # damage every entry: the next run rebuilds each with one warning
        data = bytearray(entry.read_bytes())
        data[len(data) // 2] ^= 0x10
        entry.write_bytes(bytes(data))
    repaired = _plan_process(tmp_path / "repaired.mcap", cache, filtered=True)
    _, stderr = repaired.communicate(timeout=300)
    assert repaired.returncode == 0, stderr
    assert stderr.count("cannot be used (checksum mismatch") == len(entries), stderr
    warm = _plan_process(tmp_path / "warm.mcap", cache, filtered=True)
    _, stderr = warm.communicate(timeout=300)
    assert warm.returncode == 0 and "WARNING" not in stderr, stderr
    reference = (tmp_path / "cold0.mcap").read_bytes()
    for name in ("cold1", "cold2", "repaired", "warm"):
        assert (tmp_path / f"{name}.mcap").read_bytes() == reference, name


def test_json_stays_clean_when_the_cache_warns(tmp_path: Path) -> None:
    cache = tmp_path / "cache"
    cache.mkdir()
    command = [sys.executable, "-m", "moveplan.cli.app", *map(str, CACHE_BENCHMARK)]
    env = {**os.environ, "MOVEPLAN_CACHE_DIR": str(cache)}
    subprocess.run([*command, "-q"], env=env, check=True, capture_output=True, timeout=300)
    assert list(cache.iterdir())
    for entry in cache.iterdir():
        entry.write_bytes(b"garbage")
    result = subprocess.run([*command, "--json"], env=env, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["ok"] is True
    assert "WARNING" in result.stderr
