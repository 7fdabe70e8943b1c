"""Plan files written by plan_writer and read by plan_file and summary, checked by independent readers."""

from __future__ import annotations

import re
import struct
from dataclasses import replace
from importlib.resources import files
from pathlib import Path
from typing import Any

import mcap.writer
import numpy as np
import pytest
from mcap.reader import make_reader
from reference_cdr import generic, reference_cdr
from rosbags.highlevel import AnyReader
from rosbags.interfaces import ConnectionExtRosbag2, QosDurability

from moveplan.core.bag.cdr import bulk as message_cdr
from moveplan.core.bag.cdr import messages as msgs
from moveplan.core.bag.container._mcap_writer import McapWriter
from moveplan.core.bag.container.summary import summarize
from moveplan.core.bag.plan_file import PlanFile, read_plan
from moveplan.core.bag.plan_writer import write_plan
from moveplan.core.errors import InputError, UsageError
from moveplan.core.rotations import tf_poses
from moveplan.core.types import (
    CollisionObject,
    Frame,
    JointTrajectory,
    Plan,
    Shape,
    StepResult,
    TfSamples,
)

MAGIC = b"\x89MCAP0\r\n"
LATCHED = ("/robot_description", "/tf_static", "/planning_scene_markers", "/display_planned_path")
TYPES = {
    "/robot_description": "std_msgs/msg/String",
    "/tf_static": "tf2_msgs/msg/TFMessage",
    "/planning_scene_markers": "visualization_msgs/msg/MarkerArray",
    "/planned_trajectory": "trajectory_msgs/msg/JointTrajectory",
    "/display_planned_path": "moveit_msgs/msg/DisplayTrajectory",
    "/tf": "tf2_msgs/msg/TFMessage",
}
DISTROS = sorted(
    entry.name
    for entry in files("moveplan.core.bag.cdr.msgs").iterdir()
    if entry.is_dir() and entry.name.isalpha()
)


def transform(
    xyz: tuple[float, float, float],
    axis: tuple[float, float, float] = (0, 0, 1),
    angle: float = 0.0,
) -> np.ndarray:
    """4x4 transform: rotation `angle` about unit `axis` (Rodrigues), then translation `xyz`."""
    k = np.array(axis, dtype=float)
    skew = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    result = np.eye(4)
    result[:3, :3] = np.eye(3) + np.sin(angle) * skew + (1 - np.cos(angle)) * skew @ skew
    result[:3, 3] = xyz
    return result


def quaternion(axis: tuple[float, float, float], angle: float) -> list[float]:
    q = [*(np.sin(angle / 2) * np.array(axis)), np.cos(angle / 2)]
    return [-v for v in q] if q[3] < 0 else q


def trajectory(start: list[float], end: list[float], duration_s: float) -> JointTrajectory:
    times = np.linspace(0.0, duration_s, 4)
    fraction = (times / duration_s)[:, None]
    positions = np.array(start) + fraction * (np.array(end) - np.array(start))
    velocities = np.tile((np.array(end) - np.array(start)) / duration_s, (4, 1))
    accelerations = np.array([[0.5, -0.5], [0.25, 0.0], [0.0, 0.25], [-1e-3, 3.3]])
    return JointTrajectory(("shoulder", "elbow"), times, positions, velocities, accelerations)


@pytest.fixture
def plan() -> Plan:
    steps = (
        StepResult(
            "approach",
            {"joints": [1.0, -0.5]},
            "RRTConnect",
            0.01,
            trajectory([0.0, 0.0], [1.0, -0.5], 1.2345678912),
        ),
        StepResult(
            "retreat",
            {"named": "home"},
            "RRTConnect",
            0.02,
            trajectory([1.0, -0.5], [0.1, 0.2], 0.75),
        ),
    )
    objects = (
        CollisionObject("table", Shape("box", (1.2, 0.8, 0.05)), transform((0.6, 0, -0.03))),
        CollisionObject(
            "post", Shape("cylinder", (0.05, 0.6)), transform((0.3, 0.5, 0.3), (1, 0, 0), np.pi)
        ),
        CollisionObject(
            "ball", Shape("sphere", (0.04,)), transform((0.7, -0.3, 0.1)), link="tool0"
        ),
    )
    tf_times = np.array([0.0, 0.5, 1.0, 1.9845678912])
    tf = TfSamples(
        tf_times,
        ("base_link", "link_1"),
        ("link_1", "link_2"),
        tf_poses(np.array(
            [
                [transform((0, 0, 0.1), (0, 0, 1), t), transform((0.3, 0, 0), (0, 1, 0), -t)]
                for t in tf_times
            ]
        )),
    )
    return Plan(
        robot_name="twolink",
        group="arm",
        planning_frame="base_link",
        steps=steps,
        urdf="<robot name='twolink'/>",
        static_frames=(
            Frame("target_1", "base_link", transform((0.6, 0.2, 0.4), (0, 0, 1), np.pi / 2)),
        ),
        objects=objects,
        tf=tf,
        limits={
            "shoulder": {"max_velocity": 2.0, "max_acceleration": 5.0},
            "elbow": {"max_velocity": 3.0, "max_acceleration": 6.0},
        },
        attachments={"twolink.srdf": b"<robot name='twolink'/>\n", "joint_limits.yaml": b"a: 1\n"},
        metadata={"seed": "0", "planner": "RRTConnect"},
    )


@pytest.fixture
def plan_path(tmp_path: Path, plan: Plan) -> Path:
    path = tmp_path / "plan.mcap"
    write_plan(path, plan)
    return path


def read_all(path: Path) -> list[tuple[str, int, Any]]:
    """(topic, log time [ns], message) decoded by rosbags with the file's schemas."""
    with AnyReader([path]) as reader:
        return [(c.topic, t, reader.deserialize(raw, c.msgtype)) for c, t, raw in reader.messages()]


def rosbag2_ext(connection: Any) -> ConnectionExtRosbag2:
    assert isinstance(connection.ext, ConnectionExtRosbag2)
    return connection.ext


def ns(stamp: Any) -> int:
    return int(stamp.sec) * 1_000_000_000 + int(stamp.nanosec)


def on(messages: list[tuple[str, int, Any]], topic: str) -> list[tuple[int, Any]]:
    return [(t, m) for name, t, m in messages if name == topic]


# --- a raw walk over top-level records, without the mcap library ---------------------------------


class Fields:
    def __init__(self, body: bytes) -> None:
        self.body, self.pos = body, 0

    def take(self, fmt: str) -> Any:
        (value,) = struct.unpack_from(fmt, self.body, self.pos)
        self.pos += struct.calcsize(fmt)
        return value

    def skip(self, length: int) -> None:
        self.pos += length

    def raw(self, length: int) -> bytes:
        self.pos += length
        return self.body[self.pos - length : self.pos]

    def string(self) -> str:
        return self.raw(self.take("<I")).decode()

    def mapping(self) -> dict[str, str]:
        end = self.pos + 4 + self.take("<I")
        result = {}
        while self.pos < end:
            key = self.string()
            result[key] = self.string()
        return result


def top_level_records(path: Path) -> list[tuple[int, Fields]]:
    data = path.read_bytes()
    assert data[:8] == MAGIC and data[-8:] == MAGIC
    records, offset = [], 8
    while offset < len(data) - 8:
        opcode, length = struct.unpack_from("<BQ", data, offset)
        records.append((opcode, Fields(data[offset + 9 : offset + 9 + length])))
        offset += 9 + length
    assert offset == len(data) - 8
    return records


def summary_start(path: Path) -> int:
    data = path.read_bytes()
    return int(struct.unpack_from("<Q", data, len(data) - 8 - 20)[0])


# --- the file is a rosbag2 bag -------------------------------------------------------------------


def test_written_plan_has_ros2_profile_statistics_indexes_and_crcs(plan_path: Path) -> None:
    records = top_level_records(plan_path)
    opcodes = [opcode for opcode, _ in records]
    header = records[0][1]
    assert records[0][0] == 0x01 and header.string() == "ros2"
    assert {0x0B, 0x08, 0x07, 0x0A, 0x0D, 0x0E}.issubset(opcodes)  # stats, chunk/msg/att/meta idx
    chunks = [fields for opcode, fields in records if opcode == 0x06]
    for chunk in chunks:
        chunk.skip(24)
        assert chunk.take("<I") != 0  # uncompressed CRC
        assert chunk.string() == "zstd"
    footer = records[-1][1]
    assert records[-1][0] == 0x02
    footer.skip(16)
    assert footer.take("<I") != 0  # summary CRC


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
def test_every_channel_is_cdr_with_the_shipped_schema_text_byte_for_byte(
    tmp_path: Path, plan: Plan, distro: str
) -> None:
    path = tmp_path / "plan.mcap"
    write_plan(path, plan, distro=distro)
    shipped = files("moveplan.core.bag.cdr.msgs").joinpath(distro)
    schemas = {}
    for opcode, fields in top_level_records(path):
        if opcode == 0x03:
            fields.take("<H")
            name, encoding = fields.string(), fields.string()
            schemas[name] = (encoding, fields.raw(fields.take("<I")))
    assert set(schemas) == set(TYPES.values())
    for name, (encoding, data) in schemas.items():
        assert encoding == "ros2msg"
        assert data == shipped.joinpath(name.replace("/", "__") + ".msg").read_bytes(), name
    with AnyReader([path]) as reader:
        assert {c.topic: c.msgtype for c in reader.connections} == TYPES
        for connection in reader.connections:
            assert rosbag2_ext(connection).serialization_format == "cdr"
            assert connection.msgdef.data.encode() == schemas[connection.msgtype][1]
    assert len(read_all(path)) == 10


def test_latched_topics_offer_transient_local_and_the_rest_volatile(plan_path: Path) -> None:
    raw = {}
    for opcode, fields in top_level_records(plan_path):
        if opcode == 0x04:
            fields.skip(4)
            topic, _ = fields.string(), fields.string()
            raw[topic] = fields.mapping()["offered_qos_profiles"]
    assert "durability: 1" in raw["/tf_static"] and "durability: 1" in raw["/robot_description"]
    with AnyReader([plan_path]) as reader:
        durability = {
            c.topic: rosbag2_ext(c).offered_qos_profiles[0].durability for c in reader.connections
        }
    for topic in TYPES:
        want = QosDurability.TRANSIENT_LOCAL if topic in LATCHED else QosDurability.VOLATILE
        assert durability[topic] == want, topic


@pytest.mark.parametrize("distro", ["humble", "jazzy"])
def test_file_has_one_rosbag2_metadata_record_naming_the_distro(
    tmp_path: Path, plan: Plan, distro: str
) -> None:
    path = tmp_path / "plan.mcap"
    write_plan(path, plan, distro=distro)
    metadata = {}
    for opcode, fields in top_level_records(path):
        if opcode == 0x0C:
            name = fields.string()
            assert name not in metadata
            metadata[name] = fields.mapping()
    assert metadata["rosbag2"] == {"ROS_DISTRO": distro}
    assert metadata["moveplan"]["seed"] == "0" and metadata["moveplan"]["distro"] == distro


def test_message_counts_match_what_the_plan_holds(plan_path: Path, plan: Plan) -> None:
    with AnyReader([plan_path]) as reader:
        counts = {topic: info.msgcount for topic, info in reader.topics.items()}
    assert counts == {
        "/robot_description": 1,
        "/tf_static": 1,
        "/planning_scene_markers": 1,
        "/display_planned_path": 1,
        "/planned_trajectory": 2,
        "/tf": 4,
    }
    assert len(read_all(plan_path)) == sum(counts.values())


# --- message contents ----------------------------------------------------------------------------


def test_planned_trajectory_holds_each_step_exactly_logged_at_its_start(
    plan_path: Path, plan: Plan
) -> None:
    messages = on(read_all(plan_path), "/planned_trajectory")
    start_ns = 0
    for (log_time, message), step in zip(messages, plan.steps, strict=True):
        expected = step.trajectory
        assert log_time == start_ns
        assert (message.header.stamp.sec, message.header.stamp.nanosec) == (0, 0)
        assert tuple(message.joint_names) == expected.joint_names
        times_ns = [ns(p.time_from_start) for p in message.points]
        assert times_ns == [round(t * 1e9) for t in expected.times_s]
        for point, q, v, a in zip(
            message.points,
            expected.positions,
            expected.velocities,
            expected.accelerations,
            strict=True,
        ):
            np.testing.assert_array_equal(point.positions, q)
            np.testing.assert_array_equal(point.velocities, v)
            np.testing.assert_array_equal(point.accelerations, a)
        start_ns += times_ns[-1]
    assert [t for t, _ in messages] == [0, 1_234_567_891]


def test_display_path_holds_every_step_and_starts_at_the_first_point(
    plan_path: Path, plan: Plan
) -> None:
    [(log_time, display)] = on(read_all(plan_path), "/display_planned_path")
    assert log_time == 0 and display.model_id == "twolink"
    assert len(display.trajectory) == 2
    for robot_trajectory, step in zip(display.trajectory, plan.steps, strict=True):
        np.testing.assert_array_equal(
            [p.positions for p in robot_trajectory.joint_trajectory.points],
            step.trajectory.positions,
        )
        assert robot_trajectory.multi_dof_joint_trajectory.points == []
    start = display.trajectory_start.joint_state
    assert list(start.name) == ["shoulder", "elbow"]
    np.testing.assert_array_equal(start.position, plan.steps[0].trajectory.positions[0])


def test_static_and_moving_transforms_carry_translation_and_quaternion(
    plan_path: Path, plan: Plan
) -> None:
    messages = read_all(plan_path)
    [(_, static)] = on(messages, "/tf_static")
    [frame] = static.transforms
    assert (frame.header.frame_id, frame.child_frame_id) == ("base_link", "target_1")
    translation, rotation = frame.transform.translation, frame.transform.rotation
    np.testing.assert_allclose([translation.x, translation.y, translation.z], [0.6, 0.2, 0.4])
    np.testing.assert_allclose(
        [rotation.x, rotation.y, rotation.z, rotation.w],
        quaternion((0, 0, 1), np.pi / 2),
        atol=1e-12,
    )
    moving = on(messages, "/tf")
    assert [t for t, _ in moving] == [0, 500_000_000, 1_000_000_000, 1_984_567_891]
    for log_time, message in moving:
        stamps = {ns(tf.header.stamp) for tf in message.transforms}
        assert stamps == {log_time}
        assert [(tf.header.frame_id, tf.child_frame_id) for tf in message.transforms] == [
            ("base_link", "link_1"),
            ("link_1", "link_2"),
        ]
    last = moving[-1][1].transforms[1].transform.rotation
    np.testing.assert_allclose(
        [last.x, last.y, last.z, last.w], quaternion((0, 1, 0), -1.9845678912), atol=1e-12
    )


def test_markers_show_each_object_in_its_frame_with_shape_and_size(plan_path: Path) -> None:
    [(_, array)] = on(read_all(plan_path), "/planning_scene_markers")
    markers = array.markers
    assert [m.ns for m in markers] == ["moveplan"] * 3
    assert [m.type for m in markers] == [1, 3, 2]  # CUBE, CYLINDER, SPHERE
    assert [m.header.frame_id for m in markers] == ["base_link", "base_link", "tool0"]
    scales = [[m.scale.x, m.scale.y, m.scale.z] for m in markers]
    np.testing.assert_allclose(scales, [[1.2, 0.8, 0.05], [0.1, 0.1, 0.6], [0.08, 0.08, 0.08]])
    assert all(m.color.a > 0.5 for m in markers)
    post = markers[1].pose
    np.testing.assert_allclose([post.position.x, post.position.y, post.position.z], [0.3, 0.5, 0.3])
    np.testing.assert_allclose(
        [post.orientation.x, post.orientation.y, post.orientation.z, post.orientation.w],
        quaternion((1, 0, 0), np.pi),
        atol=1e-12,
    )


def test_mesh_object_becomes_a_mesh_resource_marker_with_a_file_uri(
    tmp_path: Path, plan: Plan
) -> None:
    mesh = CollisionObject(
        "bucket",
        Shape("mesh", mesh_path=str(tmp_path / "bucket.stl"), scale=(0.001, 0.001, 0.001)),
        np.eye(4),
    )
    path = tmp_path / "plan.mcap"
    write_plan(path, Plan(**{**vars(plan), "objects": (mesh,)}))
    [(_, array)] = on(read_all(path), "/planning_scene_markers")
    [marker] = array.markers
    assert marker.type == 10
    assert marker.mesh_resource == (tmp_path / "bucket.stl").as_uri()
    assert [marker.scale.x, marker.scale.y, marker.scale.z] == [0.001, 0.001, 0.001]


# --- determinism, round trip, summaries ----------------------------------------------------------


def test_same_plan_written_twice_gives_identical_bytes(tmp_path: Path, plan: Plan) -> None:
    write_plan(tmp_path / "a.mcap", plan)
    write_plan(tmp_path / "b.mcap", plan)
    assert (tmp_path / "a.mcap").read_bytes() == (tmp_path / "b.mcap").read_bytes()


def assert_same_plan(plan_file: PlanFile, plan: Plan) -> None:
    assert (plan_file.robot_name, plan_file.group, plan_file.planning_frame, plan_file.distro) == (
        "twolink",
        "arm",
        "base_link",
        "jazzy",
    )
    assert [s.name for s in plan_file.steps] == ["approach", "retreat"]
    assert [s.start_s for s in plan_file.steps] == [0.0, 1.234567891]
    for record, step in zip(plan_file.steps, plan.steps, strict=True):
        got, want = record.trajectory, step.trajectory
        assert got.joint_names == want.joint_names
        np.testing.assert_allclose(got.times_s, want.times_s, rtol=0, atol=1e-9)
        np.testing.assert_array_equal(got.positions, want.positions)
        np.testing.assert_array_equal(got.velocities, want.velocities)
        np.testing.assert_array_equal(got.accelerations, want.accelerations)
    assert plan_file.attachments == plan.attachments
    assert plan_file.metadata == plan.metadata
    assert plan_file.limits == plan.limits


def test_read_plan_returns_what_write_plan_wrote(plan_path: Path, plan: Plan) -> None:
    assert_same_plan(read_plan(plan_path), plan)


def test_each_step_keeps_the_scaling_it_was_timed_with(tmp_path: Path, plan: Plan) -> None:
    """inspect --plot draws a step's limits as planned: the joint's limit times this scaling."""
    scaled = (replace(plan.steps[0], scaling=(0.5, 0.25)), plan.steps[1])  # the second: not timed by moveplan
    write_plan(tmp_path / "scaled.mcap", replace(plan, steps=scaled))
    assert [s.scaling for s in read_plan(tmp_path / "scaled.mcap").steps] == [(0.5, 0.25), None]
    write_plan(tmp_path / "plain.mcap", plan)
    assert [s.scaling for s in read_plan(tmp_path / "plain.mcap").steps] == [None, None]


@pytest.mark.parametrize("text", ["[[2.0, 0.5], null]", "[[0.5], null]", "[[0.5, 0.5]]", "{}"])
def test_a_malformed_step_scaling_names_the_file_and_the_key(tmp_path: Path, plan: Plan, text: str) -> None:
    path = tmp_path / "plan.mcap"
    write_plan(path, replace(plan, metadata={**plan.metadata, "step_scaling": text}))
    with pytest.raises(InputError, match=rf"^{re.escape(str(path))}: 'moveplan' metadata is malformed: .*"):
        read_plan(path)


def test_attachments_get_media_types_from_their_file_names(plan_path: Path) -> None:
    media = {}
    for opcode, fields in top_level_records(plan_path):
        if opcode == 0x09:
            fields.skip(16)
            name = fields.string()
            media[name] = fields.string()
    assert media == {"twolink.srdf": "application/xml", "joint_limits.yaml": "application/yaml"}


def test_summarize_lists_topics_counts_durability_and_records(plan_path: Path) -> None:
    summary = summarize(plan_path)
    assert summary.profile == "ros2" and summary.library.startswith("moveplan")
    assert (summary.start_ns, summary.end_ns) == (0, 1_984_567_891)
    assert summary.duration_s == pytest.approx(1.984567891)
    assert [(t.topic, t.type, t.encoding, t.count, t.qos_durability) for t in summary.topics] == [
        ("/display_planned_path", TYPES["/display_planned_path"], "cdr", 1, "transient_local"),
        ("/planned_trajectory", TYPES["/planned_trajectory"], "cdr", 2, "volatile"),
        ("/planning_scene_markers", TYPES["/planning_scene_markers"], "cdr", 1, "transient_local"),
        ("/robot_description", TYPES["/robot_description"], "cdr", 1, "transient_local"),
        ("/tf", TYPES["/tf"], "cdr", 4, "volatile"),
        ("/tf_static", TYPES["/tf_static"], "cdr", 1, "transient_local"),
    ]
    assert summary.metadata == ("rosbag2", "moveplan")
    assert summary.attachments == ("twolink.srdf", "joint_limits.yaml")


def test_unfinished_file_without_summary_is_read_by_a_linear_scan(
    tmp_path: Path, plan_path: Path, plan: Plan
) -> None:
    data_end = summary_start(plan_path) - 13  # the DataEnd record: opcode, length, CRC
    unfinished = tmp_path / "unfinished.mcap"
    unfinished.write_bytes(plan_path.read_bytes()[:data_end])
    assert_same_plan(read_plan(unfinished), plan)
    assert summarize(unfinished) == summarize(plan_path)


def test_summarize_counts_messages_of_a_bag_without_statistics(tmp_path: Path) -> None:
    path = tmp_path / "other.mcap"
    with path.open("wb") as stream:
        writer = mcap.writer.Writer(stream, use_statistics=False)
        writer.start(profile="ros2", library="test")
        schema = writer.register_schema("std_msgs/msg/String", "ros2msg", b"string data\n")
        channel = writer.register_channel("/chatter", "cdr", schema)
        for i in range(3):
            writer.add_message(channel, 10 + i, b"\x00\x01\x00\x00\x01\x00\x00\x00\x00", 10 + i)
        writer.finish()  # type: ignore[no-untyped-call]
    summary = summarize(path)
    assert [(t.topic, t.count, t.qos_durability) for t in summary.topics] == [("/chatter", 3, "")]
    assert (summary.start_ns, summary.end_ns) == (10, 12)
    with pytest.raises(InputError, match=re.escape(str(path)) + ".*not a moveplan plan"):
        read_plan(path)


# --- bad files and failed writes -----------------------------------------------------------------


@pytest.mark.parametrize("read", [read_plan, summarize])
def test_truncated_file_raises_input_error_naming_the_file(
    tmp_path: Path, plan_path: Path, read: Any
) -> None:
    data = plan_path.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    with pytest.raises(InputError, match=re.escape(str(cut)) + ".*truncated"):
        read(cut)


def test_corrupt_chunk_raises_input_error_naming_the_file(tmp_path: Path, plan_path: Path) -> None:
    data = bytearray(plan_path.read_bytes())
    chunk_data = data.index(b"zstd") + 4 + 8  # compression string, then the data length
    data[chunk_data + 50] ^= 0xFF
    corrupt = tmp_path / "corrupt.mcap"
    corrupt.write_bytes(bytes(data))
    with pytest.raises(InputError, match=re.escape(str(corrupt)) + ".*corrupt MCAP data"):
        read_plan(corrupt)


@pytest.mark.parametrize("read", [read_plan, summarize])
def test_non_mcap_file_raises_input_error_naming_the_file(tmp_path: Path, read: Any) -> None:
    path = tmp_path / "notes.mcap"
    path.write_text("robot: ur10e\n")
    with pytest.raises(InputError, match=re.escape(str(path)) + ".*not an MCAP file"):
        read(path)


@pytest.mark.parametrize("read", [read_plan, summarize])
def test_missing_file_raises_input_error_naming_the_file(tmp_path: Path, read: Any) -> None:
    path = tmp_path / "nothing.mcap"
    with pytest.raises(InputError, match=re.escape(str(path)) + ".*not found"):
        read(path)


def test_failed_write_leaves_no_file_behind(
    tmp_path: Path, plan: Plan, monkeypatch: pytest.MonkeyPatch
) -> None:
    def fail(*args: Any, **kwargs: Any) -> None:
        raise RuntimeError("disk on fire")

    monkeypatch.setattr(McapWriter, "add_attachment", fail)
    out = tmp_path / "out"
    out.mkdir()
    with pytest.raises(RuntimeError, match="disk on fire"):
        write_plan(out / "plan.mcap", plan)
    assert list(out.iterdir()) == []


def test_failed_write_keeps_the_previous_file(
    tmp_path: Path, plan: Plan, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "plan.mcap"
    path.write_bytes(b"previous plan")
    monkeypatch.setattr(McapWriter, "finish", lambda self: 1 / 0)
    with pytest.raises(ZeroDivisionError):
        write_plan(path, plan)
    assert [p.name for p in tmp_path.iterdir()] == ["plan.mcap"]
    assert path.read_bytes() == b"previous plan"


def test_write_into_a_missing_folder_raises_input_error_naming_it(
    tmp_path: Path, plan: Plan
) -> None:
    path = tmp_path / "no" / "plan.mcap"
    with pytest.raises(InputError, match=re.escape(str(path)) + ".*cannot write"):
        write_plan(path, plan)


def test_unknown_distro_raises_usage_error_listing_known_ones(tmp_path: Path, plan: Plan) -> None:
    with pytest.raises(UsageError, match="rolling.*humble, jazzy"):
        write_plan(tmp_path / "plan.mcap", plan, distro="rolling")
    assert list(tmp_path.iterdir()) == []


# --- the fast CDR encoders write what the reference encoder writes -------------------------------

# Names of every length mod 8, so strings leave every possible padding before what follows.
ODD_NAMES = ("j", "jo", "joi", "join", "joint", "joint_", "joint_1", "joint_12", "joint_123")


def random_trajectory(names: tuple[str, ...], count: int, seed: int) -> JointTrajectory:
    rng = np.random.default_rng(seed)
    times = np.cumsum(rng.uniform(1e-3, 0.9, count)) - 1e-3  # some stamps past a second
    times[0] = 0.0
    shape = (count, len(names))
    return JointTrajectory(
        names, times, rng.normal(size=shape), rng.normal(size=shape), rng.normal(size=shape)
    )


def random_transforms(samples: int, count: int, seed: int) -> np.ndarray:
    """Rotations about random axes plus half turns about x, y and z (each Shepperd branch)."""
    rng = np.random.default_rng(seed)
    result = np.empty((samples, count, 4, 4))
    for index in np.ndindex(samples, count):
        axis = [(1, 0, 0), (0, 1, 0), (0, 0, 1), tuple(rng.normal(size=3))][sum(index) % 4]
        angle = np.pi if sum(index) % 4 < 3 else rng.uniform(-np.pi, np.pi)
        unit = tuple(np.array(axis, dtype=float) / np.linalg.norm(axis))
        result[index] = transform(tuple(rng.normal(size=3)), unit, angle)
    return result


@pytest.mark.parametrize("distro", DISTROS)
@pytest.mark.parametrize("frame_id", ["", "w", "base_link", "odd_frame"])
@pytest.mark.parametrize(
    ("joints", "count"), [(2, 1), (1, 2), (3, 3), (6, 600), (7, 5), (9, 4), (0, 3)]
)
def test_fast_joint_trajectory_matches_the_generic_encoder(
    distro: str, frame_id: str, joints: int, count: int
) -> None:
    trajectory = random_trajectory(ODD_NAMES[:joints], count, seed=joints * count)
    message = msgs.joint_trajectory(trajectory, frame_id)
    expected = generic("trajectory_msgs/msg/JointTrajectory", distro, message)
    assert message_cdr.joint_trajectory_cdr(trajectory, frame_id) == expected


@pytest.mark.parametrize("distro", DISTROS)
@pytest.mark.parametrize("robot_name", ["ur10e", "arm", "twolink"])
@pytest.mark.parametrize("counts", [[1], [587], [3, 1, 40], [2, 2]])
def test_fast_display_trajectory_matches_the_generic_encoder(
    distro: str, robot_name: str, counts: list[int]
) -> None:
    names = ODD_NAMES[1:7]
    trajectories = [random_trajectory(names, count, seed) for seed, count in enumerate(counts)]
    message = msgs.display_trajectory(robot_name, trajectories, "world")
    expected = generic("moveit_msgs/msg/DisplayTrajectory", distro, message)
    assert message_cdr.display_trajectory_cdr(robot_name, trajectories, "world") == expected


@pytest.mark.parametrize("distro", DISTROS)
@pytest.mark.parametrize(("samples", "count"), [(0, 3), (1, 0), (1, 1), (3, 7), (180, 7)])
def test_fast_tf_messages_match_the_generic_encoder(distro: str, samples: int, count: int) -> None:
    parents = tuple(ODD_NAMES[(i + 3) % len(ODD_NAMES)] for i in range(count))
    children = tuple(ODD_NAMES[i % len(ODD_NAMES)] for i in range(count))
    poses = tf_poses(random_transforms(samples, count, seed=samples + count))
    stamps_ns = [i * 987_654_321 for i in range(samples)]  # seconds and nanoseconds
    encoded = message_cdr.tf_messages_cdr(parents, children, poses, stamps_ns)
    assert len(encoded) == samples
    messages = [
        msgs.tf_message(parents, children, list(sample), stamp_ns)
        for sample, stamp_ns in zip(poses, stamps_ns, strict=True)
    ]
    assert encoded == reference_cdr("tf2_msgs/msg/TFMessage", distro, messages)


@pytest.fixture
def edge_plan(plan: Plan) -> Plan:
    """Several steps of odd joint names, one of a single point, no /tf samples, no statics."""
    names = ("a", "bcd", "efghi")
    steps = tuple(
        StepResult(f"step_{i}", {}, "RRTConnect", 0.01, random_trajectory(names, count, seed=i))
        for i, count in enumerate([1, 5, 2, 30])
    )
    tf = TfSamples(np.zeros(0), ("odd",), ("frame",), np.zeros((0, 1, 7)))
    changes = {"steps": steps, "tf": tf, "planning_frame": "wor", "static_frames": ()}
    return Plan(**{**vars(plan), **changes})


@pytest.mark.parametrize("distro", DISTROS)
@pytest.mark.parametrize("which", ["plan", "edge_plan"])
def test_every_written_message_is_what_the_generic_encoder_writes(
    tmp_path: Path, distro: str, which: str, request: pytest.FixtureRequest
) -> None:
    plan = request.getfixturevalue(which)
    path = tmp_path / "plan.mcap"
    write_plan(path, plan, distro=distro)
    frame, trajectories = plan.planning_frame, [step.trajectory for step in plan.steps]
    statics = plan.static_frames
    expected = {
        "/robot_description": [msgs.string_message(plan.urdf)],
        "/tf_static": [
            msgs.tf_message(
                [f.parent for f in statics],
                [f.name for f in statics],
                list(tf_poses(np.reshape([f.transform for f in statics], (len(statics), 4, 4)))),
                stamp_ns=0,
            )
        ],
        "/planning_scene_markers": [msgs.marker_array(plan.objects, frame)],
        "/display_planned_path": [msgs.display_trajectory(plan.robot_name, trajectories, frame)],
        "/planned_trajectory": [msgs.joint_trajectory(t, frame) for t in trajectories],
        "/tf": [
            msgs.tf_message(
                plan.tf.parents, plan.tf.children, list(sample), round(float(time_s) * 1e9)
            )
            for time_s, sample in zip(plan.tf.times_s, plan.tf.poses, strict=True)
        ],
    }
    written: dict[str, list[bytes]] = {topic: [] for topic in TYPES}
    with path.open("rb") as stream:
        for _, channel, message in make_reader(stream).iter_messages(log_time_order=False):
            written[channel.topic].append(message.data)
    for topic, messages in expected.items():
        want = reference_cdr(TYPES[topic], distro, messages)
        assert written[topic] == want, topic
    decoded = read_all(path)  # and an independent reader decodes every one of them
    assert len(decoded) == sum(len(messages) for messages in expected.values())
    trajectory_messages = on(decoded, "/planned_trajectory")
    for (_, message), trajectory in zip(trajectory_messages, trajectories, strict=True):
        np.testing.assert_array_equal([p.positions for p in message.points], trajectory.positions)


def test_same_edge_plan_written_twice_gives_identical_bytes(
    tmp_path: Path, edge_plan: Plan
) -> None:
    write_plan(tmp_path / "a.mcap", edge_plan)
    write_plan(tmp_path / "b.mcap", edge_plan)
    assert (tmp_path / "a.mcap").read_bytes() == (tmp_path / "b.mcap").read_bytes()


@pytest.mark.parametrize("distro", DISTROS)
@pytest.mark.parametrize("count", [0, 1, 6])
def test_fast_markers_match_the_generic_encoder(distro: str, count: int, tmp_path: Path) -> None:
    mesh = tmp_path / "tray.obj"  # a mesh file becomes a mesh_resource URI; an inline mesh, its triangles
    inline = Shape("mesh", vertices=np.eye(3), triangles=np.array([[0, 1, 2]]))
    shapes = [Shape("box", (1.2, 0.8, 0.05)), Shape("cylinder", (0.05, 0.6)), Shape("sphere", (0.04,)),
              Shape("mesh", mesh_path=str(mesh), scale=(0.001, 0.001, 0.002)), inline,
              Shape("mesh", mesh_path="package://tray/tray.stl")]
    objects = [CollisionObject(f"object {k}", shapes[k], transform((0.1 * k, -0.2, 0.3), (1, 1, 0), 0.3 * k),
                               link="tool0" if k % 2 else "", touch_links=("tool0",) if k % 2 else ())
               for k in range(count)]
    expected = generic("visualization_msgs/msg/MarkerArray", distro, msgs.marker_array(objects, "world"))
    assert message_cdr.marker_array_cdr(objects, "world") == expected
