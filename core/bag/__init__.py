"""ROS 2 bags: MCAP reading and writing, rosbag2 sqlite3 reading, CDR encoding, and the message layouts moveplan writes.

Two layers, as the mcap Python package splits container and codec. The container:
bag_writer (a bag written atomically), qos, mcap_scan and summary (reading with the mcap
package), mcap_records, mcap_linear and topic_reader (one topic in bulk, without it),
db3 (rosbag2's sqlite3 storage) and bag_files (which files a recording is). The codec, on
top: cdr, definitions, generic_cdr, messages, message_cdr, jointstate_cdr. The files
moveplan writes and reads are built from both: plan_file and plan_writer,
execution_file, jointstates (with sample_store: decoded samples kept on disk, so that
reading a recording takes the same memory for an hour as for a minute).
"""

from importlib import import_module
from typing import Any

# Loaded on first use (PEP 562): writing a plan needs none of the readers (sqlite3, the linear
# MCAP scan, the sample store), and every command pays for what its imports load.
_HOME = {
    "EXECUTION_RESULT_TOPIC": "execution_file", "ExecutedStep": "execution_file", "write_execution": "execution_file",
    "JointStateStore": "jointstates", "open_joint_states": "jointstates", "read_joint_states": "jointstates",
    "PlanFile": "plan_file", "PlanStepRecord": "plan_file", "plan_urdf": "plan_file", "read_plan": "plan_file",
    "write_plan": "plan_writer",
    "BagSummary": "summary", "TopicSummary": "summary", "summarize": "summary",
}

__all__ = [
    "EXECUTION_RESULT_TOPIC",
    "BagSummary",
    "ExecutedStep",
    "JointStateStore",
    "PlanFile",
    "PlanStepRecord",
    "TopicSummary",
    "open_joint_states",
    "plan_urdf",
    "read_joint_states",
    "read_plan",
    "summarize",
    "write_execution",
    "write_plan",
]


def __getattr__(name: str) -> Any:
    """Return the exported name `name`, importing the module that defines it."""
    if name not in _HOME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(import_module(f".{_HOME[name]}", __name__), name)

