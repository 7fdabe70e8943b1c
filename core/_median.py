"""The median as np.median takes it, without np.median: its first call imports numpy.ma (10-40 ms of a command)."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

__all__ = ["median"]


def median(values: npt.ArrayLike, axis: int = 0) -> NDArray[np.float64]:
    """Return the median of finite `values` along `axis`: the middle value, or the mean of the two middle ones."""
    ordered = np.sort(np.asarray(values, dtype=np.float64), axis=axis)
    count = ordered.shape[axis]
    middle = count // 2
    high = np.take(ordered, middle, axis=axis)
    if count % 2:
        return np.asarray(high)
    return np.asarray((np.take(ordered, middle - 1, axis=axis) + high) / 2)
