"""Flag values as core's typed values: numbers, angles, joints, poses; errors are usage errors (exit 2).

Only the spelling of one flag is checked here; rules between flags and ranges of values are core's.
Numbers and angles are read by core/config/fields.py, as task files' are: pi expressions, and a
`deg` suffix on angles.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TypeVar

from ..core.errors import UsageError

if TYPE_CHECKING:  # imported where used: `moveplan --help` loads no config code
    from ..core.config import JointGoal, PoseGoal, ShiftGoal

__all__ = [
    "MAX_SEED", "MAX_SEEDS", "parse_angle", "parse_disturbance", "parse_joint_values",
    "parse_joints", "parse_number", "parse_optional", "parse_params", "parse_pose", "parse_pose_angle", "parse_seeds",
    "parse_shard", "parse_shift", "parse_time",
]

_T = TypeVar("_T")

MAX_SEED = 2**32 - 1
"""Largest seed: OMPL's random generator takes 32-bit seeds (the same bound as core/config/tasks.py's,
kept here so that `moveplan --help` imports no config code)."""
MAX_SEEDS = 10_000
"""Seeds one benchmark may run per planner and problem."""

def parse_number(text: str, what: str) -> float:
    """Return the number `text` spells: a decimal, or an expression of numbers and pi.

    Raises:
        UsageError: Not such an expression, longer than fields.MAX_EXPRESSION_LENGTH characters, or a
            value (or an intermediate value) beyond MAX_MAGNITUDE: no flag needs more than a
            million radians, metres or seconds, and beyond it a typo must not reach the planner.
            A `deg` suffix, which only angles take (parse_angle).
    """
    from ..core.config import expression

    return expression(text, what, UsageError)


def parse_angle(text: str, what: str) -> tuple[float, bool]:
    """Return an angle in [rad] from radians, a pi expression or degrees (`90deg`), and whether it was in degrees."""
    from ..core.config import angle

    return angle(text, what, UsageError)


def parse_pose_angle(text: str, what: str) -> float:
    """Return a pose's roll, pitch or yaw in [rad] (as parse_angle reads it); a unitless one beyond 2*pi is refused."""
    from ..core.config import pose_angle

    return pose_angle(text, what, UsageError)


def parse_time(text: str, what: str) -> float:
    """Return a time in [s] from `text` (a number or expression), checked to lie in [0, MAX_MAGNITUDE]."""
    from ..core.config import MAX_MAGNITUDE

    time_s = parse_number(text, what)
    if time_s < 0:
        raise UsageError(f"{what}: a time must lie in [0, {MAX_MAGNITUDE:,.0f}] s, got '{text.strip()}'")
    return time_s


def parse_optional(parse: Callable[[str, str], _T], text: str | None, what: str) -> _T | None:
    """Return `parse(text, what)`, or None when the flag was not given."""
    return None if text is None else parse(text, what)


def parse_joints(text: str, what: str) -> JointGoal:
    """Return a joints goal from "q1,...,qn" (all joints) or "name=value,..." (some joints), in [rad], [m] or `deg`."""
    from ..core.config import JointGoal

    items = [item.strip() for item in text.split(",")]
    if not text.strip() or any(not item for item in items):
        raise UsageError(f"{what}: expected comma-separated values like '0,-1.57,...' or 'elbow_joint=1.2'")
    if all("=" in item for item in items):
        pairs = [(name.strip(), value) for name, value in (item.split("=", 1) for item in items)]
        names = [name for name, _ in pairs]
        twice = next((name for name in names if names.count(name) > 1), None)
        if twice is not None:
            # A dict would keep the last value silently: which one the user meant is unknown.
            raise UsageError(f"{what}: joint '{twice}' is given twice")
        read = {name: parse_angle(value, f"{what} {name}") for name, value in pairs}
        return JointGoal.by_name({name: v for name, (v, _) in read.items()}, [d for _, d in read.values()], what)
    if any("=" in item for item in items):
        raise UsageError(f"{what}: give either all values or name=value pairs, not a mix")
    values = [parse_angle(item, what) for item in items]
    return JointGoal(tuple(v for v, _ in values), degrees=tuple(d for _, d in values), source=what)


def parse_joint_values(text: str, what: str) -> JointGoal:
    """Return the joint values of "name=value,..." (the joints not named are left alone), units recorded."""
    goal = parse_joints(text, what)
    if goal.named_values is None:
        raise UsageError(f"{what}: give joint=value pairs")
    return goal


def parse_pose(text: str, what: str) -> PoseGoal:
    """Return a pose goal from "x,y,z", "x,y,z,roll,pitch,yaw" or "x,y,z,qx,qy,qz,qw" (frame and link unset).

    Positions in [m]; roll, pitch and yaw in [rad] or `deg`, a unitless one beyond 2*pi refused.
    """
    from ..core.config import PoseGoal

    items = text.split(",") if text.strip() else []
    if len(items) not in (3, 6, 7):
        raise UsageError(f"{what}: expected 'x,y,z', 'x,y,z,roll,pitch,yaw' or 'x,y,z,qx,qy,qz,qw', "
                         f"got {len(items)} values")
    x, y, z = (parse_number(item, what) for item in items[:3])
    if len(items) == 6:
        roll, pitch, yaw = (parse_pose_angle(item, f"{what} {axis}") for axis, item in
                            zip(("roll", "pitch", "yaw"), items[3:], strict=True))
        return PoseGoal(xyz=(x, y, z), rpy=(roll, pitch, yaw))
    if len(items) == 7:
        qx, qy, qz, qw = (parse_number(item, what) for item in items[3:])
        if math.fsum(v * v for v in (qx, qy, qz, qw)) < 1e-12:
            raise UsageError(f"{what}: the quaternion (qx,qy,qz,qw) has zero norm; it is not a rotation")
        return PoseGoal(xyz=(x, y, z), quat=(qx, qy, qz, qw))
    return PoseGoal(xyz=(x, y, z))


def parse_shift(text: str, what: str) -> ShiftGoal:
    """Return a shift of the tip from "z=0.1" or "x=0.05,yaw=30deg" ([m]; [rad] or `deg`), along the tool's axes."""
    from ..core.config import SHIFT_AXES, ShiftGoal

    offsets: dict[str, float] = {}
    for item in text.split(","):
        name, _, value = item.partition("=")
        name = name.strip()
        if name not in SHIFT_AXES or not value.strip():
            raise UsageError(f"{what}: expected axis=value pairs with axes {', '.join(SHIFT_AXES)}, "
                             f"got '{item.strip()}'")
        if name in offsets:
            raise UsageError(f"{what}: axis '{name}' is given twice")
        read = parse_number if name in ("x", "y", "z") else parse_pose_angle
        offsets[name] = read(value, f"{what} {name}")
    return ShiftGoal.of(offsets)


def parse_params(items: list[str], what: str) -> dict[str, float]:
    """Return parameters from "k=v" items (values may be pi expressions)."""
    params: dict[str, float] = {}
    for item in items:
        key, _, value = item.partition("=")
        if not key.strip() or not value.strip():
            raise UsageError(f"{what}: expected key=value, got '{item}'")
        if key.strip() in params:
            raise UsageError(f"{what}: '{key.strip()}' is given twice")
        params[key.strip()] = parse_number(value, f"{what} {key.strip()}")
    return params


def parse_disturbance(text: str) -> Any:
    """Return a Disturbance from "t=1.2,joint=elbow_joint,delta=0.05"."""
    from ..core.control import Disturbance

    pairs = [item.partition("=")[::2] for item in text.split(",")]
    fields = {k.strip(): v.strip() for k, v in pairs}
    if set(fields) != {"t", "joint", "delta"} or len(pairs) != len(fields) or not fields["joint"]:
        raise UsageError(f"--disturb: expected 't=SECONDS,joint=NAME,delta=RAD', got '{text}'")
    time_s = parse_time(fields["t"], "--disturb t")
    return Disturbance(time_s, fields["joint"], parse_number(fields["delta"], "--disturb delta"))


def parse_shard(text: str) -> tuple[int, int]:
    """Return (K, N) of a `--shard K/N` text: shard K (1-based) of N."""
    index, slash, count = text.strip().partition("/")
    if slash and index.isdigit() and count.isdigit() and len(index) <= 6 and len(count) <= 6:
        return int(index), int(count)
    shown = text if len(text) <= 40 else f"{text[:37]}..."
    raise UsageError(f"--shard: expected K/N, shard K of N ('2/4'), got '{shown}'")


def parse_seeds(text: str) -> list[int]:
    """Return the seeds `text` lists: '0-4' (inclusive), '0,3,7', or a mix of both."""
    seeds: list[int] = []
    shown = text if len(text) <= 40 else f"{text[:37]}..."
    try:
        for part in text.split(","):
            low, _, high = part.strip().partition("-")
            if len(low) > 10 or len(high) > 10:  # int() of a 10,000-digit string is slow
                raise ValueError
            first, last = int(low), int(high or low)
            if first < 0 or last < first or last > MAX_SEED:
                raise ValueError
            if len(seeds) + last - first + 1 > MAX_SEEDS:
                raise UsageError(f"--seeds: '{shown}' lists more than {MAX_SEEDS} seeds")
            seeds.extend(range(first, last + 1))
    except ValueError:
        raise UsageError(f"--seeds: expected '0-4' or '0,3,7' with seeds in 0..{MAX_SEED}, got '{shown}'") from None
    return list(dict.fromkeys(seeds))
