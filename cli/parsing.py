"""Flag values: numbers with pi expressions, joint lists, poses; errors are usage errors (exit 2)."""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable
from typing import Any

from moveplan.core.errors import UsageError

__all__ = [
    "parse_disturbance", "parse_joints", "parse_number", "parse_params", "parse_pose", "parse_scaling", "parse_seeds",
    "parse_shift",
]

_BINARY: dict[type, Callable[[float, float], float]] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul, ast.Div: operator.truediv,
}


def parse_number(text: str, what: str) -> float:
    """Return the finite number `text` spells: a decimal, or an expression of numbers and pi."""
    def value(node: ast.AST) -> float:
        if isinstance(node, ast.Constant) and isinstance(node.value, int | float) and not isinstance(node.value, bool):
            return float(node.value)
        if isinstance(node, ast.Name) and node.id == "pi":
            return math.pi
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
            return -value(node.operand) if isinstance(node.op, ast.USub) else value(node.operand)
        if isinstance(node, ast.BinOp) and type(node.op) in _BINARY:
            return _BINARY[type(node.op)](value(node.left), value(node.right))
        raise ValueError

    expected = f"{what}: expected a number or an expression like pi/2, got '{text.strip()}'"
    try:
        result = value(ast.parse(text.strip(), mode="eval").body)
    except (SyntaxError, ValueError, ZeroDivisionError, RecursionError):
        raise UsageError(expected) from None
    if not math.isfinite(result):
        raise UsageError(expected)
    return result


def parse_scaling(text: str | None, what: str) -> float | None:
    """Return a scaling factor in (0, 1], or None when the flag was not given."""
    if text is None:
        return None
    factor = parse_number(text, what)
    if not 0.0 < factor <= 1.0:
        raise UsageError(f"{what}: expected a factor in (0, 1], got '{text}'")
    return factor


def parse_joints(text: str, what: str) -> dict[str, Any]:
    """Return a joints goal from "q1,...,qn" (all joints) or "name=value,..." (some joints)."""
    items = [item.strip() for item in text.split(",")]
    if not text.strip() or any(not item for item in items):
        raise UsageError(f"{what}: expected comma-separated values like '0,-1.57,...' or 'elbow_joint=1.2'")
    if all("=" in item for item in items):
        pairs = [item.split("=", 1) for item in items]
        return {"joints": {name.strip(): parse_number(v, f"{what} {name.strip()}") for name, v in pairs}}
    if any("=" in item for item in items):
        raise UsageError(f"{what}: give either all values or name=value pairs, not a mix")
    return {"joints": [parse_number(item, what) for item in items]}


def parse_pose(text: str, what: str) -> dict[str, Any]:
    """Return a pose goal from "x,y,z", "x,y,z,roll,pitch,yaw" or "x,y,z,qx,qy,qz,qw"."""
    values = [parse_number(item, what) for item in text.split(",")] if text.strip() else []
    if len(values) not in (3, 6, 7):
        raise UsageError(f"{what}: expected 'x,y,z', 'x,y,z,roll,pitch,yaw' or 'x,y,z,qx,qy,qz,qw', "
                         f"got {len(values)} values")
    pose: dict[str, Any] = {"xyz": values[:3], "rpy": None, "quat": None}
    if len(values) == 6:
        pose["rpy"] = values[3:]
    elif len(values) == 7:
        if math.fsum(v * v for v in values[3:]) < 1e-12:
            raise UsageError(f"{what}: the quaternion (qx,qy,qz,qw) has zero norm; it is not a rotation")
        pose["quat"] = values[3:]
    return pose


def parse_shift(text: str, what: str) -> dict[str, Any]:
    """Return shift displacements from "z=0.1" or "x=0.05,yaw=0.3" (metres and radians)."""
    axes = ("x", "y", "z", "roll", "pitch", "yaw")
    shift: dict[str, Any] = {}
    for item in text.split(","):
        name, _, value = item.partition("=")
        name = name.strip()
        if name not in axes or not value.strip():
            raise UsageError(f"{what}: expected axis=value pairs with axes {', '.join(axes)}, got '{item.strip()}'")
        shift[name] = parse_number(value, f"{what} {name}")
    return shift


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
    time_s = parse_number(fields["t"], "--disturb t")
    if time_s < 0:
        raise UsageError(f"--disturb: t must not be negative, got '{fields['t']}'")
    return Disturbance(time_s, fields["joint"], parse_number(fields["delta"], "--disturb delta"))


def parse_seeds(text: str) -> list[int]:
    """Return the seeds `text` lists: '0-4' (inclusive), '0,3,7', or a mix of both."""
    seeds: list[int] = []
    try:
        for part in text.split(","):
            low, _, high = part.strip().partition("-")
            first, last = int(low), int(high or low)
            if first < 0 or last < first:
                raise ValueError
            seeds.extend(range(first, last + 1))
    except ValueError:
        raise UsageError(f"--seeds: expected '0-4' or '0,3,7' (non-negative), got '{text}'") from None
    return list(dict.fromkeys(seeds))
