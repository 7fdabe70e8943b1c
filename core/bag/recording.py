"""MCAP I/O: plans and executions written as ROS 2 bags, plans and summaries read back.

The only module that imports mcap and mcap_ros2. Plan and executed files follow DESIGN
section 6 and rosbag2's own layout, so `ros2 bag`, Foxglove and rosbags open them:
profile ros2, ros2msg schemas, CDR messages, QoS in channel metadata, a "rosbag2"
metadata record, statistics, chunk and message indexes, CRCs.
"""

from __future__ import annotations

import json
import os
import struct
from collections import Counter
from collections.abc import Callable, Collection, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cache
from importlib.metadata import version
from pathlib import Path
from typing import IO, Any

import numpy as np
import zstandard
from mcap.exceptions import EndOfFile, McapError
from mcap.opcode import Opcode
from mcap.reader import SeekingReader
from mcap.records import Attachment, Channel, Header, McapRecord, Message, Metadata, Schema
from mcap.stream_reader import MAGIC_SIZE, StreamReader
from mcap.writer import LIBRARY_IDENTIFIER, CompressionType, Writer

# Private module: mcap_ros2's public Writer cannot set channel metadata (no QoS, so nothing
# is latched on playback); serialize_dynamic is the encoder behind it, built from schema text.
from mcap_ros2._dynamic import serialize_dynamic
from mcap_ros2.decoder import DecoderFactory
from numpy.typing import NDArray

from ..errors import InputError
from ..types import JointTrajectory, Plan, TfSamples
from . import messages as msgs
from .jointstate_cdr import encode_joint_states

__all__ = [
    "EXECUTION_RESULT_TOPIC",
    "BagSummary",
    "PlanFile",
    "PlanStepRecord",
    "TopicSummary",
    "read_plan",
    "summarize",
    "ExecutedStep",
    "plan_urdf",
    "write_execution",
    "write_plan",
]

EXECUTION_RESULT_TOPIC = "/moveplan/execution_result"
"""Topic of an executed file's result: a std_msgs/String holding the result JSON."""

_TRAJECTORY = "/planned_trajectory"
_ROBOT_DESCRIPTION = "/robot_description"
# topic -> (message type, latched). Latched topics are offered transient_local, so a late
# subscriber (RViz, robot_state_publisher) still gets them from `ros2 bag play`. The
# trajectory stays volatile: a controller that joins late must not receive a stale step.
_TOPICS: dict[str, tuple[str, bool]] = {
    "/robot_description": ("std_msgs/msg/String", True),
    "/tf_static": ("tf2_msgs/msg/TFMessage", True),
    "/planning_scene_markers": ("visualization_msgs/msg/MarkerArray", True),
    "/display_planned_path": ("moveit_msgs/msg/DisplayTrajectory", True),
    _TRAJECTORY: ("trajectory_msgs/msg/JointTrajectory", False),
    "/tf": ("tf2_msgs/msg/TFMessage", False),
}
_PLAN_KEYS = ("robot_name", "group", "planning_frame", "step_names", "limits", "distro")
_MEDIA_TYPES = {".urdf": "application/xml", ".srdf": "application/xml", ".yaml": "application/yaml"}
_STRING = "std_msgs/msg/String"
_JOINT_STATE = "sensor_msgs/msg/JointState"
_CONTROLLER_STATE = "control_msgs/msg/JointTrajectoryControllerState"
_TF = "tf2_msgs/msg/TFMessage"
_MAGIC = b"\x89MCAP0\r\n"
# What mcap and the decompressors raise on a damaged file (lz4 raises RuntimeError).
_DAMAGE = (McapError, EOFError, ValueError, struct.error, RuntimeError, zstandard.ZstdError)


@dataclass(frozen=True)
class PlanStepRecord:
    """One step read back from a plan file: name, start on the plan's timeline in [s], motion."""

    name: str
    start_s: float
    trajectory: JointTrajectory


@dataclass(frozen=True)
class PlanFile:
    """A plan read back from an MCAP file: its steps plus what execute and checks need.

    `urdf` is the text of the file's /robot_description, "" if it has none.
    """

    robot_name: str
    group: str
    planning_frame: str
    distro: str
    steps: tuple[PlanStepRecord, ...]
    attachments: dict[str, bytes]
    metadata: dict[str, str]
    limits: dict[str, dict[str, float]]
    urdf: str = ""


@dataclass(frozen=True)
class TopicSummary:
    """One channel: topic, type, message encoding, count, offered durability ("" if unknown)."""

    topic: str
    type: str
    encoding: str
    count: int
    qos_durability: str


@dataclass(frozen=True)
class BagSummary:
    """What `moveplan inspect` shows of an MCAP file; times are log times in [ns]."""

    profile: str
    library: str
    start_ns: int
    end_ns: int
    duration_s: float
    topics: tuple[TopicSummary, ...]
    metadata: tuple[str, ...]
    attachments: tuple[str, ...]


def write_plan(path: Path, plan: Plan, distro: str = "jazzy") -> None:
    """Write `plan` to `path` as a ROS 2 bag for `distro`, atomically; return None.

    Raises:
        UsageError: `distro` has no shipped message definitions.
        InputError: `path` cannot be written.

    """
    schemas = {msgtype: msgs.schema_text(msgtype, distro) for msgtype, _ in _TOPICS.values()}
    messages = _plan_messages(plan, schemas)
    metadata = {
        **plan.metadata,
        "robot_name": plan.robot_name,
        "group": plan.group,
        "planning_frame": plan.planning_frame,
        "step_names": json.dumps([step.name for step in plan.steps]),
        "limits": json.dumps(plan.limits, sort_keys=True),
        "distro": distro,
    }
    topics = {topic: _TOPICS[topic] for topic in dict.fromkeys(t for t, _, _ in messages)}
    _write_bag(
        path,
        topics,
        schemas,
        messages,
        {"rosbag2": {"ROS_DISTRO": distro}, "moveplan": metadata},
        plan.attachments,
    )


@dataclass(frozen=True)
class ExecutedStep:
    """One executed step as written: per control cycle the measured joint state and the controller's state.

    Attributes:
        joint_names: Column order of `positions` and `velocities` (n).
        positions: Measured positions in [rad], shape (K, n).
        velocities: Measured velocities in [rad]/[s], shape (K, n).
        states: The controller's state per cycle, stamped on the execution's timeline.
    """

    joint_names: tuple[str, ...]
    positions: NDArray[np.float64]
    velocities: NDArray[np.float64]
    states: msgs.ControllerStates


def write_execution(
    path: Path,
    steps: Sequence[ExecutedStep],
    document: dict[str, Any],
    end_ns: int,
    *,
    controller: str,
    urdf: str = "",
    distro: str = "jazzy",
    tf: TfSamples | None = None,
) -> None:
    """Write an execution to `path` as a ROS 2 bag for `distro`, atomically; return None.

    Per control cycle: /joint_states (measured state) and /<controller>/controller_state
    (JointTrajectoryControllerState in the layout of `distro`). Once: /robot_description
    (`urdf`, if given) and the result `document` as JSON, on EXECUTION_RESULT_TOPIC at
    `end_ns` and in the metadata record "moveplan_execution" (one JSON value per key). /tf
    only if `tf` is given (times on the execution's timeline). No steps write no cycles.

    Raises:
        UsageError: `distro` has no shipped message definitions.
        InputError: `path` cannot be written.

    """
    state_topic = f"/{controller}/controller_state"
    # Channels exist even without messages (an execution refused before its first cycle),
    # so every executed file has the same topics and schemas.
    topics = {_ROBOT_DESCRIPTION: (_STRING, True)} if urdf else {}
    topics |= {"/joint_states": (_JOINT_STATE, False), state_topic: (_CONTROLLER_STATE, False)}
    if tf is not None:
        topics["/tf"] = (_TF, False)
    # Latched: a late subscriber (a dashboard, `ros2 topic echo`) still gets the verdict.
    topics[EXECUTION_RESULT_TOPIC] = (_STRING, True)
    schemas = {msgtype: msgs.schema_text(msgtype, distro) for msgtype, _ in topics.values()}
    string = _encoder(_STRING, schemas[_STRING])

    messages: list[tuple[str, int, bytes]] = []
    if urdf:
        messages.append((_ROBOT_DESCRIPTION, 0, string(msgs.string(urdf))))
    for step in steps:
        stamps_ns = step.states.stamps_ns
        joint_states = encode_joint_states(step.joint_names, stamps_ns, step.positions, step.velocities)
        controller_states = msgs.controller_states_cdr(step.states, distro)
        for stamp, joint_state, state in zip(stamps_ns.tolist(), joint_states, controller_states, strict=True):
            messages += [("/joint_states", stamp, joint_state), (state_topic, stamp, state)]
    if tf is not None:
        tf_stamps = msgs.stamps_ns(tf.times_s).tolist()
        encoded = msgs.tf_messages_cdr(tf.parents, tf.children, tf.transforms, tf_stamps)
        messages += [("/tf", stamp, data) for stamp, data in zip(tf_stamps, encoded, strict=True)]
    messages.append((EXECUTION_RESULT_TOPIC, end_ns, string(msgs.string(json.dumps(document)))))
    # A stable sort: within a cycle the joint state comes before the controller state.
    messages.sort(key=lambda item: item[1])
    metadata = {key: json.dumps(value) for key, value in document.items()}
    _write_bag(
        path,
        topics,
        schemas,
        messages,
        {"rosbag2": {"ROS_DISTRO": distro}, "moveplan_execution": metadata},
        {},
    )


def read_plan(path: Path) -> PlanFile:
    """Return the plan stored in the moveplan MCAP file at `path`.

    Raises:
        InputError: The file is missing, not MCAP, truncated, corrupt or not a moveplan plan.

    """
    with _open_mcap(path) as stream:
        contents = _scan(path, stream, keep_topics=(_TRAJECTORY, _ROBOT_DESCRIPTION))
    info = next((m.metadata for m in contents.metadata if m.name == "moveplan"), {})
    if any(key not in info for key in _PLAN_KEYS):
        raise InputError(f"{path}: not a moveplan plan file (no complete 'moveplan' metadata)")
    try:
        step_names = [str(name) for name in json.loads(info["step_names"])]
        limits = {
            joint: {key: float(value) for key, value in joint_limits.items()}
            for joint, joint_limits in json.loads(info["limits"]).items()
        }
    except (ValueError, TypeError, AttributeError) as exc:
        raise InputError(f"{path}: 'moveplan' metadata is malformed: {exc}") from exc
    kept = [item for item in contents.kept if item[0].topic == _TRAJECTORY]
    if len(kept) != len(step_names):
        raise InputError(
            f"{path}: {len(kept)} messages on {_TRAJECTORY} "
            f"but {len(step_names)} step names in its metadata"
        )
    factory = DecoderFactory()
    steps = []
    for name, (channel, schema, message) in zip(step_names, kept, strict=True):
        decode = factory.decoder_for(channel.message_encoding, schema)
        if decode is None or schema is None or schema.name != _TOPICS[_TRAJECTORY][0]:
            raise InputError(
                f"{path}: {_TRAJECTORY} must hold CDR trajectory_msgs/msg/JointTrajectory "
                "messages with a ros2msg schema"
            )
        try:
            trajectory = msgs.trajectory_from_message(decode(message.data))
        except (*_DAMAGE, TypeError, IndexError, AttributeError) as exc:
            raise InputError(
                f"{path}: step '{name}' on {_TRAJECTORY} is unreadable: {exc}"
            ) from exc
        steps.append(PlanStepRecord(name, message.log_time / 1e9, trajectory))
    descriptions = [item for item in contents.kept if item[0].topic == _ROBOT_DESCRIPTION]
    return PlanFile(
        robot_name=info["robot_name"],
        group=info["group"],
        planning_frame=info["planning_frame"],
        distro=info["distro"],
        steps=tuple(steps),
        attachments={attachment.name: attachment.data for attachment in contents.attachments},
        metadata={key: value for key, value in info.items() if key not in _PLAN_KEYS},
        limits=limits,
        urdf=_robot_description(path, factory, descriptions),
    )


def summarize(path: Path) -> BagSummary:
    """Return profile, topics, counts, time range, metadata and attachment names of an MCAP file.

    Uses the summary section's statistics when present, else counts in one linear pass.

    Raises:
        InputError: The file is missing, not MCAP, truncated or corrupt.

    """
    with _open_mcap(path) as stream:
        indexed = _summary_from_index(stream)
        if indexed is not None:
            return indexed
        contents = _scan(path, stream, keep_topics=())
    return _bag_summary(
        contents.header or Header(profile="", library=""),
        contents.start_ns,
        contents.end_ns,
        [
            (channel, contents.schemas.get(channel.schema_id), contents.counts[channel.id])
            for channel in contents.channels.values()
        ],
        tuple(record.name for record in contents.metadata),
        tuple(record.name for record in contents.attachments),
    )


# --- writing -------------------------------------------------------------------------------------


@contextmanager
def _atomic_writer(path: Path) -> Iterator[Writer]:
    """Yield a started mcap Writer on a temporary file beside `path`; finish, then rename.

    On any error the temporary file is removed: `path` is either untouched or complete.
    """
    temporary = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    library = f"moveplan {version('moveplan')}; {LIBRARY_IDENTIFIER}"
    try:
        # open(mode "x"), not tempfile: the output gets the user's umask permissions.
        with temporary.open("xb") as stream:
            writer = Writer(stream, compression=CompressionType.ZSTD, enable_data_crcs=True)
            writer.start(profile="ros2", library=library)
            yield writer
            writer.finish()  # type: ignore[no-untyped-call]  # mcap leaves it unannotated
        temporary.replace(path)
    except BaseException as exc:
        temporary.unlink(missing_ok=True)
        if isinstance(exc, OSError):
            raise InputError(f"{path}: cannot write: {exc.strerror or exc}") from exc
        raise


def _write_bag(
    path: Path,
    topics: Mapping[str, tuple[str, bool]],
    schemas: Mapping[str, bytes],
    messages: list[tuple[str, int, bytes]],
    metadata: Mapping[str, dict[str, str]],
    attachments: Mapping[str, bytes],
) -> None:
    """Write a ROS 2 bag to `path` atomically; return None.

    `topics` maps topic -> (message type, latched), in channel order; `schemas` maps
    message type -> schema text; `messages` are (topic, log time [ns], CDR), in log-time
    order; then metadata records and attachments, in order.
    """
    with _atomic_writer(path) as writer:
        schema_ids: dict[str, int] = {}
        channel_ids: dict[str, int] = {}
        for topic, (msgtype, latched) in topics.items():
            if msgtype not in schema_ids:
                schema_ids[msgtype] = writer.register_schema(msgtype, "ros2msg", schemas[msgtype])
            qos = {"offered_qos_profiles": msgs.offered_qos_profiles(latched)}
            channel_ids[topic] = writer.register_channel(topic, "cdr", schema_ids[msgtype], qos)
        add_message = writer.add_message
        for topic, log_time_ns, data in messages:
            add_message(channel_ids[topic], log_time_ns, data, log_time_ns)
        for name, record in metadata.items():
            writer.add_metadata(name, record)
        for name, content in attachments.items():
            media_type = _MEDIA_TYPES.get(Path(name).suffix.lower(), "application/octet-stream")
            writer.add_attachment(0, 0, name, media_type, content)


def plan_urdf(plan: PlanFile) -> str:
    """Return the plan's URDF: its /robot_description, else its one .urdf attachment, else ""."""
    if plan.urdf:
        return plan.urdf
    urdfs = [data for name, data in plan.attachments.items() if name.lower().endswith(".urdf")]
    return urdfs[0].decode() if len(urdfs) == 1 else ""


def _plan_messages(plan: Plan, schemas: dict[str, bytes]) -> list[tuple[str, int, bytes]]:
    """Return (topic, log time [ns], CDR message) for every message of `plan`, in log-time order.

    Trajectories and transforms take the fast `*_cdr` encoders; the two small messages
    take the generic encoder built from `schemas` (message type -> schema text).
    """
    if not plan.steps:
        raise ValueError("a plan needs at least one step")

    def generic(topic: str, message: dict[str, Any]) -> bytes:
        msgtype = _TOPICS[topic][0]
        return _encoder(msgtype, schemas[msgtype])(message)

    frame = plan.planning_frame
    trajectories = [step.trajectory for step in plan.steps]
    statics = plan.static_frames
    # reshape, not np.array alone: no static frames must still give shape (1, 0, 4, 4).
    static_transforms = np.reshape([f.transform for f in statics], (1, len(statics), 4, 4))
    [tf_static] = msgs.tf_messages_cdr(
        [f.parent for f in statics], [f.name for f in statics], static_transforms, [0]
    )
    messages = [
        ("/robot_description", 0, generic("/robot_description", msgs.string(plan.urdf))),
        ("/tf_static", 0, tf_static),
        (
            "/planning_scene_markers",
            0,
            generic("/planning_scene_markers", msgs.marker_array(plan.objects, frame)),
        ),
        (
            "/display_planned_path",
            0,
            msgs.display_trajectory_cdr(plan.robot_name, trajectories, frame),
        ),
    ]
    # Starts add up integer durations, so a step starts exactly where the previous one's
    # last time_from_start ends.
    start_ns = 0
    for trajectory in trajectories:
        messages.append((_TRAJECTORY, start_ns, msgs.joint_trajectory_cdr(trajectory, frame)))
        start_ns += msgs.seconds_to_ns(trajectory.duration_s)
    if plan.tf is not None:
        tf = plan.tf
        stamps_ns = [msgs.seconds_to_ns(float(time_s)) for time_s in tf.times_s]
        encoded = msgs.tf_messages_cdr(tf.parents, tf.children, tf.transforms, stamps_ns)
        messages += [("/tf", stamp, data) for stamp, data in zip(stamps_ns, encoded, strict=True)]
    # A stable sort: messages logged at the same time keep the order above.
    return sorted(messages, key=lambda item: item[1])


@cache
def _encoder(msgtype: str, schema_text: bytes) -> Callable[[dict[str, Any]], bytes]:
    """Return the CDR encoder of `msgtype` built from its schema text (cached: building is slow)."""
    encoders = serialize_dynamic(msgtype, schema_text.decode())
    return encoders[msgtype]


# --- reading -------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Contents:
    """What a linear pass over an MCAP file found; `kept` holds the kept topics' messages."""

    header: Header | None
    schemas: dict[int, Schema]
    channels: dict[int, Channel]
    counts: Counter[int]
    start_ns: int
    end_ns: int
    metadata: tuple[Metadata, ...]
    attachments: tuple[Attachment, ...]
    kept: tuple[tuple[Channel, Schema | None, Message], ...]


@contextmanager
def _open_mcap(path: Path) -> Iterator[IO[bytes]]:
    """Yield `path` opened for reading, after checking that it starts like an MCAP file."""
    try:
        stream = path.open("rb")
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    except IsADirectoryError:
        raise InputError(f"{path}: is a folder; give the .mcap file inside it") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror or exc}") from exc
    with stream:
        if stream.read(MAGIC_SIZE) != _MAGIC:
            raise InputError(f"{path}: not an MCAP file (it does not start with the MCAP magic)")
        yield stream


def _summary_from_index(stream: IO[bytes]) -> BagSummary | None:
    """Return the summary from the file's summary section, or None where that is incomplete."""
    stream.seek(0)
    try:
        reader = SeekingReader(stream)
        header = reader.get_header()
        summary = reader.get_summary()
    except (*_DAMAGE, OSError):
        return None  # no readable footer (unfinished or damaged): left to the linear pass
    if summary is None or summary.statistics is None:
        return None
    stats = summary.statistics
    if stats.metadata_count != len(summary.metadata_indexes):
        return None
    if stats.attachment_count != len(summary.attachment_indexes):
        return None
    return _bag_summary(
        header,
        stats.message_start_time if stats.message_count else 0,
        stats.message_end_time if stats.message_count else 0,
        [
            (
                channel,
                summary.schemas.get(channel.schema_id),
                stats.channel_message_counts.get(channel.id, 0),
            )
            for channel in summary.channels.values()
        ],
        tuple(index.name for index in summary.metadata_indexes),
        tuple(index.name for index in summary.attachment_indexes),
    )


def _scan(path: Path, stream: IO[bytes], keep_topics: Collection[str]) -> _Contents:
    """Return the contents of an MCAP file read record by record, keeping `keep_topics`' messages.

    A file that stops on a record boundary without a footer (its writer never finished)
    is read as far as it goes; one that stops inside a record is truncated.
    """
    header = None
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    counts: Counter[int] = Counter()
    times: list[int] = []
    metadata: list[Metadata] = []
    attachments: list[Attachment] = []
    kept: list[tuple[Channel, Schema | None, Message]] = []
    for record in _records(path, stream):
        if isinstance(record, Header):
            header = record
        elif isinstance(record, Schema):
            schemas[record.id] = record
        elif isinstance(record, Channel):
            channels[record.id] = record
        elif isinstance(record, Message):
            channel = channels.get(record.channel_id)
            if channel is None:
                raise InputError(f"{path}: a message uses undefined channel {record.channel_id}")
            counts[record.channel_id] += 1
            times.append(record.log_time)
            if channel.topic in keep_topics:
                kept.append((channel, schemas.get(channel.schema_id), record))
        elif isinstance(record, Metadata):
            metadata.append(record)
        elif isinstance(record, Attachment):
            attachments.append(record)
    return _Contents(
        header=header,
        schemas=schemas,
        channels=channels,
        counts=counts,
        start_ns=min(times, default=0),
        end_ns=max(times, default=0),
        metadata=tuple(metadata),
        attachments=tuple(attachments),
        kept=tuple(sorted(kept, key=lambda item: item[2].log_time)),
    )


def _records(path: Path, stream: IO[bytes]) -> Iterator[McapRecord]:
    """Yield every record of an MCAP file in file order, chunks opened and CRCs checked."""
    stream.seek(0)
    records = StreamReader(stream, validate_crcs=True).records
    while True:
        try:
            record = next(records)
        except StopIteration:
            return
        except _DAMAGE as exc:
            cut = _cut_record(stream)
            if cut is None and isinstance(exc, EndOfFile):
                return
            if cut is not None:
                message = f"file is truncated (the record at byte {cut} runs past its end)"
            else:
                message = f"corrupt MCAP data: {type(exc).__name__}: {exc}".removesuffix(": ")
            raise InputError(f"{path}: {message}") from exc
        yield record


def _robot_description(
    path: Path,
    factory: DecoderFactory,
    kept: list[tuple[Channel, Schema | None, Message]],
) -> str:
    """Return the URDF text of the first /robot_description message, "" if there is none.

    Raises:
        InputError: The message is not a readable std_msgs/msg/String.

    """
    if not kept:
        return ""
    channel, schema, message = kept[0]
    decode = factory.decoder_for(channel.message_encoding, schema)
    if decode is None or schema is None or schema.name != _STRING:
        raise InputError(
            f"{path}: {_ROBOT_DESCRIPTION} must hold a CDR {_STRING} with a ros2msg schema"
        )
    try:
        return str(decode(message.data).data)
    except (*_DAMAGE, TypeError, IndexError, AttributeError) as exc:
        raise InputError(f"{path}: {_ROBOT_DESCRIPTION} is unreadable: {exc}") from exc


def _cut_record(stream: IO[bytes]) -> int | None:
    """Return the offset of the first record that runs past the end of the file, or None."""
    size = stream.seek(0, os.SEEK_END)
    offset = MAGIC_SIZE
    while offset < size:
        stream.seek(offset)
        head = stream.read(9)
        if len(head) < 9:
            return offset
        opcode, length = struct.unpack("<BQ", head)
        end = offset + 9 + length + (MAGIC_SIZE if opcode == Opcode.FOOTER else 0)
        if end > size:
            return offset
        offset = end
    return None


def _bag_summary(
    header: Header,
    start_ns: int,
    end_ns: int,
    channels: list[tuple[Channel, Schema | None, int]],
    metadata: tuple[str, ...],
    attachments: tuple[str, ...],
) -> BagSummary:
    """Return a BagSummary of (channel, schema, message count) triples, sorted by topic."""
    topics = [
        TopicSummary(
            topic=channel.topic,
            type=schema.name if schema is not None else "",
            encoding=channel.message_encoding,
            count=count,
            qos_durability=msgs.durability(channel.metadata.get("offered_qos_profiles", "")),
        )
        for channel, schema, count in channels
    ]
    return BagSummary(
        profile=header.profile,
        library=header.library,
        start_ns=start_ns,
        end_ns=end_ns,
        duration_s=(end_ns - start_ns) / 1e9,
        topics=tuple(sorted(topics, key=lambda topic: topic.topic)),
        metadata=metadata,
        attachments=attachments,
    )
