"""rospy as a MoveIt script uses it around planning, with no ROS graph: nothing is started, nothing waits.

`init_node` does nothing. Time is the script's own clock: it starts at the wall time and moves
only when the script sleeps (`sleep`, `Rate.sleep`), at once, so a loop waiting for the planning
scene with a timeout ends as soon as the scene is as asked (it is at once: every call applies
before it returns) or the timeout has passed, never on how busy the machine is. A Publisher keeps
what it is given (`published`) and delivers it to nobody, except to what move_group listens to:
a JointState on the fake controllers' topic moves the robot, as MoveIt 1's fake controllers do,
and a PlanningScene, CollisionObject or AttachedCollisionObject on `planning_scene`,
`collision_object` or `attached_collision_object` changes the planning scene, as move_group's
planning scene monitor applies them. Parameters are
the robot's: `robot_description` and `robot_description_semantic` are its URDF and SRDF text.
`loginfo`... go to the logging module (logger "moveplan.commander.ros.rospy").
"""

from __future__ import annotations

import logging
import math
from typing import Any

from ...core.errors import MoveplanError, UsageError
from ..msgs import (
    AttachedCollisionObject,
    CollisionObject,
    Duration,
    JointState,
    PlanningScene,
    PlanningSceneWorld,
    RobotState,
    Time,
    advance_clock,
    clock,
)

__all__ = [
    "Duration", "Publisher", "ROSException", "ROSInterruptException", "Rate", "ServiceProxy", "Subscriber", "Time",
    "get_name",
    "get_namespace",
    "get_param", "get_rostime", "get_time", "has_param", "init_node", "is_shutdown", "logdebug", "logerr",
    "logfatal", "loginfo", "logwarn", "on_shutdown", "search_param", "set_param", "signal_shutdown", "sleep",
    "spin", "wait_for_message", "wait_for_service",
]

_LOG = logging.getLogger(__name__)
_PARAMS: dict[str, Any] = {}
_NODE = ["/unnamed"]
_FAKE_CONTROLLER_TOPIC = "fake_controller_joint_states"  # MoveIt 1's fake controllers listen here
# The topics move_group listens to that change what it plans with: the planning scene, the robot's state.
_LISTENED = (_FAKE_CONTROLLER_TOPIC, "planning_scene", "collision_object", "attached_collision_object")


class ROSException(MoveplanError):
    """rospy's base exception."""


class ROSInterruptException(ROSException, KeyboardInterrupt):
    """rospy's: raised when the node shuts down; never raised here (nothing shuts the script down)."""


def init_node(name: str, *args: Any, **kwargs: Any) -> None:
    """Start no node: there is no ROS graph; remember the name for get_name(); return None."""
    _NODE[0] = name if name.startswith("/") else f"/{name}"


def get_name() -> str:
    """Return the node name init_node was given."""
    return _NODE[0]


def get_namespace() -> str:
    """Return the node's namespace: "/" (no launch file put it in another)."""
    return "/"


def get_time() -> float:
    """Return the script's clock in [s]."""
    return clock()


def get_rostime() -> Time:
    """Return the script's clock as a Time."""
    return Time.now()


def sleep(duration: float | Duration) -> None:
    """Move the script's clock on by `duration` [s] at once: motions are done when go() and execute() return."""
    seconds = duration.to_sec() if isinstance(duration, Duration) else duration
    try:
        advance_clock(float(seconds))
    except (TypeError, ValueError):
        raise UsageError(f"rospy.sleep: expected seconds or a Duration, got {duration!r}") from None


class Rate:
    """rospy.Rate: `sleep()` moves the script's clock on by one period."""

    def __init__(self, hz: float, reset: bool = False) -> None:
        if not isinstance(hz, int | float) or not 0 < hz < math.inf:
            raise UsageError(f"rospy.Rate: expected a rate > 0 in [Hz], got {hz!r}")
        self.period = 1.0 / hz

    def sleep(self) -> None:
        """Move the clock on by one period; return None."""
        advance_clock(self.period)

    def remaining(self) -> Duration:
        """Return the time left until the next period: none, sleep() never waits."""
        return Duration()


def is_shutdown() -> bool:
    """Return False: nothing shuts the script down from outside."""
    return False


def on_shutdown(hook: Any) -> None:
    """Remember nothing: the script ends when it ends; return None."""


def signal_shutdown(reason: str) -> None:
    """Do nothing (no node to shut down); return None."""


def spin() -> None:
    """Return at once: there are no callbacks to wait for."""


class Publisher:
    """rospy.Publisher: keeps every message published in `published`; what move_group listens to applies.

    A JointState on `.../fake_controller_joint_states` sets those joints of the robot created
    last, as MoveIt 1's fake controllers do; a PlanningScene on `planning_scene`, a
    CollisionObject on `collision_object`, an AttachedCollisionObject on
    `attached_collision_object` change its planning scene, as move_group's monitor applies them.
    """

    def __init__(self, name: str, data_class: Any = None, queue_size: int | None = None, latch: bool = False,
                 **kwargs: Any) -> None:
        self.name = name
        self.resolved_name = name if name.startswith("/") else f"/{name}"
        self.data_class = data_class
        self.published: list[Any] = []

    def publish(self, *args: Any, **kwargs: Any) -> None:
        """Keep the message (built from the arguments as rospy builds it); return None."""
        message = args[0] if len(args) == 1 and not kwargs else self.data_class(*args, **kwargs)
        self.published.append(message)
        topic = self.name.rstrip("/").rsplit("/", 1)[-1]
        if topic in _LISTENED:
            from .._messages import apply_scene
            from .._world import current_world

            world = current_world(None, f"Publisher('{self.name}')")
            where = f"Publisher('{self.name}').publish"
            if topic == _FAKE_CONTROLLER_TOPIC and isinstance(message, JointState):
                world.set_joints(message, where)
            elif topic == "planning_scene" and isinstance(message, PlanningScene):
                apply_scene(world, message)
            elif topic == "collision_object" and isinstance(message, CollisionObject):
                apply_scene(world, PlanningScene(world=PlanningSceneWorld([message]), is_diff=True))
            elif topic == "attached_collision_object" and isinstance(message, AttachedCollisionObject):
                apply_scene(world, PlanningScene(robot_state=RobotState(attached_collision_objects=[message]),
                                                 is_diff=True))

    def get_num_connections(self) -> int:
        """Return 0: nothing subscribes."""
        return 0

    def unregister(self) -> None:
        """Do nothing; return None."""


class Subscriber:
    """rospy.Subscriber: nothing is ever published to it."""

    def __init__(self, name: str, data_class: Any = None, callback: Any = None, *args: Any, **kwargs: Any) -> None:
        self.name = name

    def unregister(self) -> None:
        """Do nothing; return None."""


def wait_for_message(topic: str, topic_type: Any, timeout: float | None = None) -> Any:
    """Raise ROSException: no topic carries messages here (the robot's state: RobotCommander.get_current_state)."""
    raise ROSException(f"wait_for_message('{topic}'): there is no ROS graph; read the robot's state with "
                       "RobotCommander.get_current_state() instead")


class ServiceProxy:
    """rospy.ServiceProxy: there are no ROS services; calling one raises ROSException saying what serves instead."""

    def __init__(self, name: str, service_class: Any = None, *args: Any, **kwargs: Any) -> None:
        self.resolved_name = name

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        """Raise ROSException: nothing serves the call here."""
        raise ROSException(f"ServiceProxy('{self.resolved_name}'): there is no ROS graph to call; the commander's "
                           "methods do what move_group's services do (compute_ik: set_joint_value_target(pose), "
                           "get_planning_scene: PlanningSceneInterface.get_planning_scene)")

    call = __call__

    def wait_for_service(self, timeout: float | None = None) -> None:
        """Return at once."""


def wait_for_service(service: str, timeout: float | None = None) -> None:
    """Return at once: the services MoveIt scripts call are the commander's methods here."""


def get_param(name: str, default: Any = KeyError) -> Any:
    """Return a parameter: the robot's `robot_description` (URDF) and `robot_description_semantic` (SRDF), or one set.

    Raises:
        KeyError: Not set and no default, as rospy's does.
    """
    key = _key(name)
    value = _robot_params().get(key, _PARAMS.get(key, default))
    if value is KeyError:
        raise KeyError(name)
    return value


def has_param(name: str) -> bool:
    """Return True if get_param(name) has a value."""
    key = _key(name)
    return key in _PARAMS or key in _robot_params()


def set_param(name: str, value: Any) -> None:
    """Set a parameter; return None."""
    _PARAMS[_key(name)] = value


def search_param(name: str) -> str | None:
    """Return the full name of a parameter called `name` (the robot's or one set), else None."""
    key = _key(name)
    return f"/{key}" if key in _PARAMS or key in _robot_params() else None


def _key(name: str) -> str:
    """Return a parameter name without namespace slashes or rospy's private `~`."""
    return str(name).strip("/").lstrip("~")


def _robot_params() -> dict[str, str]:
    """Return the description parameters of the robot created last (of $MOVEPLAN_ROBOT's, made now, if none is).

    Raises:
        UsageError: No robot was created and MOVEPLAN_ROBOT is not set: a script waiting for
            the parameter would wait forever.
    """
    from .._world import current_world

    world = current_world(None, "rospy: the robot_description parameters")
    return {"robot_description": world.config.urdf, "robot_description_semantic": world.config.srdf_text}


def loginfo(message: Any, *args: Any, **kwargs: Any) -> None:
    """Log `message` (%-formatted with `args`) at INFO; return None."""
    _LOG.info(message, *args)


def logwarn(message: Any, *args: Any, **kwargs: Any) -> None:
    """Log `message` at WARNING; return None."""
    _LOG.warning(message, *args)


def logerr(message: Any, *args: Any, **kwargs: Any) -> None:
    """Log `message` at ERROR; return None."""
    _LOG.error(message, *args)


def logfatal(message: Any, *args: Any, **kwargs: Any) -> None:
    """Log `message` at CRITICAL; return None."""
    _LOG.critical(message, *args)


def logdebug(message: Any, *args: Any, **kwargs: Any) -> None:
    """Log `message` at DEBUG; return None."""
    _LOG.debug(message, *args)
