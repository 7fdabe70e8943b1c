"""moveit_commander's Python API on moveplan: plan, execute and save motions in a script, without ROS.

A MoveIt script ports by changing its imports (moveplan.commander.ros has rospy, tf, tf2_ros
and the message packages under their ROS names)::

    from moveplan import commander as moveit_commander
    from moveplan.commander.ros import rospy, tf2_ros
    from moveplan.commander.ros.geometry_msgs.msg import Pose, PoseStamped, TransformStamped

RobotCommander loads the robot (standing in for the launched move_group), MoveGroupCommander
plans and executes (on the simulated controller of `moveplan execute --fake`),
PlanningSceneInterface adds collision objects, tf's Buffer and StaticTransformBroadcaster
look up and add frames; RobotCommander.save writes what was executed as a plan file the CLI
reads. Failures are moveplan's typed errors (moveplan.core.errors). As MoveIt's, a failed
plan or execution is logged at WARNING, which Python shows on stderr unless the script
configures logging otherwise. docs/python.md has the whole API.
"""

from . import conversions, msgs, ros
from .exception import MoveItCommanderException
from .move_group import MoveGroupCommander
from .robot import RobotCommander
from .scene import PlanningSceneInterface

__all__ = [
    "MoveGroupCommander", "MoveItCommanderException", "PlanningSceneInterface", "RobotCommander", "conversions",
    "msgs", "ros", "roscpp_initialize", "roscpp_shutdown",
]

def roscpp_initialize(args: object = None) -> None:
    """Initialise nothing: there is no roscpp to start; return None."""


def roscpp_shutdown() -> None:
    """Shut nothing down; return None."""
