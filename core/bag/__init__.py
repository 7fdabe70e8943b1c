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

from typing import TYPE_CHECKING

from .._faces import lazy_exports

if TYPE_CHECKING:
    from ._sample_store import JointStateStore
    from .cdr import seconds_to_ns, stamps_ns
    from .container import BagSummary, TopicSummary, atomic_file, output_problem, staged_file, summarize
    from .execution_file import EXECUTION_RESULT_TOPIC, ExecutedStep, ExecutionWriter, execution_writer, write_execution
    from .jointstates import open_joint_states, read_joint_states
    from .plan_file import END_STATES_KEY, PlanFile, PlanStepRecord, plan_urdf, read_plan
    from .plan_writer import write_plan

__all__ = [
    "BagSummary",
    "END_STATES_KEY",
    "EXECUTION_RESULT_TOPIC",
    "ExecutedStep",
    "ExecutionWriter",
    "JointStateStore",
    "PlanFile",
    "PlanStepRecord",
    "TopicSummary",
    "atomic_file",
    "execution_writer",
    "open_joint_states",
    "output_problem",
    "plan_urdf",
    "read_joint_states",
    "read_plan",
    "seconds_to_ns",
    "staged_file",
    "stamps_ns",
    "summarize",
    "write_execution",
    "write_plan",
]

__getattr__ = lazy_exports(__name__, {
    "BagSummary": "container",
    "END_STATES_KEY": "plan_file",
    "EXECUTION_RESULT_TOPIC": "execution_file",
    "ExecutedStep": "execution_file",
    "ExecutionWriter": "execution_file",
    "JointStateStore": "_sample_store",
    "PlanFile": "plan_file",
    "PlanStepRecord": "plan_file",
    "TopicSummary": "container",
    "atomic_file": "container",
    "execution_writer": "execution_file",
    "open_joint_states": "jointstates",
    "output_problem": "container",
    "plan_urdf": "plan_file",
    "read_joint_states": "jointstates",
    "read_plan": "plan_file",
    "seconds_to_ns": "cdr",
    "staged_file": "container",
    "stamps_ns": "cdr",
    "summarize": "container",
    "write_execution": "execution_file",
    "write_plan": "plan_writer",
})
