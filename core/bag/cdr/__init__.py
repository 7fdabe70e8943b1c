"""ROS 2 messages as CDR bytes: the writer, the ros2msg definitions moveplan ships, and the encoders.

The schema-driven encoder (generic) writes any message given as a dict (messages); the
hand-written twins (bulk, joint_state) write the big, numerous ones with bulk float packing,
to the same bytes. Nothing here knows a file format (that is `..container`'s, below).
"""

from typing import TYPE_CHECKING

from ..._faces import lazy_exports

if TYPE_CHECKING:
    from .bulk import (
        controller_states_cdr,
        display_trajectory_cdr,
        joint_trajectory_cdr,
        marker_array_cdr,
        tf_messages_cdr,
    )
    from .definitions import CONTROLLER_STATE, schema_text
    from .generic import encoder
    from .joint_state import JOINT_STATE_TYPE, JointStateLayout, check_definition, encode_joint_states, parse_layout
    from .messages import Message, marker_array, seconds_to_ns, stamps_ns, string_message, trajectory_from_message

__all__ = [
    "CONTROLLER_STATE",
    "JOINT_STATE_TYPE",
    "JointStateLayout",
    "Message",
    "check_definition",
    "controller_states_cdr",
    "display_trajectory_cdr",
    "encode_joint_states",
    "encoder",
    "joint_trajectory_cdr",
    "marker_array",
    "marker_array_cdr",
    "parse_layout",
    "schema_text",
    "seconds_to_ns",
    "stamps_ns",
    "string_message",
    "tf_messages_cdr",
    "trajectory_from_message",
]

__getattr__ = lazy_exports(__name__, {
    "CONTROLLER_STATE": "definitions",
    "JOINT_STATE_TYPE": "joint_state",
    "JointStateLayout": "joint_state",
    "Message": "messages",
    "check_definition": "joint_state",
    "controller_states_cdr": "bulk",
    "display_trajectory_cdr": "bulk",
    "encode_joint_states": "joint_state",
    "encoder": "generic",
    "joint_trajectory_cdr": "bulk",
    "marker_array": "messages",
    "marker_array_cdr": "bulk",
    "parse_layout": "joint_state",
    "schema_text": "definitions",
    "seconds_to_ns": "messages",
    "stamps_ns": "messages",
    "string_message": "messages",
    "tf_messages_cdr": "bulk",
    "trajectory_from_message": "messages",
})
