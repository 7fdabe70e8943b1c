"""Which ros2_controllers release the simulated JointTrajectoryController behaves as.

Releases differ in how JTC blends from the state it reads to a trajectory whose first point
lies after time 0 (ros2_controllers PR #2043, "Fill point_before_trajectory with same
information as trajectory"): from Humble 2.52.0, Jazzy 4.36.0, Kilted 5.11.0 and Rolling
6.2.0 on, a state without velocities (or accelerations) gets zeros where the trajectory's first
point has them, so the blend has the trajectory's spline degree; earlier releases blend
linearly (or cubically) from the bare state.
"""

from __future__ import annotations

import re

from ..errors import UsageError

__all__ = ["DEFAULT_RELEASE", "RELEASES", "fills_point_before"]

DEFAULT_RELEASE = "jazzy"
"""The newest Jazzy release: what `apt install ros-jazzy-ros2-controllers` installs today."""

# Per major version (a ROS distro's series), the first release with PR #2043.
_FILLED_FROM = {2: (2, 52), 4: (4, 36), 5: (5, 11), 6: (6, 2)}
RELEASES = {"humble": 2, "jazzy": 4, "kilted": 5, "rolling": 6}
"""A distro's name means its newest release."""


def fills_point_before(release: str) -> bool:
    """Return True if ros2_controllers `release` (a distro's name or X.Y[.Z]) fills the point before with zeros.

    Raises:
        UsageError: Neither a known distro nor a version number of a ROS 2 distro's series.
    """
    name = release.strip().lower()
    if name in RELEASES:
        return True
    match = re.fullmatch(r"(\d+)\.(\d+)(?:\.\d+)?", name)
    if match is None:
        raise UsageError(f"--ros2-controllers {release!r}: expected a distro ({', '.join(RELEASES)}) or a "
                         "ros2_controllers version such as 4.35.0")
    major, minor = int(match.group(1)), int(match.group(2))
    first = _FILLED_FROM.get(major)
    # Iron's 3.x and older series never got it; a future series starts with it.
    return (major, minor) >= first if first is not None else major > max(_FILLED_FROM)
