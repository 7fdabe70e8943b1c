"""Items per second of `check-tolerances --manifest` on a night's recordings, against a shell loop of single checks.

Run from the repository root with moveplan installed:
    python benchmarks/fleet.py [--items 1000] [--minutes 1] [--jobs 1,2] [--engines local,ray] [--loop 10]
        [--repeats 3]

The recording is an executed file of a UR10e task alternating two joint goals for about
`--minutes` (planned and executed once, kept under /tmp/moveplan_fleet_<minutes>/); the night's
`--items` recordings are hard links to it, so that they cost no disk and the figures are the
check's, not the disk's (each item is still read and hashed from its own path). Each batch is
the whole command, `moveplan check-tolerances --manifest M --jobs N -q`, timed `--repeats`
times (median); the shell loop runs `--loop` single checks, one process each, and its median
per item is scaled to `--items`. For the Ray engine (`--engine ray`, needs `moveplan[ray]`) the
script starts a cluster on this machine, a head and a worker node of one CPU each (stopped at
the end), and runs the same batches with `--jobs N` actors. Machines are shared and noisy:
compare ratios, run it twice.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

MOVEPLAN = [sys.executable, "-m", "moveplan.cli.app"]
GOALS = ("[0.6, -1.2, -1.8, 0.0, 1.57, 0.0]", "[-0.6, -1.6, -1.2, 0.3, 1.2, 0.4]")
STEP_S = 2.5  # about what one of the task's steps lasts at the task's scaling


def recording(folder: Path, minutes: float) -> tuple[Path, Path]:
    """Return a plan file and its executed file of about `minutes`, made once in `folder`."""
    plan, executed = folder / "plan.mcap", folder / "executed.mcap"
    if plan.exists() and executed.exists():
        return plan, executed
    folder.mkdir(parents=True, exist_ok=True)
    steps = max(2, round(60.0 * minutes / STEP_S))
    task = folder / "task.yaml"
    task.write_text("robot: ur10e\nsteps:\n" + "".join(
        f"  - {{name: move{k}, joints: {GOALS[k % 2]}}}\n" for k in range(steps)))
    subprocess.run([*MOVEPLAN, "plan", str(task), "-o", str(plan), "-q"], check=True)
    subprocess.run([*MOVEPLAN, "execute", str(plan), "--fake", "-o", str(executed), "-q"], check=True)
    return plan, executed


def night(folder: Path, plan: Path, executed: Path, items: int) -> Path:
    """Return a manifest of `items` recordings, each a hard link to `executed`."""
    links = folder / f"night_{items}"
    links.mkdir(exist_ok=True)
    rows = ["plan,recording,cell"]
    for k in range(items):
        link = links / f"rec_{k:05d}.mcap"
        if not link.exists():
            os.link(executed, link)
        rows.append(f"{plan},{link},cell-{k % 7}")
    manifest = folder / f"night_{items}.csv"
    manifest.write_text("\n".join(rows) + "\n")
    return manifest


def timed(command: list[str]) -> float:
    """Return the wall time [s] of running `command` to its end (exit 0 or 5: a verdict either way)."""
    began = time.perf_counter()
    result = subprocess.run(command, stdout=subprocess.DEVNULL, check=False)
    if result.returncode not in (0, 5):
        raise SystemExit(f"{' '.join(command)} exited {result.returncode}")
    return time.perf_counter() - began


def main() -> None:
    """Time the batch per worker count and the shell loop; print items per second and the ratios."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--items", type=int, default=1000)
    parser.add_argument("--minutes", type=float, default=1.0)
    parser.add_argument("--jobs", default="1,2")
    parser.add_argument("--engines", default="local,ray")
    parser.add_argument("--loop", type=int, default=10)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    folder = Path(f"/tmp/moveplan_fleet_{args.minutes:g}")
    plan, executed = recording(folder, args.minutes)
    manifest = night(folder, plan, executed, args.items)
    size = executed.stat().st_size / 1e6
    print(f"{args.items} recordings of {args.minutes:g} min ({size:.1f} MB each, hard links), plan {plan}")
    single = [timed([*MOVEPLAN, "check-tolerances", str(plan), str(executed), "-q"]) for _ in range(args.loop)]
    loop_s = statistics.median(single) * args.items
    print(f"shell loop of single checks: {statistics.median(single):.3f} s an item (median of {args.loop}), "
          f"{loop_s:.0f} s for {args.items}: {args.items / loop_s:.2f} items/s")
    for engine in args.engines.split(","):
        with cluster(engine) as address:
            first = None
            for jobs in (int(j) for j in args.jobs.split(",")):
                command = [*MOVEPLAN, "check-tolerances", "--manifest", str(manifest), "--jobs", str(jobs), "-q",
                           "--engine", engine, *(["--ray-address", address] if address else [])]
                wall = statistics.median(timed(command) for _ in range(args.repeats))
                first = first or wall
                print(f"{engine} engine, {jobs} worker(s): {wall:.1f} s (median of {args.repeats}), "
                      f"{args.items / wall:.2f} items/s; {first / wall:.2f}x one worker, "
                      f"{loop_s / wall:.1f}x the shell loop")


@contextmanager
def cluster(engine: str) -> Iterator[str | None]:
    """Yield a Ray cluster's address for engine "ray" (a head and a worker node here, one CPU each), else None."""
    if engine != "ray":
        yield None
        return
    from ray.cluster_utils import Cluster

    os.environ["RAY_USAGE_STATS_ENABLED"] = "0"
    ray_cluster = Cluster(initialize_head=True, head_node_args={"num_cpus": 1, "include_dashboard": False})
    ray_cluster.add_node(num_cpus=1)
    try:
        ray_cluster.wait_for_nodes()
        yield ray_cluster.address
    finally:
        ray_cluster.shutdown()


if __name__ == "__main__":
    main()
