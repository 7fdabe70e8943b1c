"""Flag values: numbers with pi expressions, joint lists, poses; errors are usage errors (exit 2)."""

from __future__ import annotations

import ast
import math
import operator
from collections.abc import Callable
from typing import Any

from moveplan.core.errors import UsageError

__all__ = ["parse_joints", "parse_number", "parse_scaling"]

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
