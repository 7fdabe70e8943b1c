"""One-time set-up done in the middle of a search (building the sphere filter), kept off its planning-time cap.

The cap bounds the search's own work; numba's import or a kernel compilation that happens to
fall inside a step is no part of it, and must not make a search run out of time on a cold or
busy machine (the budget of checked motions, not the clock, decides the path).
"""

from __future__ import annotations

__all__ = ["add_setup_time", "setup_time_spent"]

_spent_s = 0.0


def add_setup_time(seconds: float) -> None:
    """Record `seconds` of set-up done inside a search; return None."""
    global _spent_s
    _spent_s += seconds


def setup_time_spent() -> float:
    """Return the set-up seconds recorded in this process so far."""
    return _spent_s
