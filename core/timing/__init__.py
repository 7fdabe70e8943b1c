"""Time parameterisation: a joint-space path timed within the velocity and acceleration limits."""

from typing import TYPE_CHECKING

from .._faces import lazy_exports

if TYPE_CHECKING:
    from ._twins import compiled_fastest_speeds, compiled_quintic_peak_rates, twins_built, twins_failed
    from .parameterize import rest_to_rest, time_parameterize

__all__ = [
    "compiled_fastest_speeds",
    "compiled_quintic_peak_rates",
    "rest_to_rest",
    "time_parameterize",
    "twins_built",
    "twins_failed",
]

__getattr__ = lazy_exports(__name__, {
    "compiled_fastest_speeds": "_twins",
    "compiled_quintic_peak_rates": "_twins",
    "rest_to_rest": "parameterize",
    "time_parameterize": "parameterize",
    "twins_built": "_twins",
    "twins_failed": "_twins",
})
