"""Collision checking: exact geometry through coal, a sphere filter before it, and certification of motions."""

from typing import TYPE_CHECKING

from .._faces import lazy_exports

if TYPE_CHECKING:
    from ._verdicts import MAYBE
    from .checker import CollisionChecker, GeometryMode
    from .compiled import (
        add_setup_time,
        count_unfiltered,
        kernels_loaded,
        kernels_native,
        kernels_ready,
        setup_time_spent,
    )
    from .mesh_arrays import inline_mesh
    from .motion import MotionChecker, build_sphere_filter, exact_checks, scene_checkers, sphere_filter_cached
    from .sphere_filter import SphereFilter

__all__ = [
    "CollisionChecker",
    "GeometryMode",
    "MAYBE",
    "MotionChecker",
    "SphereFilter",
    "add_setup_time",
    "build_sphere_filter",
    "count_unfiltered",
    "exact_checks",
    "inline_mesh",
    "kernels_loaded",
    "kernels_native",
    "kernels_ready",
    "scene_checkers",
    "setup_time_spent",
    "sphere_filter_cached",
]

__getattr__ = lazy_exports(__name__, {
    "CollisionChecker": "checker",
    "GeometryMode": "checker",
    "MAYBE": "_verdicts",
    "MotionChecker": "motion",
    "SphereFilter": "sphere_filter",
    "add_setup_time": "compiled",
    "build_sphere_filter": "motion",
    "count_unfiltered": "compiled",
    "exact_checks": "motion",
    "inline_mesh": "mesh_arrays",
    "kernels_loaded": "compiled",
    "kernels_native": "compiled",
    "kernels_ready": "compiled",
    "scene_checkers": "motion",
    "setup_time_spent": "compiled",
    "sphere_filter_cached": "motion",
})
