"""Flag values as core's typed values: numbers with pi expressions, joints, poses; errors are usage errors (exit 2).

Only the spelling of one flag is checked here; rules between flags and ranges of values are core's.
"""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, TypeVar

from moveplan.core.errors import UsageError

if TYPE_CHECKING:  # imported where used: `moveplan --help` loads no config code
    from moveplan.core.config.goals import JointGoal, PoseGoal, ShiftGoal

__all__ = [
    "MAX_EXPRESSION_LENGTH", "MAX_SEED", "MAX_SEEDS", "parse_disturbance", "parse_joint_values", "parse_joints",
    "parse_number", "parse_optional", "parse_params", "parse_pose", "parse_seeds", "parse_shift", "parse_time",
]

_T = TypeVar("_T")

MAX_SEED = 2**32 - 1
"""Largest seed: OMPL's random generator takes 32-bit seeds (the same bound as core/config/tasks.py's,
kept here so that `moveplan --help` imports no config code)."""
MAX_SEEDS = 10_000
"""Seeds one benchmark may run per planner and problem."""

_BINARY: dict[type, Callable[[float, float], float]] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
}


MAX_EXPRESSION_LENGTH = 100
"""Characters of one number or pi expression: `-pi/2+0.25` is 10, a double written in full 25."""


def parse_number(text: str, what: str) -> float:
    """Return the number `text` spells: a decimal, or an expression of numbers and pi.

    Raises:
        UsageError: Not such an expression, longer than MAX_EXPRESSION_LENGTH characters, or a
            value (or an intermediate value) beyond MAX_MAGNITUDE: no flag needs more than a
            million radians, metres or seconds, and beyond it a typo must not reach the planner.
    """
    from moveplan.core.config.fields import MAX_MAGNITUDE

    text = text.strip()
    shown = f"'{text}'" if len(text) <= 40 else f"'{text[:20]}...{text[-10:]}' ({len(text)} characters)"
    if len(text) > MAX_EXPRESSION_LENGTH:
        raise UsageError(f"{what}: {shown} is longer than {MAX_EXPRESSION_LENGTH} characters, "
                         "the longest number or pi expression moveplan reads")

    def bounded(result: float) -> float:
        if not abs(result) <= MAX_MAGNITUDE:  # NaN and inf fail this too
            raise OverflowError
        return result

    def value(node: ast.AST) -> float:
        if isinstance(node, ast.Constant) and isinstance(node.value, int | float) and not isinstance(node.value, bool):
            return bounded(float(node.value))
        if isinstance(node, ast.Name) and node.id == "pi":
            return math.pi
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            return -value(node.operand) if isinstance(node.op, ast.USub) else value(node.operand)
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            return bounded(_BINARY[type(node.op)](value(node.left), value(node.right)))
        raise ValueError

    try:
        return value(ast.parse(text, mode="eval").body)
    except (SyntaxError, ValueError, ZeroDivisionError, RecursionError, MemoryError):
        raise UsageError(f"{what}: expected a number or an expression like pi/2, got {shown}") from None
    except OverflowError:
        raise UsageError(f"{what}: {shown} is out of range; values are limited to "
                         f"|value| <= {MAX_MAGNITUDE:,.0f} (rad, m or s)") from None


def parse_time(text: str, what: str) -> float:
    """Return a time in [s] from `text` (a number or expression), checked to lie in [0, MAX_MAGNITUDE]."""
    from moveplan.core.config.fields import MAX_MAGNITUDE

    time_s = parse_number(text, what)
    if time_s < 0:
        raise UsageError(f"{what}: a time must lie in [0, {MAX_MAGNITUDE:,.0f}] s, got '{text.strip()}'")
    return time_s


def parse_optional(parse: Callable[[str, str], _T], text: str | None, what: str) -> _T | None:
    """Return `parse(text, what)`, or None when the flag was not given."""
    return None if text is None else parse(text, what)


def parse_joints(text: str, what: str) -> JointGoal:
    """Return a joints goal from "q1,...,qn" (all joints) or "name=value,..." (some joints)."""
    from moveplan.core.config.goals import JointGoal

    items = [item.strip() for item in text.split(",")]
    if not text.strip() or any(not item for item in items):
        raise UsageError(f"{what}: expected comma-separated values like '0,-1.57,...' or 'elbow_joint=1.2'")
    if all("=" in item for item in items):
        pairs = [item.split("=", 1) for item in items]
        return JointGoal.by_name({name.strip(): parse_number(v, f"{what} {name.strip()}") for name, v in pairs})
    if any("=" in item for item in items):
        raise UsageError(f"{what}: give either all values or name=value pairs, not a mix")
    return JointGoal(tuple(parse_number(item, what) for item in items))


def parse_joint_values(text: str, what: str) -> dict[str, float]:
    """Return joint -> value from "name=value,..." (the joints not named are left alone)."""
    named = parse_joints(text, what).named_values
    if named is None:
        raise UsageError(f"{what}: give joint=value pairs")
    return named


def parse_pose(text: str, what: str) -> PoseGoal:
    """Return a pose goal from "x,y,z", "x,y,z,roll,pitch,yaw" or "x,y,z,qx,qy,qz,qw" (frame and link unset)."""
    from moveplan.core.config.goals import PoseGoal

    values = [parse_number(item, what) for item in text.split(",")] if text.strip() else []
    if len(values) not in (3, 6, 7):
        raise UsageError(f"{what}: expected 'x,y,z', 'x,y,z,roll,pitch,yaw' or 'x,y,z,qx,qy,qz,qw', "
                         f"got {len(values)} values")
    x, y, z, *orientation = values
    if len(orientation) == 3:
        roll, pitch, yaw = orientation
        return PoseGoal(xyz=(x, y, z), rpy=(roll, pitch, yaw))
    if len(orientation) == 4:
        if math.fsum(v * v for v in orientation) < 1e-12:
            raise UsageError(f"{what}: the quaternion (qx,qy,qz,qw) has zero norm; it is not a rotation")
        qx, qy, qz, qw = orientation
        return PoseGoal(xyz=(x, y, z), quat=(qx, qy, qz, qw))
    return PoseGoal(xyz=(x, y, z))


def parse_shift(text: str, what: str) -> ShiftGoal:
    """Return a shift of the tip from "z=0.1" or "x=0.05,yaw=0.3" (metres and radians), along the tool's axes."""
    from moveplan.core.config.goals import SHIFT_AXES, ShiftGoal

    offsets: dict[str, float] = {}
    for item in text.split(","):
        name, _, value = item.partition("=")
        name = name.strip()
        if name not in SHIFT_AXES or not value.strip():
            raise UsageError(f"{what}: expected axis=value pairs with axes {', '.join(SHIFT_AXES)}, "
                             f"got '{item.strip()}'")
        offsets[name] = parse_number(value, f"{what} {name}")
    return ShiftGoal.of(offsets)


def parse_params(items: list[str], what: str) -> dict[str, float]:
    """Return parameters from "k=v" items (values may be pi expressions)."""
    params: dict[str, float] = {}
    for item in items:
        key, _, value = item.partition("=")
        if not key.strip() or not value.strip():
            raise UsageError(f"{what}: expected key=value, got '{item}'")
        params[key.strip()] = parse_number(value, f"{what} {key.strip()}")
    return params


def parse_disturbance(text: str) -> Any:
    """Return a Disturbance from "t=1.2,joint=elbow_joint,delta=0.05"."""
    from moveplan.core.control.controller import Disturbance

    fields = dict(item.partition("=")[::2] for item in text.split(","))
    fields = {k.strip(): v.strip() for k, v in fields.items()}
    if set(fields) != {"t", "joint", "delta"} or not fields["joint"]:
        raise UsageError(f"--disturb: expected 't=SECONDS,joint=NAME,delta=RAD', got '{text}'")
    time_s = parse_time(fields["t"], "--disturb t")
    return Disturbance(time_s, fields["joint"], parse_number(fields["delta"], "--disturb delta"))


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
