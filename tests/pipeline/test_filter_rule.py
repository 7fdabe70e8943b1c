"""When a one-shot command builds the sphere filter (core/pipeline/_checks.py), and that it changes no plan.

Each case runs in a fresh interpreter: a process that has built one filter builds the next at once.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from conftest import ROOT

_PLAN = (
    "import sys\nfrom pathlib import Path\nfrom moveplan.core.bag import write_plan\n"
    "from moveplan.core.collision import compiled\nfrom moveplan.core.config.tasks import load_task\n"
    "from moveplan.core.pipeline.plan import PlanFlags, plan, planned, resolve_request\n"
    "def request(sample):\n"
    "    return resolve_request(load_task(Path('samples') / sample), PlanFlags(seed=0))\n"
)


def _run(code: str) -> str:
    """Return the last line a fresh interpreter running `code` (after _PLAN) prints."""
    result = subprocess.run([sys.executable, "-c", _PLAN + code], capture_output=True, text=True, cwd=ROOT,
                            timeout=600)
    assert result.returncode == 0, result.stderr
    return result.stdout.strip().splitlines()[-1]


def test_a_plan_is_the_same_file_with_the_filter_built_at_once_midway_or_never(tmp_path: Path) -> None:
    # The shelf sample asks about ~47,000 states: past 2,000 the filter is built in its first step.
    built = {}
    for name, after in (("never", 10**15), ("midway", 2_000), ("at once", 0)):
        out = tmp_path / f"{name}.mcap"
        built[name] = _run(f"planned_plan = plan(request('panda_shelf_bays.yaml'), filter_after={after})\n"
                           f"write_plan(Path({str(out)!r}), planned_plan)\nprint(compiled.kernels_loaded())")
    assert built == {"never": "False", "midway": "True", "at once": "True"}
    never = (tmp_path / "never.mcap").read_bytes()
    assert (tmp_path / "midway.mcap").read_bytes() == never
    assert (tmp_path / "at once.mcap").read_bytes() == never


def test_the_states_of_a_scripts_problems_count_together_toward_the_filter() -> None:
    # A script replans in changed scenes (a new problem each): the filter's build is paid once per process,
    # so the states asked about in every problem count toward it.
    code = ("plan(request('ur10e_joint_goals.yaml'), filter_after=10**15)\n"
            "asked = compiled.count_unfiltered(0)\n"
            "assert not compiled.kernels_loaded()\n"
            "_, second = planned(request('ur10e_joint_goals.yaml'), filter_after=asked + asked // 2)\n"
            "print(asked > 0, compiled.kernels_loaded(), type(second.checks.spheres).__name__)")
    assert _run(code) == "True True SphereFilter"


def test_a_motionbenchmaker_search_checks_the_same_motions_and_plans_the_same_file_with_the_filter_or_without(
    tmp_path: Path
) -> None:
    # The search stops at the convex hulls (conservative), so a state the spheres clear must be free under the
    # hulls, not only under the meshes: spheres fitted to panda_link6's mesh cleared states its hull touches
    # a shelf in, and this search checked 1,022 motions with the filter against 1,019 without it.
    problem = ROOT / "tests" / "data" / "mbm" / "problems" / "bookshelf_small_panda"
    flags = (f"PlanFlags(robot=Path({str(ROOT / 'tests' / 'data' / 'mbm' / 'panda_robot')!r}), "
             f"scene=Path({str(problem / 'scene0005.yaml')!r}), request=Path({str(problem / 'request0005.yaml')!r}), "
             "motion=MotionSettings(planner='RRTConnect'), seed=0)")
    checks = {}
    for name, after in (("never", 10**15), ("at once", 0)):
        checks[name] = _run(f"from moveplan.core.config import MotionSettings\n"
                            f"result, _ = planned(resolve_request(None, {flags}), filter_after={after})\n"
                            f"write_plan(Path({str(tmp_path / name)!r}), result)\n"
                            "print(int(sum(step.stats['checks'] for step in result.steps)))")
    assert checks["never"] == checks["at once"]
    assert (tmp_path / "never").read_bytes() == (tmp_path / "at once").read_bytes()
