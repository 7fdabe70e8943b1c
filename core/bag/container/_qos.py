"""QoS in rosbag2's channel metadata: the offered profiles written per topic, and read back.

rosbag2 stores each topic's offered QoS profiles as YAML in the channel's
"offered_qos_profiles" metadata; `ros2 bag play` offers them again, so a latched
(transient_local) topic reaches late subscribers.
"""

from __future__ import annotations

import re

__all__ = ["durability", "offered_qos_profiles"]


def offered_qos_profiles(latched: bool) -> str:
    """Return the offered_qos_profiles YAML rosbag2 stores per topic, with integer enums.

    Humble's player reads the enums as integers only; Jazzy's reads both. history 1 =
    keep_last, reliability 1 = reliable, durability 1 = transient_local (latched) or
    2 = volatile, liveliness 1 = automatic; durations are rmw's "infinite".
    """
    infinite = "    sec: 9223372036\n    nsec: 854775807\n"
    return (
        "- history: 1\n"
        f"  depth: {1 if latched else 10}\n"
        "  reliability: 1\n"
        f"  durability: {1 if latched else 2}\n"
        f"  deadline:\n{infinite}"
        f"  lifespan:\n{infinite}"
        "  liveliness: 1\n"
        f"  liveliness_lease_duration:\n{infinite}"
        "  avoid_ros_namespace_conventions: false"
    )


def durability(offered_qos_profiles: str) -> str:
    """Return "transient_local" if all offered profiles are, else "volatile"; "" if none given."""
    # Humble writes integer enums, Jazzy writes names. No yaml here: it enters through config only.
    values = re.findall(r"^[\s-]*durability:\s*['\"]?(\w+)", offered_qos_profiles, re.MULTILINE)
    enums = {"1": "transient_local", "2": "volatile"}
    names = [enums.get(value, value.lower()) for value in values]
    if not names:
        return ""
    return "transient_local" if all(name == "transient_local" for name in names) else "volatile"
