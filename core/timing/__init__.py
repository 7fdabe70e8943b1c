"""Time parameterisation: a joint-space path timed within the velocity and acceleration limits."""

from typing import TYPE_CHECKING

from .._faces import lazy_exports

if TYPE_CHECKING:
    from ._compiled import compiled_fastest_speeds, compiled_quintic_peak_rates
    from .parameterize import rest_to_rest, time_parameterize

__all__ = [
    "compiled_fastest_speeds",
    "compiled_quintic_peak_rates",
    "rest_to_rest",
    "time_parameterize",
]

__getattr__ = lazy_exports(__name__, {
    "compiled_fastest_speeds": "_compiled",
    "compiled_quintic_peak_rates": "_compiled",
    "rest_to_rest": "parameterize",
    "time_parameterize": "parameterize",
})
