"""Collision checking: exact geometry through coal, a sphere filter before it, and certification of motions."""

from typing import TYPE_CHECKING

from .._faces import lazy_exports

if TYPE_CHECKING:
    from ._setup_clock import add_setup_time, setup_time_spent
    from ._verdicts import MAYBE
    from .checker import CollisionChecker, GeometryMode
    from .kernel_cache import kernels_cached
    from .motion import MotionChecker, build_sphere_filter, exact_checks, hull_checker
    from .sphere_filter import SphereFilter, kernels_loaded

__all__ = [
    "CollisionChecker",
    "GeometryMode",
    "MAYBE",
    "MotionChecker",
    "SphereFilter",
    "add_setup_time",
    "build_sphere_filter",
    "exact_checks",
    "hull_checker",
    "kernels_cached",
    "kernels_loaded",
    "setup_time_spent",
]

__getattr__ = lazy_exports(__name__, {
    "CollisionChecker": "checker",
    "GeometryMode": "checker",
    "MAYBE": "_verdicts",
    "MotionChecker": "motion",
    "SphereFilter": "sphere_filter",
    "add_setup_time": "_setup_clock",
    "build_sphere_filter": "motion",
    "exact_checks": "motion",
    "hull_checker": "motion",
    "kernels_cached": "kernel_cache",
    "kernels_loaded": "sphere_filter",
    "setup_time_spent": "_setup_clock",
})
