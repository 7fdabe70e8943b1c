"""The few rospy calls a MoveIt script makes around planning, for scripts that keep them: no ROS node is started.

`init_node` does nothing, `sleep` returns at once (nothing runs in the background to wait
for), `is_shutdown` is False, and `loginfo`/`logwarn`/`logerr`/`logdebug` go to the logging
module (logger "moveplan.commander.rospy"), shown only when the script configures logging.
"""

from __future__ import annotations

import logging
from typing import Any

from .msgs import Duration, Time

__all__ = ["Duration", "Time", "init_node", "is_shutdown", "logdebug", "logerr", "loginfo", "logwarn", "sleep"]

_LOG = logging.getLogger(__name__)


def init_node(name: str, *args: Any, **kwargs: Any) -> None:
    """Start no node: there is no ROS graph; return None."""


def sleep(duration: float | Duration) -> None:
    """Return at once: motions are executed before go() and execute() return."""


def is_shutdown() -> bool:
    """Return False: nothing shuts the script down from outside."""
    return False


def loginfo(message: Any, *args: Any) -> None:
    """Log `message` (%-formatted with `args`) at INFO; return None."""
    _LOG.info(message, *args)


def logwarn(message: Any, *args: Any) -> None:
    """Log `message` at WARNING; return None."""
    _LOG.warning(message, *args)


def logerr(message: Any, *args: Any) -> None:
    """Log `message` at ERROR; return None."""
    _LOG.error(message, *args)


def logdebug(message: Any, *args: Any) -> None:
    """Log `message` at DEBUG; return None."""
    _LOG.debug(message, *args)
