"""The CDR layout of sensor_msgs/msg/JointState, both ways: payloads built, and parsed.

`encode_joint_states` builds payloads for writers and tests; `parse_layout` finds where
the fields of one payload lie, which core.bag.jointstates uses as a template for the rows
laid out alike; `check_definition` checks that a ros2msg schema named JointState has
its fields.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt
from numpy.typing import NDArray

from ...errors import InputError
from ._primitives import CdrWriter, patched_copies

__all__ = [
    "JOINT_STATE_TYPE",
    "JointStateLayout",
    "check_definition",
    "encode_joint_states",
    "parse_layout",
]

JOINT_STATE_TYPE = "sensor_msgs/msg/JointState"

_EXPECTED_FIELDS = [
    ("header", ("std_msgs/Header", "std_msgs/msg/Header", "Header")),
    ("name", ("string[]",)),
    ("position", ("float64[]",)),
    ("velocity", ("float64[]",)),
    ("effort", ("float64[]",)),
]


def encode_joint_states(
    names: Sequence[str],
    stamps_ns: npt.ArrayLike,
    positions: npt.ArrayLike,
    velocities: npt.ArrayLike | None = None,
    efforts: npt.ArrayLike | None = None,
    frame_id: str = "",
) -> list[bytes]:
    """Return one little-endian CDR sensor_msgs/msg/JointState payload per row of `positions`.

    Built with numpy: one template row (frame_id, names, array sizes) repeated, with
    stamps and values written into their columns, so a million messages take about a second.

    Args:
        names: Joint names, n.
        stamps_ns: header.stamp per message in [ns], shape (M,).
        positions: In [rad] or [m], shape (M, n).
        velocities: Shape (M, n), or None for empty arrays.
        efforts: Shape (M, n), or None for empty arrays.
        frame_id: header.frame_id of every message.

    """
    stamps = np.asarray(stamps_ns, dtype=np.int64)
    count, n = len(stamps), len(names)
    template = CdrWriter()
    # sec as int32, as builtin_interfaces/Time has it (cdr.time_array refuses a negative time).
    times = np.column_stack(np.divmod(stamps, 1_000_000_000)).astype("<i4")
    patches: list[tuple[int, NDArray[np.generic]]] = [(template.time(0), times)]
    template.string(frame_id)
    template.strings(names)
    for values in (positions, velocities, efforts):
        if values is None:
            template.uint32(0)
        else:
            at = template.float64_sequence(np.zeros(n))
            patches.append((at, np.asarray(values, dtype="<f8").reshape(count, n)))
    rows = patched_copies(template.data(), count, patches)
    data, size = rows.tobytes(), rows.shape[1]
    return [data[i * size : (i + 1) * size] for i in range(count)]


@dataclass(frozen=True)
class JointStateLayout:
    """Where the fields of one JointState payload lie, in bytes from the payload's start."""

    little: bool
    stamp_ns: int
    names: tuple[str, ...]
    length: int
    position_at: int
    position_count_at: int
    position_size: int
    velocity_count_at: int
    velocity_at: int
    velocity_size: int
    effort_count_at: int


def parse_layout(data: bytes) -> JointStateLayout:
    """Return the layout of one CDR JointState payload.

    Raises:
        ValueError: The payload is not plain CDR, or lists more than it holds.
        struct.error: The payload is cut inside a field.

    """
    if len(data) < 16 or data[0] != 0:
        raise ValueError("a JointState message is too short or not plain CDR")
    if data[1] not in (0, 1):
        raise ValueError(f"unsupported CDR encapsulation 0x{data[:2].hex()}")
    order = "<" if data[1] == 1 else ">"

    def u32(at: int) -> int:
        return int(struct.unpack_from(order + "I", data, at)[0])

    def aligned(at: int, alignment: int) -> int:
        return at + (-(at - 4) % alignment)

    sec, nanosec = struct.unpack_from(order + "iI", data, 4)
    position = 16 + u32(12)
    count = u32(aligned(position, 4))
    position = aligned(position, 4) + 4
    if count * 4 > len(data) - position:
        raise ValueError("a JointState message lists more names than it holds")
    names = []
    for _ in range(count):
        position = aligned(position, 4)
        size = u32(position)
        name = data[position + 4 : position + 4 + size].rstrip(b"\x00")
        names.append(name.decode(errors="replace"))
        position += 4 + size
    arrays = []
    for _ in range(3):
        count_at = aligned(position, 4)
        size = u32(count_at)
        position = count_at + 4
        if size:
            position = aligned(position, 8)
        arrays.append((count_at, position, size))
        position += 8 * size
    if position > len(data):
        raise ValueError("a JointState message is shorter than its arrays")
    (p_count, p_at, p_size), (v_count, v_at, v_size), (e_count, _, _) = arrays
    return JointStateLayout(order == "<", int(sec) * 1_000_000_000 + int(nanosec), tuple(names),
                            len(data), p_at, p_count, p_size, v_count, v_at, v_size, e_count)


def check_definition(path: Path, topic: str, text: bytes) -> None:
    """Raise InputError unless the schema's top-level fields are JointState's, in order."""
    top = text.decode(errors="replace").split("\n" + "=" * 80)[0]
    fields = []
    for line in top.splitlines():
        line = line.split("#", 1)[0].strip()
        if line and "=" not in line:
            parts = line.split()
            fields.append((parts[-1] if len(parts) > 1 else "", parts[0]))
    ok = len(fields) == len(_EXPECTED_FIELDS) and all(
        name == want and kind in kinds
        for (name, kind), (want, kinds) in zip(fields, _EXPECTED_FIELDS, strict=True)
    )
    if not ok:
        found = ", ".join(f"{kind} {name}" for name, kind in fields) or "(none)"
        raise InputError(f"{path}: the schema of {topic} is named {JOINT_STATE_TYPE} but its "
                         f"fields are not JointState's (header, name, position, velocity, "
                         f"effort): {found}")
