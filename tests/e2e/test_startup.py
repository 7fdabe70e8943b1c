"""Start-up: what `moveplan` imports before it works, and the notice of one-time work on a cold cache."""

from __future__ import annotations

import logging
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _run(code: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    """Return a fresh interpreter's run of `code`."""
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT,
                          env={**os.environ, **(env or {})}, timeout=300)


def _cli(argv: list[str], then: str) -> str:
    """Return code for a fresh interpreter: `moveplan ARGV` run to success, then the statement `then`."""
    return (f"import sys\nsys.argv = ['moveplan', *{argv!r}]\nfrom moveplan.cli.app import main\ntry:\n    main()\n"
            f"except SystemExit as exc:\n    assert not exc.code, exc.code\n{then}")


def test_help_imports_no_numba_pinocchio_or_scipy() -> None:
    result = _run("import sys\nfrom moveplan.cli.app import app\nfrom typer.testing import CliRunner\n"
                  "assert CliRunner().invoke(app, ['--help']).exit_code == 0\n"
                  "print(sorted(m for m in ('numba', 'pinocchio', 'scipy', 'ompl', 'mcap') if m in sys.modules))")
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"


def test_single_joint_goal_plan_imports_no_numba_scipy_or_pydantic(tmp_path: Path) -> None:
    code = _cli(["plan", "--robot", "ur10e", "--start-named", "home", "--joints", "0.5,-1.2,-1.8,0,1.57,0", "-o",
                 str(tmp_path / "plan.mcap"), "-q"],
                "print(sorted(m for m in ('numba', 'scipy', 'pydantic') if m in sys.modules))")
    result = _run(code)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[]"
    assert (tmp_path / "plan.mcap").stat().st_size > 0


def _compile_kernels() -> None:
    """Have numba compile (or load) the filter's kernels into its cache: a benchmark builds the filter at once."""
    subprocess.run([sys.executable, "-m", "moveplan.cli.app", "benchmark", "tests/data/mbm/problems", "--robot",
                    "tests/data/mbm/panda_robot", "--count", "1", "-q"], check=True, cwd=ROOT, timeout=600)


def test_cold_cache_announces_sphere_fitting_once(tmp_path: Path) -> None:
    _compile_kernels()  # the compilation's own notice aside
    cache = tmp_path / "cache"
    # A benchmark builds the sphere filter at once; a one-shot plan only past FILTER_AFTER_STATES (and the next test).
    command = [sys.executable, "-m", "moveplan.cli.app", "benchmark", "tests/data/mbm/problems/box_panda",
               "--robot", "tests/data/mbm/panda_robot", "--count", "1"]
    env = {**os.environ, "MOVEPLAN_CACHE_DIR": str(cache)}
    cold = subprocess.run(command, capture_output=True, text=True, cwd=ROOT, env=env, timeout=600)
    assert cold.returncode == 0, cold.stderr
    assert f"moveplan: fitting collision spheres for panda (once per robot; cached in {cache})" in cold.stderr
    warm = subprocess.run(command, capture_output=True, text=True, cwd=ROOT, env=env, timeout=600)
    assert warm.returncode == 0, warm.stderr
    assert "fitting collision spheres" not in warm.stderr


def test_fresh_machine_plans_without_compiling_the_kernels(tmp_path: Path) -> None:
    """Empty numba and moveplan caches: a plan that checks far fewer states than a compilation is worth stays
    with coal, says nothing, imports no numba, and writes the same file as a machine with everything cached."""
    _compile_kernels()
    warm = tmp_path / "warm.mcap"
    subprocess.run([sys.executable, "-m", "moveplan.cli.app", "plan", "samples/panda_shelf_bays.yaml", "-o", str(warm)],
                   check=True, cwd=ROOT, capture_output=True, timeout=600)
    cold = tmp_path / "cold.mcap"
    code = _cli(["plan", "samples/panda_shelf_bays.yaml", "-o", str(cold)],
                "print(sorted(m for m in ('numba', 'scipy') if m in sys.modules))")
    result = _run(code, {"NUMBA_CACHE_DIR": str(tmp_path / "numba"), "MOVEPLAN_CACHE_DIR": str(tmp_path / "cache")})
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip().splitlines()[-1] == "[]"
    assert result.stderr == ""
    assert cold.read_bytes() == warm.read_bytes()


def test_quiet_cold_cache_prints_no_notice(tmp_path: Path) -> None:
    command = [sys.executable, "-m", "moveplan.cli.app", "plan", "samples/panda_shelf_bays.yaml",
               "-o", str(tmp_path / "plan.mcap"), "-q"]
    env = {**os.environ, "MOVEPLAN_CACHE_DIR": str(tmp_path / "cache")}
    result = subprocess.run(command, capture_output=True, text=True, cwd=ROOT, env=env, timeout=600)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""


def test_compilation_is_announced_only_when_the_kernels_are_not_compiled(caplog: pytest.LogCaptureFixture) -> None:
    from moveplan.core.collision._cache import announce_compilation

    with caplog.at_level(logging.INFO, logger="moveplan.core.collision._cache"):
        announce_compilation("loading cached kernels", compiled=True)
        announce_compilation("compiling kernels", compiled=False)
    assert [r.getMessage() for r in caplog.records] == ["compiling kernels"]


_FILTERED_PLAN = (
    "from pathlib import Path\nfrom moveplan.cli.options import setup_logging\n"
    "from moveplan.core.collision import compiled\nfrom moveplan.core.config.tasks import load_task\n"
    "from moveplan.core.pipeline.plan import PlanFlags, plan, resolve_request\n"
    "setup_logging(False, False)\n"
    "plan(resolve_request(load_task(Path('samples/ur10e_joint_goals.yaml')), PlanFlags()), filter_after=0)\n"
    "assert compiled.kernels_loaded(), 'no sphere filter was built'\n")
_COMPILING = "moveplan: compiling the collision kernels (once per install)"
_SLOW_LOAD = (  # the filter's first kernel call takes 1.5 s longer, as on a loaded machine
    "import time\nfrom moveplan.core.timing import _twins\nfastest, calls = _twins.compiled_fastest_speeds, []\n"
    "def fastest_speeds(*args, **kwargs):\n    if not calls:\n        time.sleep(1.5)\n    calls.append(1)\n"
    "    return fastest(*args, **kwargs)\n_twins.compiled_fastest_speeds = fastest_speeds\n")


def test_a_one_shot_plan_builds_the_filter_at_once_and_imports_no_numba(tmp_path: Path) -> None:
    """Kernels compiled ahead of time and the robot's spheres cached: a fresh process has the filter in milliseconds."""
    _compile_kernels()  # the benchmark fits the Panda's spheres and tables too
    problem = "tests/data/mbm/problems/box_panda"
    code = _cli(["plan", "--robot", "tests/data/mbm/panda_robot", "--scene", f"{problem}/scene0001.yaml", "--request",
                 f"{problem}/request0001.yaml", "-o", str(tmp_path / "plan.mcap"), "-q"],
                "from moveplan.core.collision import compiled\n"
                "print(compiled.kernels_loaded(), 'numba' in sys.modules)")
    result = _run(code)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "True False"


def test_without_a_c_compiler_numbas_jit_compiles_once_announced_and_plans_the_same(tmp_path: Path) -> None:
    """No module compiled ahead of time: numba's JIT runs the same functions, the same file. Its compilation is
    announced on an empty numba cache and not once it holds the kernels, however slow their load (the cache
    decides, not the clock); the failed build is said once and not tried again."""
    _compile_kernels()
    native, jit = tmp_path / "native.mcap", tmp_path / "jit.mcap"
    writing = _FILTERED_PLAN.replace("plan(resolve_request", "planned = plan(resolve_request") + (
        "import sys\nfrom moveplan.core.bag import write_plan\nwrite_plan(Path(sys.argv[1]), planned)\n"
        "print('numba' in sys.modules)\n")
    no_compiler = {"NUMBA_CACHE_DIR": str(tmp_path / "numba"), "CC": str(tmp_path / "no-such-compiler")}
    runs = []
    cases = ((writing, native, {}), (writing, jit, no_compiler), (_SLOW_LOAD + writing, jit, no_compiler))
    for code, target, env in cases:
        result = subprocess.run([sys.executable, "-c", code, str(target)], capture_output=True, text=True, cwd=ROOT,
                                env={**os.environ, **env}, timeout=600)
        assert result.returncode == 0, result.stderr
        lines = result.stderr.splitlines()
        runs.append((result.stdout.strip(), lines.count(_COMPILING), sum("not compiled ahead of time" in line
                                                                          for line in lines)))
    # numba is imported only without the compiled modules; the failed builds (collision's, timing's) said once.
    assert runs == [("False", 0, 0), ("True", 1, 1), ("True", 0, 0)]
    assert jit.read_bytes() == native.read_bytes()


def test_inspect_reads_a_plans_end_states_without_loading_kinematics(tmp_path: Path) -> None:
    """A plan file records where each step ends: `inspect` gives them without pinocchio (start-up in CI loops)."""
    plan = tmp_path / "plan.mcap"
    subprocess.run([sys.executable, "-m", "moveplan.cli.app", "plan", "samples/ur10e_joint_goals.yaml", "-o", str(plan),
                    "-q"], check=True, cwd=ROOT, timeout=300)
    code = ("import sys, json, io, contextlib\nsys.argv = ['moveplan', 'inspect', " + repr(str(plan)) + ", '--json']\n"
            "from moveplan.cli.app import main\nout = io.StringIO()\ntry:\n    with contextlib.redirect_stdout(out):\n"
            "        main()\nexcept SystemExit as exc:\n    assert not exc.code\n"
            "steps = json.loads(out.getvalue())['plan']['steps']\n"
            "print(json.dumps([s['end_state']['pose']['link'] for s in steps]), 'pinocchio' in sys.modules)")
    result = _run(code)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == '["tool0", "tool0", "tool0"] False'


def test_plan_execute_and_check_never_load_numpy_ma(tmp_path: Path) -> None:
    """np.median and np.unique import numpy.ma on their first call: 10-40 ms of a command that needs none of it."""
    plan, executed = tmp_path / "plan.mcap", tmp_path / "executed.mcap"
    commands = [["plan", "samples/ur10e_tool_up.yaml", "-o", str(plan)],
                ["execute", str(plan), "--fake", "-o", str(executed)],
                ["check-tolerances", str(plan), str(executed)]]
    for argv in commands:
        code = _cli(argv, "print('numpy.ma' in sys.modules)")
        result = _run(code)
        assert result.returncode == 0, result.stderr
        assert result.stdout.strip().splitlines()[-1] == "False", argv[0]


_LEAVE = ("import atexit, sys, threading, time\n"
          "atexit.register(lambda: print('exit handler ran', flush=True))\n"
          "sys.argv = ['moveplan', *{argv!r}]\n"
          "{before}\n"
          "from moveplan.cli.app import run\nrun()\n")


@pytest.mark.parametrize(("argv", "code"), [(["--version"], 0), (["inspect", "/no/such.mcap"], 3), (["--bogus"], 2)])
def test_the_program_leaves_with_its_exit_code_its_output_and_its_exit_handlers(argv: list[str], code: int) -> None:
    result = _run(_LEAVE.format(argv=argv, before=""))
    assert result.returncode == code, result.stderr
    assert result.stdout.rstrip().endswith("exit handler ran")
    assert (code == 0) == ("moveplan" in result.stdout), result.stdout


def test_the_program_waits_for_a_thread_still_working() -> None:
    # Leaving without the interpreter's teardown would cut the thread off before it prints.
    before = "threading.Thread(target=lambda: (time.sleep(0.5), print('thread finished', flush=True))).start()"
    result = _run(_LEAVE.format(argv=["--version"], before=before))
    assert result.returncode == 0, result.stderr
    assert "thread finished" in result.stdout
