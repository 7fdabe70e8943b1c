"""ROS 2 bags: MCAP reading and writing, CDR encoding, and the message layouts moveplan writes.

Two layers, as the mcap Python package splits container and codec. The container:
bag_writer (a bag written atomically), qos, mcap_scan and summary (reading with the mcap
package), mcap_records and topic_reader (one topic in bulk, without it). The codec, on
top: cdr, definitions, generic_cdr, messages, message_cdr, jointstate_cdr. The files
moveplan writes and reads are built from both: plan_file and plan_writer,
execution_file, jointstates.
"""

from .execution_file import EXECUTION_RESULT_TOPIC, ExecutedStep, write_execution
from .jointstates import read_joint_states
from .plan_file import PlanFile, PlanStepRecord, plan_urdf, read_plan
from .plan_writer import write_plan
from .summary import BagSummary, TopicSummary, summarize

__all__ = [
    "EXECUTION_RESULT_TOPIC",
    "BagSummary",
    "ExecutedStep",
    "PlanFile",
    "PlanStepRecord",
    "TopicSummary",
    "plan_urdf",
    "read_joint_states",
    "read_plan",
    "summarize",
    "write_execution",
    "write_plan",
]
