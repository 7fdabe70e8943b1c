"""ROS 2 bags: MCAP reading and writing, rosbag2 sqlite3 reading, CDR encoding, and the message layouts moveplan writes.

Three floors, as the mcap Python packages split container and codec:
- `container/`: bags as records and files, whatever the messages: a bag written atomically
  (writer, qos), MCAP read with the mcap package (mcap_scan, summary) and without it
  (mcap_records, mcap_linear, topic_reader: one topic in bulk), chunks checked
  (chunk_codecs, mcap_verify), rosbag2's sqlite3 storage (db3), and which files a recording
  is (files).
- `cdr/`: messages as bytes: the CDR writer (primitives), the ros2msg definitions moveplan
  ships (definitions, msgs/), the schema-driven encoder (generic), messages as dicts
  (messages) and the hand-written twins of the big ones (bulk, joint_state).
- here, on both: the files moveplan writes and reads: plan files (plan_file, plan_writer),
  executed files (execution_file) and joint states from any recording (jointstates, with
  _sample_store: decoded samples kept on disk, so that reading a recording takes the same
  memory for an hour as for a minute).
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
    "BagSummary": "container.summary", "TopicSummary": "container.summary", "summarize": "container.summary",
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

