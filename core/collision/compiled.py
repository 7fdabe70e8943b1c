"""The compiled kernels' state in this process, in one place: are they loaded, are they cached, and set-up time.

numba's kernels (the sphere filter's, the certification walk's, timing's twins) are compiled
once per install and loaded once per process. Who decides by it asks here, by name:
- the one-shot commands' rent-or-buy rule (core/pipeline/_checks.py) counts the states this
  process has judged without the sphere filter (`count_unfiltered`), and builds it sooner when
  `kernels_ready()`: loading costs less than a compilation;
- a search keeps set-up done inside it (a filter built mid-step) off its planning-time cap,
  through `add_setup_time` and `setup_time_spent`: the budget of work, not the clock, decides
  the path on a cold or busy machine;
- a step times its path with the compiled passes when its checks carry a built filter
  (MotionChecker.compiled).
"""

from __future__ import annotations

from ._kernel_cache import kernels_cached

__all__ = ["add_setup_time", "count_unfiltered", "kernels_loaded", "kernels_ready", "mark_kernels_loaded",
           "setup_time_spent"]

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


def kernels_ready() -> bool:
    """Return True if building a filter costs no compilation: the kernels are loaded, or numba's cache holds them."""
    return _loaded or kernels_cached()


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
