"""Peak memory of `moveplan execute --fake` against the number of plan steps and the controller's update rate.

Run from the repository root with moveplan installed:
    python benchmarks/execute_memory.py [--steps 100,400] [--rates 1000,10000] [--plant mirror]
        [--scaling 1.0] [--no-json] [--command "python other/moveplan_entry.py"]

It writes, under a temporary folder (never in the repository), a UR10e task file per step
count that alternates two joint goals (velocity and acceleration scaling `--scaling`), plans
it once with `moveplan plan --seed 0`, and a copy of configs/ur10e/ros2_controllers.yaml per
update rate. Then, per step count and rate, it runs `moveplan execute PLAN --fake
--controllers CTL -o EXECUTED.mcap --quiet` and `... --json` (no output file) in a child
process each, and prints the child's peak resident set size (what `/usr/bin/time -v` reports
as "Maximum resident set size"), its wall time, the control cycles executed and the executed
file's size. Execution memory should not grow with the steps or the rate: compare the rows.
`--command` runs another moveplan (a checkout to compare with) instead of the one installed
beside this Python. Machines are shared and noisy: run it more than once.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CONTROLLERS = ROOT / "configs" / "ur10e" / "ros2_controllers.yaml"
GOALS = ("[0.3, -1.4, -1.6, 0.0, 1.57, 0.0]", "[-0.3, -1.7, -1.4, 0.2, 1.57, 0.3]")


def task_text(steps: int, scaling: float) -> str:
    """Return a UR10e task file alternating two joint goals `steps` times."""
    lines = [
        f"robot: {ROOT / 'configs' / 'ur10e'}",
        "start: {named: home}",
        f"defaults: {{velocity_scaling: {scaling}, acceleration_scaling: {scaling}}}",
        "steps:",
    ]
    lines += [f"  - {{name: s{i}, joints: {GOALS[i % 2]}}}" for i in range(steps)]
    return "\n".join(lines) + "\n"


def controllers_text(rate_hz: float) -> str:
    """Return the UR10e's ros2_controllers.yaml with its update_rate set to `rate_hz`."""
    text, count = re.subn(r"update_rate: *[0-9.]+", f"update_rate: {rate_hz:g}", CONTROLLERS.read_text())
    if count != 1:
        raise SystemExit(f"{CONTROLLERS}: expected one update_rate, found {count}")
    return text


def measured(command: list[str]) -> tuple[int, float, int, str]:
    """Return the child's peak RSS [KiB], wall time [s], exit code and stdout."""
    started = time.perf_counter()
    with tempfile.TemporaryFile() as stdout:
        child = subprocess.Popen(command, stdout=stdout, stderr=subprocess.PIPE)
        # wait4 gives this child's own rusage; RUSAGE_CHILDREN would be the max over all children.
        _, status, usage = os.wait4(child.pid, 0)
        elapsed = time.perf_counter() - started
        child.returncode = os.waitstatus_to_exitcode(status)
        error = child.stderr.read().decode() if child.stderr else ""
        stdout.seek(0)
        text = stdout.read().decode()
    if child.returncode not in (0, 5):
        raise SystemExit(f"{shlex.join(command)} exited {child.returncode}: {error.strip()[-500:]}")
    return usage.ru_maxrss, elapsed, child.returncode, text


def main() -> None:
    """Plan, execute and print peak memory per step count and update rate."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--steps", default="100,400", help="step counts, comma-separated")
    parser.add_argument("--rates", default="1000,10000", help="update rates [Hz], comma-separated")
    parser.add_argument("--plant", default="mirror", help="mirror, lag or pid (pid needs velocity commands)")
    parser.add_argument("--scaling", type=float, default=1.0, help="velocity and acceleration scaling")
    parser.add_argument("--no-json", action="store_true", help="skip the runs without an output file")
    parser.add_argument("--command", default=None, help="moveplan command line (default: the installed one)")
    args = parser.parse_args()
    moveplan = shlex.split(args.command) if args.command else [str(Path(sys.executable).with_name("moveplan"))]
    steps = [int(s) for s in args.steps.split(",")]
    rates = [float(r) for r in args.rates.split(",")]

    with tempfile.TemporaryDirectory(prefix="moveplan-execute-memory-") as folder:
        work = Path(folder)
        print(f"{'steps':>6} {'rate Hz':>8} {'output':>7} {'peak RSS MiB':>13} {'wall s':>7} "
              f"{'cycles':>9} {'file MB':>8} result")
        for count in steps:
            task, plan = work / f"task{count}.yaml", work / f"plan{count}.mcap"
            task.write_text(task_text(count, args.scaling))
            subprocess.run([*moveplan, "plan", str(task), "-o", str(plan), "--seed", "0", "--quiet"], check=True)
            for rate in rates:
                controllers = work / f"controllers_{rate:g}.yaml"
                controllers.write_text(controllers_text(rate))
                base = [*moveplan, "execute", str(plan), "--fake", "--plant", args.plant,
                        "--controllers", str(controllers)]
                executed = work / "executed.mcap"
                runs = [("-o", [*base, "-o", str(executed), "--json"])]
                if not args.no_json:
                    runs.append(("--json", [*base, "--json"]))
                for label, command in runs:
                    executed.unlink(missing_ok=True)
                    peak_kib, wall_s, _, text = measured(command)
                    document = json.loads(text)
                    cycles = sum(round(step["duration_s"] * rate) + 1 for step in document["steps"])
                    size = f"{executed.stat().st_size / 1e6:8.1f}" if executed.exists() else f"{'-':>8}"
                    print(f"{count:>6} {rate:>8g} {label:>7} {peak_kib / 1024:>13.0f} {wall_s:>7.2f} "
                          f"{cycles:>9} {size} {document['result']['name']}", flush=True)


if __name__ == "__main__":
    main()
