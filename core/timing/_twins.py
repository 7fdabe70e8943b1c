"""The timing passes' compiled twins, called from Python: built ahead of time (core/_native.py), else numba's JIT.

core/timing/_compiled.py holds the kernels; these wrappers take numpy arrays as the numpy passes
do, and raise as they do. Used once a sphere filter is built (core/pipeline/_step.py), which
loads these with its own kernels.
"""

from __future__ import annotations

from functools import cache
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import _native
from ..errors import PlanningFailed
from ._topp import SpeedProfile

__all__ = ["compiled_fastest_speeds", "compiled_quintic_peak_rates", "twins_built", "twins_failed"]

NAME = "moveplan_timing"
SOURCES = (Path(__file__).resolve().with_name("_compiled.py"),)
"""The kernel file: its bytes name the sources it compiles in (tests/foundation/test_kernel_inputs.py)."""
SIGNATURES = {
    "speeds": "Tuple((float64[::1], float64[::1], boolean))(float64[::1], float64[:, ::1], float64[:, ::1], "
              "float64[::1], float64[::1], boolean[::1], float64)",
    "peaks": "UniTuple(float64[::1], 2)(float64[::1], float64[:, ::1], float64[:, ::1], float64[:, ::1])",
}
"""The types the wrappers below pass, exactly."""


def _dispatchers() -> dict[str, Any]:
    """Return the kernels' numba dispatchers (importing numba)."""
    from ._compiled import KERNELS

    return KERNELS


@cache
def _kernels() -> Any:
    """Return the kernels by name, compiled ahead of time or by numba's JIT (built here on first need)."""
    return _native.kernels(NAME, SOURCES, SIGNATURES, _dispatchers)


def twins_built() -> bool:
    """Return True if the twins are compiled ahead of time: they load without numba."""
    return _native.built(NAME, SOURCES, SIGNATURES)


def twins_failed() -> bool:
    """Return True if compiling the twins ahead of time failed here: numba's JIT runs them."""
    return _native.failed(NAME, SOURCES, SIGNATURES)


def compiled_fastest_speeds(
    grid: NDArray[np.float64],
    first: NDArray[np.float64],
    second: NDArray[np.float64],
    straight: NDArray[np.bool_],
    max_velocity: NDArray[np.float64],
    max_acceleration: NDArray[np.float64],
    min_interval_s: float = 0.0,
) -> SpeedProfile:
    """Return topp.fastest_speeds(...) (same arguments, same result), computed by compiled code."""
    arrays = (_plain(x, np.float64) for x in (grid, first, second, max_velocity, max_acceleration))
    s, squared, finite = _kernels().speeds(*arrays, _plain(straight, np.bool_), float(min_interval_s))
    if not finite:
        raise PlanningFailed("time parameterisation found no motion along the path within the limits")
    return SpeedProfile(s, squared)


def compiled_quintic_peak_rates(
    knots: NDArray[np.float64], p: NDArray[np.float64], v: NDArray[np.float64], a: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Return trajectory.quintic_peak_rates(...) (same arguments, same result), computed by compiled code."""
    if len(knots) == 1:
        return np.abs(v[0]), np.abs(a[0])
    peaks: tuple[NDArray[np.float64], NDArray[np.float64]] = _kernels().peaks(*(_plain(x, np.float64)
                                                                                 for x in (knots, p, v, a)))
    return peaks


def _plain(values: NDArray[Any], dtype: type) -> NDArray[Any]:
    """Return `values` as a writable C-ordered array of `dtype`, copied only if it is not one already.

    numba compiles a version per array type, read-only ones included: seconds, mid-plan.
    """
    if values.dtype == dtype and values.flags.c_contiguous and values.flags.writeable:
        return values
    return np.array(values, dtype=dtype, order="C")
