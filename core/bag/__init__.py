"""ROS 2 bags: MCAP reading and writing, CDR encoding, and the message layouts moveplan writes."""

from .jointstates import read_joint_states
from .recording import EXECUTION_RESULT_TOPIC, PlanFile, read_plan, summarize, write_plan

__all__ = ["EXECUTION_RESULT_TOPIC", "PlanFile", "read_joint_states", "read_plan", "summarize", "write_plan"]
