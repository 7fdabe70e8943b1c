"""Poses read from scene and request files: the identity judged as np.allclose judges it."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from moveplan.core.config.poses import is_identity

# Off by nothing, by less or more than each tolerance (1e-9 everywhere, 1e-5 more on the diagonal), or not a number.
_OFFSETS = st.sampled_from([0.0, 5e-10, 1e-9, 2e-9, 9e-6, 1.0001e-5, 1e-3, np.nan, np.inf, -np.inf])


@given(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 3), _OFFSETS, st.sampled_from([-1.0, 1.0])),
                max_size=4))
def test_a_transform_is_the_identity_exactly_when_allclose_says_so(
    changes: list[tuple[int, int, float, float]],
) -> None:
    # A scene's virtual joint and fixed frames must be the identity: a frame a few nanometres off still is one.
    transform = np.eye(4)
    with np.errstate(invalid="ignore"):  # infinities of both signs on one entry make it not a number
        for row, column, offset, sign in changes:
            transform[row, column] += sign * offset
    assert is_identity(transform) == np.allclose(transform, np.eye(4), atol=1e-9)
