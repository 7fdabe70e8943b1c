"""The compiled kernels, and their state in this process in one place: loaded, built, cached; set-up time.

numba's kernels (the sphere filter's, the certification walk's, timing's twins) are compiled
once per install and loaded once per process: ahead of time into extension modules that load in
milliseconds without numba (core/_native.py; `collision_kernels` here, core/timing/_twins.py),
else by numba's JIT, whose start-up costs a fresh process ~0.7 s. Who decides by it asks here:
- the one-shot commands' rent-or-buy rule (core/pipeline/_checks.py) counts the states this
  process has judged without the sphere filter (`count_unfiltered`), and builds it at once
  when `kernels_native()`, sooner when `kernels_ready()`: loading costs less than a compilation;
- a search keeps set-up done inside it (a filter built mid-step) off its planning-time cap,
  through `add_setup_time` and `setup_time_spent`: the budget of work, not the clock, decides
  the path on a cold or busy machine;
- a step times its path with the compiled passes when its checks carry a built filter
  (MotionChecker.compiled).
"""

from __future__ import annotations

from functools import cache
from pathlib import Path
from typing import Any

from .. import _native
from ..timing import twins_built, twins_failed
from ._kernel_cache import kernels_cached

__all__ = ["add_setup_time", "collision_kernels", "count_unfiltered", "kernels_loaded", "kernels_native",
           "kernels_ready", "mark_kernels_loaded", "setup_time_spent"]

NAME = "moveplan_collision"
SOURCES = tuple(Path(__file__).resolve().with_name(name) for name in ("_kernels.py", "_clearance.py", "_states.py"))
"""The kernel files: their bytes name the sources they compile in (tests/foundation/test_kernel_inputs.py)."""
_PACKED = "float64[::1], int64[::1], int64[:, ::1]"  # a filter's arrays (core/collision/_packing.py)
SIGNATURES = {
    "classify": f"int64(float64[:, ::1], boolean, {_PACKED}, float64[:, ::1], int8[::1])",
    "edge": f"UniTuple(int64, 2)(float64[::1], float64[::1], float64, boolean, {_PACKED}, int8[::1], float64[:, ::1])",
    "certify": f"int64(float64[:, ::1], float64[::1], float64, float64, {_PACKED}, float64[:, ::1], int8[::1], "
               "float64[::1])",
    "trajectory_states": "Tuple((float64[:, ::1], float64[::1]))(float64[::1], float64[:, ::1], float64[:, ::1], "
                         "float64[:, ::1], float64[::1], float64[::1], float64[::1], float64, int64)",
}
"""The types core/collision/sphere_filter.py passes, exactly."""

_loaded = False  # set once a filter has its kernels: a later one in this process compiles nothing
_setup_s = 0.0
_unfiltered = 0  # states judged in this process before any filter was built: the rule's rent


def kernels_loaded() -> bool:
    """Return True once a filter built in this process has its kernels: the next one costs no numba start-up."""
    return _loaded


def mark_kernels_loaded() -> None:
    """Record that this process has loaded the kernels (a filter was built); return None."""
    global _loaded
    _loaded = True


def _dispatchers() -> dict[str, Any]:
    """Return the kernels' numba dispatchers (importing numba)."""
    from . import _clearance, _kernels, _states

    return {"classify": _kernels.classify, "edge": _kernels.edge, "certify": _clearance.certify,
            "trajectory_states": _states.trajectory_states}


@cache
def collision_kernels() -> Any:
    """Return the sphere filter's kernels by name, compiled ahead of time or by numba's JIT (built on first need)."""
    return _native.kernels(NAME, SOURCES, SIGNATURES, _dispatchers)


def kernels_native() -> bool:
    """Return True if every kernel is compiled ahead of time: a filter loads them in milliseconds, without numba."""
    return _native.built(NAME, SOURCES, SIGNATURES) and twins_built()


def kernels_ready() -> bool:
    """Return True if building a filter compiles nothing: its kernels are loaded, built, or cached by numba.

    numba's cache counts only where building them ahead of time failed here: elsewhere it is built next.
    """
    if _loaded or kernels_native():
        return True
    return (_native.failed(NAME, SOURCES, SIGNATURES) or twins_failed()) and kernels_cached()


def count_unfiltered(count: int) -> int:
    """Add `count` states judged without the sphere filter; return how many this process has judged so."""
    global _unfiltered
    _unfiltered += count
    return _unfiltered


def add_setup_time(seconds: float) -> None:
    """Record `seconds` of set-up done inside a search; return None."""
    global _setup_s
    _setup_s += seconds


def setup_time_spent() -> float:
    """Return the set-up seconds recorded in this process so far."""
    return _setup_s
