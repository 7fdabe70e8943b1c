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

from .execution_file import EXECUTION_RESULT_TOPIC, ExecutedStep, write_execution
from .jointstates import JointStateStore, open_joint_states, read_joint_states
from .plan_file import PlanFile, PlanStepRecord, plan_urdf, read_plan
from .plan_writer import write_plan
from .summary import BagSummary, TopicSummary, summarize

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
