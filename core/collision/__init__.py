"""Collision checking: exact geometry through coal, a sphere filter before it, and certification of motions."""

from .checker import CollisionChecker
from .motion import MotionChecker
from .sphere_filter import SphereFilter, UnsupportedJoint

__all__ = ["CollisionChecker", "MotionChecker", "SphereFilter", "UnsupportedJoint"]
