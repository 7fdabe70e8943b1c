"""Write a long recording of a UR10e repeating a pick cycle, for timing check-tolerances.

Run from the repository root with moveplan installed:
    python benchmarks/make_recording.py [--out /tmp/moveplan_cycles.mcap] [--hours 1] [--rate 1000]
        [--faults 100:spike,250:late]

The cycle (`cycle_plan`) has two steps, out and back, each a 4 s minimum-jerk move, with a
0.3 s pause between them and 1.7 s at home after: 360 cycles an hour. The robot follows
the plan 2 ms late with 1e-5 rad of noise. Faults: `spike` bumps elbow_joint by 0.3 rad
for 20 ms in the middle of step out (beyond the 0.2 rad path tolerance); `late` stops
shoulder_pan_joint 0.15 rad short of home for a second at the end of step back (inside the
path tolerance, outside the 0.1 rad goal tolerance for longer than goal_time 0.5 s).

The file is written as rosbag2 writes one (zstd chunks of 1 MiB, message indexes,
statistics), with payloads encoded by numpy and handed to mcap's Writer as bytes.
Generating an hour takes about a minute. Write it under /tmp, not into the repository.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mcap.writer import CompressionType, Writer
from numpy.typing import NDArray

from moveplan.core.bag.jointstates import JOINT_STATE_TYPE, encode_joint_states
from moveplan.core.bag.plan_file import PlanStepRecord
from moveplan.core.config.controllers import ControllerConfig, ExecutionConfig
from moveplan.core.trajectory import sample
from moveplan.core.types import JointTrajectory

JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
          "wrist_1_joint", "wrist_2_joint", "wrist_3_joint")
HOME = np.array([0.0, -np.pi / 2, -np.pi / 2, 0.0, 0.0, 0.0])
PICK = HOME + np.array([1.0, 0.5, -0.8, 1.2, -1.0, 1.5])
MOVE_S, PAUSE_S, DWELL_S = 4.0, 0.3, 1.7
PERIOD_S = 2 * MOVE_S + PAUSE_S + DWELL_S
DELAY_S, NOISE_RAD = 0.002, 1e-5
FIRST_S = 1.0
SCHEMA = Path(__file__).resolve().parents[1] / "core/bag/cdr/msgs/jazzy/sensor_msgs__msg__JointState.msg"
QOS = ("- history: 3\n  depth: 0\n  reliability: 1\n  durability: 2\n  deadline:\n    sec: 0\n"
       "    nsec: 0\n  lifespan:\n    sec: 0\n    nsec: 0\n  liveliness: 1\n"
       "  liveliness_lease_duration:\n    sec: 0\n    nsec: 0\n"
       "  avoid_ros_namespace_conventions: false")


@dataclass(frozen=True)
class Plan:
    """The steps of the cycle."""

    steps: tuple[PlanStepRecord, ...]


def minimum_jerk(
    start: NDArray[np.float64], goal: NDArray[np.float64], duration: float
) -> JointTrajectory:
    """Return a rest-to-rest minimum-jerk move, exact velocities and accelerations, 10 points/s."""
    t = np.linspace(0.0, duration, int(round(duration / 0.1)) + 1)
    s = (t / duration)[:, None]
    delta = goal - start
    return JointTrajectory(
        JOINTS, t, start + (10 * s**3 - 15 * s**4 + 6 * s**5) * delta,
        (30 * s**2 - 60 * s**3 + 30 * s**4) / duration * delta,
        (60 * s - 180 * s**2 + 120 * s**3) / duration**2 * delta,
    )


def cycle_plan() -> Plan:
    """Return the plan the robot repeats: out to the pick pose and back home."""
    return Plan((PlanStepRecord("out", 0.0, minimum_jerk(HOME, PICK, MOVE_S)),
                 PlanStepRecord("back", MOVE_S, minimum_jerk(PICK, HOME, MOVE_S))))


def controller() -> ControllerConfig:
    """Return a UR-like JointTrajectoryController: 500 Hz, path 0.2 rad, goal 0.1 rad."""
    return ControllerConfig(
        name="scaled_joint_trajectory_controller", joints=JOINTS, update_rate_hz=500.0,
        command_interfaces=("position",), state_interfaces=("position", "velocity"),
        goal_time_s=0.5, stopped_velocity_tolerance=0.2,
        trajectory_tolerance={j: 0.2 for j in JOINTS}, goal_tolerance={j: 0.1 for j in JOINTS},
        gains={},
    )


def execution() -> ExecutionConfig:
    """Return MoveIt's default trajectory_execution settings."""
    return ExecutionConfig()


def cycle_starts(duration_s: float, seed: int = 0) -> NDArray[np.float64]:
    """Return when each cycle's step out starts, in [s] from the recording's start (±5 ms)."""
    count = int((duration_s - FIRST_S) // PERIOD_S)
    jitter = np.random.default_rng(seed).uniform(-0.005, 0.005, count)
    return FIRST_S + np.arange(count) * PERIOD_S + jitter


def synthesize(
    times_s: NDArray[np.float64], starts: NDArray[np.float64], faults: dict[int, str], seed: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return recorded positions and velocities at `times_s` for cycles starting at `starts`."""
    plan = cycle_plan()
    out, back = (step.trajectory for step in plan.steps)
    cycle = np.clip(np.searchsorted(starts, times_s, side="right") - 1, 0, len(starts) - 1)
    phase = times_s - starts[cycle] - DELAY_S
    positions = np.tile(HOME, (len(times_s), 1))
    velocities = np.zeros_like(positions)
    moving = phase >= 0.0
    first = moving & (phase < MOVE_S + PAUSE_S)
    second = moving & ~first
    for mask, trajectory, offset in ((first, out, 0.0), (second, back, MOVE_S + PAUSE_S)):
        p, v, _ = sample(trajectory, phase[mask] - offset)
        positions[mask], velocities[mask] = p, v
    for index, kind in faults.items():
        if index >= len(starts):
            continue
        local = times_s - starts[index]
        if kind == "spike":
            positions[(local >= 2.0) & (local < 2.02), JOINTS.index("elbow_joint")] += 0.3
        elif kind == "late":
            back_end = MOVE_S + PAUSE_S + MOVE_S
            ramp = np.interp(local, [back_end - 1.0, back_end, back_end + 1.0, back_end + 1.5],
                             [0.0, 0.15, 0.15, 0.0], left=0.0, right=0.0)
            positions[:, 0] += ramp
        else:
            raise SystemExit(f"unknown fault '{kind}': spike or late")
    rng = np.random.default_rng(seed)
    positions += rng.normal(0.0, NOISE_RAD, positions.shape)
    velocities += rng.normal(0.0, 10 * NOISE_RAD, velocities.shape)
    return positions, velocities


def write(path: Path, duration_s: float, rate_hz: float, faults: dict[int, str], seed: int) -> int:
    """Write the recording to `path`; return the number of messages."""
    starts = cycle_starts(duration_s, seed)
    count = int(duration_s * rate_hz)
    epoch_ns = 1_700_000_000_000_000_000
    block = 60_000
    with path.open("wb") as stream:
        writer = Writer(stream, chunk_size=1024 * 1024, compression=CompressionType.ZSTD)
        writer.start("ros2", "moveplan benchmarks/make_recording.py")
        schema = writer.register_schema(JOINT_STATE_TYPE, "ros2msg", SCHEMA.read_bytes())
        channel = writer.register_channel("/joint_states", "cdr", schema,
                                          {"offered_qos_profiles": QOS})
        for begin in range(0, count, block):
            index = np.arange(begin, min(count, begin + block))
            times_s = index / rate_hz
            positions, velocities = synthesize(times_s, starts, faults, seed + begin)
            stamps = epoch_ns + np.round(times_s * 1e9).astype(np.int64)
            # Received a little after they were stamped, as a subscriber records them.
            received = (stamps + 150_000).tolist()
            payloads = encode_joint_states(JOINTS, stamps, positions, velocities,
                                           np.zeros_like(positions))
            for log_time, data in zip(received, payloads, strict=True):
                writer.add_message(channel, log_time, data, log_time)
        writer.add_metadata("rosbag2", {"ROS_DISTRO": "jazzy"})
        writer.finish()
    return count


def parse_faults(text: str) -> dict[int, str]:
    """Return {cycle index: fault kind} from "100:spike,250:late"."""
    faults = {}
    for item in filter(None, text.split(",")):
        index, kind = item.split(":")
        faults[int(index)] = kind.strip()
    return faults


def main() -> None:
    """Write the file and print what was written."""
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("/tmp/moveplan_cycles.mcap"))
    parser.add_argument("--hours", type=float, default=1.0)
    parser.add_argument("--rate", type=float, default=1000.0)
    parser.add_argument("--faults", default="100:spike,250:late")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    began = time.perf_counter()
    count = write(args.out, args.hours * 3600.0, args.rate, parse_faults(args.faults), args.seed)
    elapsed = time.perf_counter() - began
    size = args.out.stat().st_size
    cycles = len(cycle_starts(args.hours * 3600.0))
    print(f"{args.out}: {count} messages, {size / 1e6:.1f} MB, {cycles} cycles, "
          f"faults {args.faults or '(none)'}; written in {elapsed:.1f} s")


if __name__ == "__main__":
    main()
