"""Time parameterisation: a joint-space path timed within the velocity and acceleration limits."""

from typing import TYPE_CHECKING

from .._faces import lazy_exports

if TYPE_CHECKING:
    from .parameterize import rest_to_rest, time_parameterize

__all__ = [
    "rest_to_rest",
    "time_parameterize",
]

__getattr__ = lazy_exports(__name__, {
    "rest_to_rest": "parameterize",
    "time_parameterize": "parameterize",
})
