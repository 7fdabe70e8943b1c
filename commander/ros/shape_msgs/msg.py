"""shape_msgs/msg: the message types MoveIt scripts use (moveplan.commander.msgs defines them)."""

from ...msgs import Mesh, MeshTriangle, Plane, SolidPrimitive

__all__ = [
    "Mesh", "MeshTriangle", "Plane", "SolidPrimitive",
]
