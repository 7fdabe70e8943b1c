"""moveplan's median is np.median's, for the finite values it is given."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from moveplan.core._median import median


@given(arrays(np.float64, st.tuples(st.integers(1, 30), st.integers(1, 4)),
              elements=st.floats(-1e6, 1e6, allow_nan=False)))
def test_median_is_numpys_along_the_first_axis(values: np.ndarray) -> None:
    assert np.array_equal(median(values), np.median(values, axis=0))
    assert np.array_equal(median(values[:, 0]), np.median(values[:, 0]))
