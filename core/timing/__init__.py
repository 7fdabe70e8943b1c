"""Time parameterisation: a joint-space path timed within the velocity and acceleration limits."""

from .parameterize import rest_to_rest, time_parameterize

__all__ = ["rest_to_rest", "time_parameterize"]
