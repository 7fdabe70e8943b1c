"""moveit_commander's Python API on moveplan: plan, execute and save motions in a script, without ROS.

A MoveIt workshop script ports by changing its imports::

    from moveplan import commander as moveit_commander
    from moveplan.commander import tf as tf2_ros
    from moveplan.commander.msgs import Pose, PoseStamped, TransformStamped

RobotCommander loads the robot (standing in for the launched move_group), MoveGroupCommander
plans and executes (on the simulated controller of `moveplan execute --fake`),
PlanningSceneInterface adds collision objects, tf's Buffer and StaticTransformBroadcaster
look up and add frames; RobotCommander.save writes what was executed as a plan file the CLI
reads. Failures are moveplan's typed errors (moveplan.core.errors); nothing is printed:
messages go to the logging module. docs/python.md has the whole API.
"""

import logging

from ..core.errors import MoveplanError
from . import conversions, msgs, tf, transformations
from .move_group import MoveGroupCommander
from .robot import RobotCommander
from .scene import PlanningSceneInterface

__all__ = [
    "MoveGroupCommander", "MoveItCommanderException", "PlanningSceneInterface", "RobotCommander", "conversions",
    "msgs", "roscpp_initialize", "roscpp_shutdown", "tf", "transformations",
]

MoveItCommanderException = MoveplanError
"""moveit_commander's exception: every moveplan error is one, so `except MoveItCommanderException` catches them."""

# A library's records go nowhere unless the script configures logging (Python's last-resort
# handler would print warnings to stderr).
logging.getLogger("moveplan").addHandler(logging.NullHandler())


def roscpp_initialize(args: object = None) -> None:
    """Initialise nothing: there is no roscpp to start; return None."""


def roscpp_shutdown() -> None:
    """Shut nothing down; return None."""
