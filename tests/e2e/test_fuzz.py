"""Fuzzing plan files, recordings and config YAML: whatever the bytes or values, a command ends with a
documented exit code and one line (or its verdict), never a traceback, an internal error, a hang or a
memory blow-up.

What is fuzzed:
- plan files: a small plan written once per module by `moveplan plan` (and the shipped
  samples/recordings/tool_up_plan.mcap), damaged at three levels: raw bytes (flipped, overwritten,
  inserted, spliced from elsewhere in the file, cut short), MCAP records (a record's length, opcode or
  an integer field of its content set to 0, 1, a neighbour of the true value, 2**32 or 2**64 - 1, a
  record dropped or repeated; in an uncompressed copy without CRCs, so the damage reaches the records
  inside chunks), and content rewritten into a valid container (message payloads with their CDR
  lengths, doubles and byte order garbled, message times moved, schemas, the "moveplan" metadata's
  JSON and the attached robot config spoiled);
- recordings: the shipped samples/recordings/*.mcap and an executed plan, damaged the same ways, and
  a tiny rosbag2 .db3 written here (rows with damaged payloads, timestamps of every SQL type, wrong
  topics; the sqlite file's bytes; a bag folder's metadata.yaml);
- config YAML: the shipped configs/ur10e/*.yaml, samples' scene and task files and a MoveIt
  MotionPlanRequest with values replaced by NaN, infinities, huge integers and floats, empty
  strings, wrong types and junk, keys dropped or renamed; and documents generated from nested
  dicts, lists and such scalars, given in place of each file.

Commands run: inspect, check-tolerances PLAN RECORDING, execute --fake PLAN -o OUT, plan [TASK],
robot CONFIG, state. What is asserted of each run: the exit code is 0, 3, 4 or 5 as the command
allows (2 where a usage error applies: a task or request naming no goal); an error exit prints exactly
one non-empty line on stderr (with --json: one strict JSON document on stdout, no NaN or Infinity,
whose error names that exit code); 0 and 5 print their verdict; "Traceback" and "internal error" never
appear, nor a control character (a carriage return or escape sequence from the input, which would
garble or drive the user's terminal) outside JSON; a failed execute or plan leaves no output file.
Runs are in-process (typer's CliRunner) under a memory limit (RLIMIT_AS: what the test process uses
plus 3 GiB) and an alarm, both safety nets only; a few run as subprocesses with RLIMIT_AS at 3 GiB and
a timeout. Below the fuzz tests, plain tests keep the defects the fuzzer found as regressions.

Examples are derandomized: the same ones run every time and none depends on the clock. For a long
run by hand, MOVEPLAN_FUZZ_EXAMPLES=N runs N examples per test with random seeds instead
(`--hypothesis-seed` replays one; a failure prints its @reproduce_failure blob), and
MOVEPLAN_FUZZ_KEEP=DIR keeps the files of each test's last failing example in DIR/<test name>:

    MOVEPLAN_FUZZ_EXAMPLES=500 MOVEPLAN_FUZZ_KEEP=/tmp/fuzz .venv/bin/python -m pytest tests/e2e/test_fuzz.py
"""

from __future__ import annotations

import contextlib
import copy
import json
import math
import os
import re
import resource
import shutil
import signal
import sqlite3
import struct
import subprocess
import sys
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from io import BytesIO
from pathlib import Path
from typing import Any

import pytest
import yaml
from conftest import SAMPLES, UR10E, Cli
from hypothesis import HealthCheck, Phase, event, given, settings
from hypothesis import strategies as st
from hypothesis.control import currently_in_test_context
from mcap.records import Attachment, Channel, Message, Metadata, Schema
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, Writer
from test_db3 import HUMBLE_SCHEMA

RECORDINGS = SAMPLES / "recordings"
SAMPLE_PLAN = RECORDINGS / "tool_up_plan.mcap"
SAMPLE_RECORDINGS = sorted(p for p in RECORDINGS.glob("*.mcap") if p != SAMPLE_PLAN)
JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
          "wrist_3_joint"]
START = "0,-1.45,-1.45,0,0,0"

# ------------------------------------------------------------------------------------------- budget

LONG_RUN = int(os.environ.get("MOVEPLAN_FUZZ_EXAMPLES", "0") or 0)
MEMORY_LIMIT = 3 << 30  # bytes of address space a run may add (in-process) or use (subprocess)
SAFETY_S = 120  # a run's wall-clock safety limit: never reached by a correct run, which takes < 2 s
_SUPPRESSED = [HealthCheck.function_scoped_fixture, HealthCheck.too_slow, HealthCheck.data_too_large,
               HealthCheck.large_base_example, HealthCheck.filter_too_much]

_PHASES = [Phase.explicit, Phase.generate, Phase.shrink]  # no explain phase: it reruns a failure dozens of times


def fuzz(examples: int) -> settings:
    """The settings of one fuzz test: `examples` derandomized examples, or MOVEPLAN_FUZZ_EXAMPLES random ones."""
    if LONG_RUN:
        return settings(max_examples=LONG_RUN, deadline=None, derandomize=False, database=None,
                        print_blob=True, suppress_health_check=_SUPPRESSED, phases=_PHASES)
    return settings(max_examples=examples, deadline=None, derandomize=True, database=None,
                    suppress_health_check=_SUPPRESSED, phases=_PHASES)


class SafetyLimit(BaseException):
    """A run went past SAFETY_S: a BaseException, so that no `except Exception` in moveplan swallows it."""


@contextlib.contextmanager
def bounded() -> Iterator[None]:
    """Run the body with at most MEMORY_LIMIT more address space and a SAFETY_S alarm (safety nets only)."""
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    with open("/proc/self/statm") as statm:
        in_use = int(statm.read().split()[0]) * resource.getpagesize()
    limit = in_use + MEMORY_LIMIT if hard == resource.RLIM_INFINITY else min(in_use + MEMORY_LIMIT, hard)

    def alarm(signum: int, frame: Any) -> None:
        raise SafetyLimit(f"a run took more than {SAFETY_S} s")

    previous = signal.signal(signal.SIGALRM, alarm)
    resource.setrlimit(resource.RLIMIT_AS, (limit, hard))
    signal.alarm(SAFETY_S)
    try:
        yield
    finally:
        signal.alarm(0)
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
        signal.signal(signal.SIGALRM, previous)


# ------------------------------------------------------------------------------------------- outcome

@dataclass
class Outcome:
    """What a run of moveplan showed its user."""

    args: list[str]
    code: int
    stdout: str
    stderr: str
    exception: BaseException | None = None


Invoke = Callable[..., Outcome]
"""Runs moveplan with the given arguments and returns what it showed."""


def in_process(cli: Cli) -> Invoke:
    """Return an Invoke running moveplan in this process (typer's CliRunner), bounded."""

    def invoke(*args: Any) -> Outcome:
        with bounded():
            result = cli(*args)
        exception = None if isinstance(result.exception, SystemExit) else result.exception
        return Outcome([str(a) for a in args], result.exit_code, result.stdout, result.stderr, exception)

    return invoke


def _limit_child() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))


def as_process(*args: Any) -> Outcome:
    """Run moveplan as its own process with RLIMIT_AS at MEMORY_LIMIT and a SAFETY_S timeout."""
    argv = [str(a) for a in args]
    try:
        done = subprocess.run([sys.executable, "-m", "moveplan.cli.app", *argv], capture_output=True, text=True,
                              timeout=SAFETY_S, preexec_fn=_limit_child)
    except subprocess.TimeoutExpired as exc:
        raise AssertionError(f"moveplan {' '.join(argv)}: still running after {SAFETY_S} s") from exc
    return Outcome(argv, done.returncode, done.stdout, done.stderr)


CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f]")
"""ASCII control characters but tab and newline."""


def _not_json(constant: str) -> Any:
    raise ValueError(f"{constant} is no JSON value")


def assert_clean(outcome: Outcome, codes: set[int]) -> None:
    """Assert an exit code among `codes`, one line for an error (or one JSON document), a verdict for 0 and 5."""
    shown = f"moveplan {' '.join(outcome.args)}\nexit {outcome.code}\nstdout: {outcome.stdout[-2000:]}\n" \
            f"stderr: {outcome.stderr[-2000:]}\nexception: {outcome.exception!r}"
    if currently_in_test_context():  # the spread of outcomes, in --hypothesis-show-statistics
        event(f"{outcome.args[0]} exit {outcome.code}")
    assert outcome.exception is None, shown
    assert outcome.code in codes, shown
    for text in (outcome.stdout, outcome.stderr):
        assert "Traceback" not in text and "internal error" not in text, shown
    lines = [line for line in outcome.stderr.split("\n") if line.strip()]
    # A control character from the input (a carriage return in a key, an escape sequence in a topic
    # name) would garble the line on a terminal, or drive it.
    assert not CONTROL.search(outcome.stderr.replace("\n", "")), shown
    assert "--json" in outcome.args or not CONTROL.search(outcome.stdout.replace("\n", "")), shown
    if "--json" in outcome.args:
        try:  # one document, nothing else on stdout; strict JSON (NaN or Infinity would break a script's parser)
            document = json.loads(outcome.stdout, parse_constant=_not_json)
        except ValueError as exc:
            raise AssertionError(f"stdout is no JSON document ({exc})\n{shown}") from None
        assert isinstance(document, dict), shown
        if outcome.code in (0, 5):
            assert document.get("ok", True) is (outcome.code == 0), shown  # inspect, robot, state: no "ok"
        elif outcome.code != 2:  # a usage error found by click itself is text on stderr
            assert document["ok"] is False and document["error"]["exit_code"] == outcome.code, shown
    elif outcome.code in (0, 5):
        assert outcome.stdout.strip() or "-q" in outcome.args, shown
        assert not any(line.startswith("moveplan: error") for line in lines), shown
    else:
        assert len(lines) == 1 or (outcome.code == 2 and lines and lines[-1].startswith("Error")), shown


# ------------------------------------------------------------------------------------------- MCAP

MAGIC = b"\x89MCAP0\r\n"
CHUNK = 6
INTERESTING = [0, 1, 2, 3, 4, 7, 8, 15, 16, 255, 256, 0x7FFF, 0xFFFF, 0x10000, 0x7FFFFFFF, 0x80000000,
               0xFFFFFFFF, 1 << 32, 1 << 53, (1 << 63) - 1, 1 << 63, (1 << 64) - 1]
HOSTILE_DOUBLES = [math.nan, math.inf, -math.inf, 1e308, -1e308, 5e-324, -0.0, 1e20, -1e20, 4e9, 1e-300]


@dataclass(frozen=True)
class Record:
    """Where an MCAP record lies: offset of its opcode, opcode, content length; `inner` if inside a chunk."""

    at: int
    opcode: int
    length: int
    inner: bool = False


def mcap_records(data: bytes) -> list[Record]:
    """Return the records of an intact MCAP file, with those inside uncompressed chunks."""
    records, position = [], len(MAGIC)
    while position + 9 <= len(data):
        opcode, length = struct.unpack_from("<BQ", data, position)
        records.append(Record(position, opcode, length))
        content = position + 9
        if opcode == CHUNK:
            (size,) = struct.unpack_from("<I", data, content + 28)
            compression = data[content + 32 : content + 32 + size]
            (records_length,) = struct.unpack_from("<Q", data, content + 32 + size)
            inner, end = content + 40 + size, content + 40 + size + records_length
            while compression == b"" and inner + 9 <= end:
                inner_opcode, inner_length = struct.unpack_from("<BQ", data, inner)
                records.append(Record(inner, inner_opcode, inner_length, inner=True))
                inner += 9 + inner_length
        if opcode == 2:  # the footer, then the closing magic
            break
        position = content + length
    return records


class Damaged:
    """Damaged bytes and how they came about: the repr hypothesis shows for a failing example."""

    def __init__(self, data: bytes, how: tuple[str, ...]) -> None:
        self.data, self.how = data, how

    def __repr__(self) -> str:
        return f"Damaged({'; '.join(self.how)})"


def pack_int(value: int, size: int) -> bytes:
    """Return `value` as a little-endian unsigned integer of `size` bytes (modulo its range, as damage wraps)."""
    return (value % (1 << (8 * size))).to_bytes(size, "little")


@st.composite
def damaged_bytes(draw: st.DrawFn, data: bytes) -> Damaged:
    """`data` with one to four byte-level changes: flips, overwrites, insertions, splices, a cut."""
    result, how = bytearray(data), []
    for _ in range(draw(st.integers(1, 4))):
        kind = draw(st.sampled_from(["flip", "overwrite", "insert", "splice", "repeat", "cut"]))
        at = draw(st.integers(0, max(len(result) - 1, 0)))
        if kind == "flip" and result:
            bit = draw(st.integers(0, 7))
            result[at] ^= 1 << bit
            how.append(f"flip bit {bit} of byte {at}")
        elif kind == "overwrite":
            chunk = draw(st.binary(min_size=1, max_size=16))
            result[at : at + len(chunk)] = chunk
            how.append(f"overwrite at {at} with {chunk!r}")
        elif kind == "insert":
            chunk = draw(st.binary(min_size=1, max_size=64))
            result[at:at] = chunk
            how.append(f"insert at {at} {chunk!r}")
        elif kind in ("splice", "repeat"):  # a block of the file itself, over or beside another place
            source = draw(st.integers(0, max(len(result) - 1, 0)))
            block = bytes(result[source : source + draw(st.integers(1, 4096))])
            if kind == "splice":
                result[at : at + len(block)] = block
            else:
                result[at:at] = block
            how.append(f"{kind} at {at} the {len(block)} bytes from {source}")
        else:
            del result[at:]
            how.append(f"cut at {at}")
    return Damaged(bytes(result), tuple(how))


@st.composite
def damaged_records(draw: st.DrawFn, data: bytes) -> Damaged:
    """`data` (an MCAP file) with one to three records given a wrong length, opcode or field, dropped or repeated."""
    records = mcap_records(data)
    result, how = bytearray(data), []
    edits: list[tuple[int, int, bytes]] = []  # (at, bytes replaced, new bytes), applied from the end
    for _ in range(draw(st.integers(1, 3))):
        record = draw(st.sampled_from(records))
        kind = draw(st.sampled_from(["length", "length", "field", "field", "field", "opcode", "unknown", "drop",
                                     "repeat"]))
        whole = 9 + record.length
        name = f"the record at {record.at} (opcode {record.opcode}{', in a chunk' if record.inner else ''})"
        if kind == "length":
            value = draw(st.sampled_from([*INTERESTING, record.length - 1, record.length + 1, record.length * 2,
                                          len(data), len(data) - record.at]))
            edits.append((record.at + 1, 8, pack_int(value, 8)))
            how.append(f"length of {name} set to {value}")
        elif kind == "field" and record.length:
            offset = draw(st.integers(0, record.length - 1))
            size = draw(st.sampled_from([1, 2, 4, 8]))
            value = draw(st.sampled_from([*INTERESTING, record.length - offset, len(data)]))
            edits.append((record.at + 9 + offset, min(size, record.length - offset), pack_int(value, size)))
            how.append(f"u{8 * size} at content byte {offset} of {name} set to {value}")
        elif kind == "opcode":
            opcode = draw(st.sampled_from([0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 0x80, 0xFF]))
            edits.append((record.at, 1, bytes([opcode])))
            how.append(f"opcode of {name} set to {opcode}")
        elif kind == "unknown":  # a record of a kind no reader knows, skipped by its length: a wrong one
            value = draw(st.sampled_from([*INTERESTING, record.length + 1, len(data)]))
            edits.append((record.at, 9, bytes([0x80]) + pack_int(value, 8)))
            how.append(f"{name} made of unknown opcode 0x80 and length {value}")
        elif kind == "drop":
            edits.append((record.at, whole, b""))
            how.append(f"{name} dropped")
        elif kind == "repeat":
            edits.append((record.at, 0, data[record.at : record.at + whole]))
            how.append(f"{name} repeated")
    for at, replaced, new in sorted(edits, key=lambda edit: edit[0], reverse=True):
        result[at : at + replaced] = new
    return Damaged(bytes(result), tuple(how))


@st.composite
def garbled_cdr(draw: st.DrawFn, payload: bytes) -> Damaged:
    """A CDR payload with lengths, doubles, its byte order or its end garbled (one to three changes)."""
    result, how = bytearray(payload), []
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["u32", "u32", "double", "double", "flip", "cut", "append", "order"]))
        body = max(len(result) - 4, 1)
        if kind == "u32":  # a sequence or string length
            at = 4 + 4 * draw(st.integers(0, max(body // 4 - 1, 0)))
            value = draw(st.sampled_from([*INTERESTING, body, body // 4, body // 8]))
            result[at : at + 4] = pack_int(value, 4)
            how.append(f"u32 at {at} set to {value}")
        elif kind == "double":
            at = 4 + 8 * draw(st.integers(0, max(body // 8 - 1, 0)))
            value = draw(st.sampled_from(HOSTILE_DOUBLES))
            result[at : at + 8] = struct.pack("<d", value)
            how.append(f"double at {at} set to {value}")
        elif kind == "flip" and len(result) > 4:
            at, bit = draw(st.integers(4, len(result) - 1)), draw(st.integers(0, 7))
            result[at] ^= 1 << bit
            how.append(f"flip bit {bit} of byte {at}")
        elif kind == "cut":
            at = draw(st.integers(0, len(result)))
            del result[at:]
            how.append(f"cut at {at}")
        elif kind == "append":
            tail = draw(st.binary(min_size=1, max_size=64))
            result += tail
            how.append(f"append {tail!r}")
        elif kind == "order":  # the encapsulation header: big-endian CDR, XCDR2, junk
            header = draw(st.sampled_from([b"\x00\x00\x00\x00", b"\x00\x06\x00\x00", b"\x00\x07\x00\x00",
                                           b"\xff\xff\x00\x00", b"\x00\x01\x00\x03"]))
            result[0:4] = header
            how.append(f"encapsulation header {header!r}")
    return Damaged(bytes(result), tuple(how))


class McapContent:
    """An MCAP file's records to write again: header profile, schemas, channels, messages, metadata, attachments.

    `how` says how it differs from the file it was read from (the repr a failing example shows).
    """

    def __init__(self, profile: str, library: str, items: list[Any] | None = None) -> None:
        self.profile, self.library, self.items = profile, library, items if items is not None else []
        self.how: list[str] = []

    def __repr__(self) -> str:
        return f"McapContent({'; '.join(self.how) or 'as read'})"


def mcap_content(data: bytes) -> McapContent:
    """Return the records of an intact MCAP file a writer writes again, in file order."""
    content = McapContent("ros2", "moveplan fuzz")
    for record in StreamReader(BytesIO(data)).records:
        if type(record).__name__ == "Header":
            content.profile, content.library = record.profile, record.library
        elif isinstance(record, Schema | Channel | Message | Attachment | Metadata):
            content.items.append(record)
    return content


@dataclass(frozen=True)
class Layout:
    """How a file is written: chunk size, compression, chunked or not, CRCs or not."""

    chunk_size: int = 1 << 20
    compression: CompressionType = CompressionType.ZSTD
    chunked: bool = True
    crcs: bool = True


def write_mcap(content: McapContent, layout: Layout) -> bytes:
    """Return `content` written as an MCAP file laid out as `layout` says (schemas and channels renumbered)."""
    stream = BytesIO()
    writer = Writer(stream, chunk_size=layout.chunk_size, compression=layout.compression,
                    use_chunking=layout.chunked, enable_crcs=layout.crcs)
    writer.start(content.profile, content.library)
    schemas: dict[int, int] = {}
    channels: dict[int, int] = {}
    for item in content.items:
        if isinstance(item, Schema) and item.id not in schemas:
            schemas[item.id] = writer.register_schema(item.name, item.encoding, item.data)
        elif isinstance(item, Channel) and item.id not in channels:
            channels[item.id] = writer.register_channel(item.topic, item.message_encoding,
                                                        schemas.get(item.schema_id, 0), item.metadata)
        elif isinstance(item, Message):
            writer.add_message(channels.get(item.channel_id, item.channel_id), item.log_time, item.data,
                               item.publish_time, item.sequence)
        elif isinstance(item, Attachment):
            writer.add_attachment(item.create_time, item.log_time, item.name, item.media_type, item.data)
        elif isinstance(item, Metadata):
            writer.add_metadata(item.name, item.metadata)
    writer.finish()
    return stream.getvalue()


LAYOUTS = st.builds(Layout, chunk_size=st.sampled_from([2048, 32768, 1 << 20]),
                    compression=st.sampled_from([CompressionType.ZSTD, CompressionType.NONE, CompressionType.LZ4]),
                    chunked=st.booleans(), crcs=st.booleans())

# ------------------------------------------------------------------------------------------- YAML values

HOSTILE_SCALARS = [math.nan, math.inf, -math.inf, 1e308, -1e308, 1e-320, 2**70, -(2**70), 2**63, -1, 0, 0.0, -0.5,
                   "", " ", "nan", "inf", "pi", "-pi/0", "x" * 300, "\u00e9\u2603\n\t", None, True, False,
                   "$(env MOVEPLAN_FUZZ_UNSET)", "$(find nowhere)/x", "package://nowhere/x.stl", "/dev/zero",
                   "/proc/self/mem", "../../../../etc/passwd", "tool0", "base_link", "elbow_joint", "home"]
SCALARS = st.one_of(st.sampled_from(HOSTILE_SCALARS), st.integers(), st.floats(), st.text(max_size=12),
                    st.booleans(), st.none())
HOSTILE_VALUES = st.one_of(
    st.sampled_from(HOSTILE_SCALARS),
    st.sampled_from([[], {}, [1, 2, 3], [math.nan] * 6, [0] * 100, {"a": {"b": None}}, [[[[]]]], {"": ""}]),
    SCALARS,
)
DOCUMENTS = st.recursive(SCALARS, lambda inner: st.lists(inner, max_size=4)
                         | st.dictionaries(st.text(max_size=8) | st.sampled_from(["name", "joints", "steps"]), inner,
                                           max_size=4),
                         max_leaves=12)


def paths_of(document: Any, prefix: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Return the paths (keys and indexes) of every node under `document`, itself excluded."""
    found = []
    items = document.items() if isinstance(document, dict) else enumerate(document) if isinstance(document, list) \
        else []
    for key, value in items:
        found.append((*prefix, key))
        found.extend(paths_of(value, (*prefix, key)))
    return found


HOSTILE_NUMBERS = st.sampled_from([0, 0.0, -0.0, -1, -0.5, 1e-9, 5e-324, 1e9, 1e308, -1e308, 2**31, 2**63, 2**70,
                                   math.nan, math.inf, -math.inf, 3.14159265, 100])


@st.composite
def spoiled(draw: st.DrawFn, document: Any) -> Any:
    """A copy of a parsed YAML document with one to three nodes replaced, dropped, renamed or wrapped.

    Numbers are mostly replaced by numbers (zero, negative, tiny, huge, NaN, infinite): values that
    pass a type check and reach what the number is used for.
    """
    result = copy.deepcopy(document)
    for _ in range(draw(st.sampled_from([1, 1, 1, 2, 3]))):
        paths = paths_of(result)
        if not paths:
            return draw(HOSTILE_VALUES)
        path = draw(st.sampled_from(sorted(paths, key=repr)))
        parent = result
        for key in path[:-1]:
            parent = parent[key]
        key = path[-1]
        number = isinstance(parent[key], int | float) and not isinstance(parent[key], bool)
        kinds = ["number"] * 4 if number else []
        kind = draw(st.sampled_from([*kinds, "replace", "replace", "replace", "drop", "rename", "wrap", "document"]))
        if kind == "number":
            parent[key] = draw(HOSTILE_NUMBERS)
        elif kind == "replace":
            parent[key] = copy.deepcopy(draw(HOSTILE_VALUES))
        elif kind == "drop":
            del parent[key]
        elif kind == "rename" and isinstance(parent, dict):
            parent[draw(st.sampled_from(["", "x", "name", "type", "joints", "  ", "<<"]))] = parent.pop(key)
        elif kind == "wrap":
            parent[key] = [parent[key]] if draw(st.booleans()) else {"value": parent[key]}
        else:
            parent[key] = draw(DOCUMENTS)
    return result


def dump(document: Any) -> str:
    """YAML text of `document` (any Python value: NaN and infinities as .nan and .inf)."""
    return yaml.safe_dump(document, allow_unicode=True, sort_keys=False)


# ------------------------------------------------------------------------------------------- fixtures

@dataclass(frozen=True, repr=False)
class Files:
    """The intact files the fuzz tests damage, written once per module."""

    folder: Path
    plan: Path  # a one-step plan of the ur10e, from START to home
    executed: Path  # that plan executed (a recording that passes)
    db3: Path  # the executed /joint_states as a rosbag2 sqlite3 file
    plan_bytes: bytes
    plain_plan: bytes  # the plan uncompressed, without CRCs: damage reaches records inside chunks
    executed_bytes: bytes
    plain_executed: bytes
    plan_content: McapContent
    executed_content: McapContent

    def plan_source(self, source: str) -> bytes:
        """Return the plan file as written ("written"), written plain ("plain"), or the shipped sample plan."""
        return {"written": self.plan_bytes, "plain": self.plain_plan}.get(source) or SAMPLE_PLAN.read_bytes()

    def __repr__(self) -> str:
        return f"Files({self.folder})"

    def _repr_pretty_(self, printer: Any, cycle: bool) -> None:  # what hypothesis prints: not the bytes
        printer.text(repr(self))




def write_db3(path: Path, content: McapContent, topic: str = "/joint_states") -> Path:
    """Write `content`'s messages on `topic` as Humble's rosbag2 sqlite3 storage does: one row each."""
    channels = {item.id: item for item in content.items if isinstance(item, Channel)}
    schemas = {item.id: item for item in content.items if isinstance(item, Schema)}
    connection = sqlite3.connect(path)
    connection.executescript(HUMBLE_SCHEMA)
    topics: dict[int, int] = {}
    for item in content.items:
        if isinstance(item, Message) and channels[item.channel_id].topic == topic:
            channel = channels[item.channel_id]
            if channel.id not in topics:
                topics[channel.id] = connection.execute(
                    "INSERT INTO topics (name, type, serialization_format, offered_qos_profiles) VALUES (?, ?, ?, ?)",
                    (topic, schemas[channel.schema_id].name, "cdr", channel.metadata.get("offered_qos_profiles", ""))
                ).lastrowid
            connection.execute("INSERT INTO messages (timestamp, topic_id, data) VALUES (?, ?, ?)",
                               (item.log_time, topics[channel.id], item.data))
    connection.commit()
    connection.close()
    return path


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> Files:
    return make_files(tmp_path_factory.mktemp("fuzz"))


def make_files(folder: Path) -> Files:
    """Write the intact files into `folder`: a plan from START to home, its execution, that as a .db3."""
    cli = Cli()
    plan, executed = folder / "plan.mcap", folder / "executed.mcap"
    result = cli("plan", "--robot", "ur10e", "--named", "home", "--start-joints", START, "-o", plan, "-q")
    assert result.exit_code == 0, result.stderr
    result = cli("execute", plan, "--fake", "-o", executed, "-q")
    assert result.exit_code == 0, result.stderr
    plan_content, executed_content = mcap_content(plan.read_bytes()), mcap_content(executed.read_bytes())
    plain = Layout(compression=CompressionType.NONE, crcs=False)
    return Files(
        folder=folder, plan=plan, executed=executed, db3=write_db3(folder / "executed.db3", executed_content),
        plan_bytes=plan.read_bytes(), plain_plan=write_mcap(plan_content, plain),
        executed_bytes=executed.read_bytes(), plain_executed=write_mcap(executed_content, plain),
        plan_content=plan_content, executed_content=executed_content,
    )


KEEP = os.environ.get("MOVEPLAN_FUZZ_KEEP", "")
"""A folder where a failing example's files are kept (the last, shrunk one wins), for a reproducer by hand."""


@contextlib.contextmanager
def scratch_folder() -> Iterator[Path]:
    """A fresh folder per example (hypothesis runs many examples in one call of a test); kept in KEEP on failure."""
    with tempfile.TemporaryDirectory(prefix="moveplan-fuzz-") as name:
        try:
            yield Path(name)
        except AssertionError:
            if KEEP:
                kept = Path(KEEP) / os.environ.get("PYTEST_CURRENT_TEST", "test").split("::")[-1].split()[0]
                shutil.rmtree(kept, ignore_errors=True)
                shutil.copytree(name, kept)
            raise


# ------------------------------------------------------------------------------------------- plan files

PLAN_COMMANDS = ["inspect", "execute", "state", "check-tolerances"]
PLAN_SOURCES = st.sampled_from(["written", "plain", "sample"])
"""Which plan file is damaged: see Files.plan_source."""


def use_plan(invoke: Invoke, plan: Path, command: str, files: Files, as_json: bool) -> None:
    """Run `command` on the plan file `plan` (check-tolerances: with the plan's executed recording); assert it clean."""
    flags = ["--json"] if as_json else []
    if command == "inspect":
        assert_clean(invoke("inspect", plan, *flags), {0, 3})
    elif command == "execute":
        out = plan.parent / "executed.mcap"
        outcome = invoke("execute", plan, "--fake", "-o", out, *flags)
        assert_clean(outcome, {0, 3, 5})
        assert out.exists() == (outcome.code in (0, 5)), outcome
    elif command == "state":
        assert_clean(invoke("state", "--from", plan, *flags), {0, 3})
    else:
        assert_clean(invoke("check-tolerances", plan, files.executed, *flags), {0, 3, 5})


@fuzz(60)
@given(data=st.data(), source=PLAN_SOURCES, command=st.sampled_from(PLAN_COMMANDS), as_json=st.booleans())
def test_a_plan_file_with_damaged_bytes_is_refused_in_one_line_or_used(
    cli: Cli, files: Files, data: st.DataObject, source: str, command: str, as_json: bool
) -> None:
    with scratch_folder() as scratch:
        plan = scratch / "plan.mcap"
        plan.write_bytes(data.draw(damaged_bytes(files.plan_source(source))).data)
        use_plan(in_process(cli), plan, command, files, as_json)


@fuzz(60)
@given(data=st.data(), source=PLAN_SOURCES, command=st.sampled_from(PLAN_COMMANDS), as_json=st.booleans())
def test_a_plan_file_with_wrong_record_lengths_or_fields_is_refused_in_one_line_or_used(
    cli: Cli, files: Files, data: st.DataObject, source: str, command: str, as_json: bool
) -> None:
    with scratch_folder() as scratch:
        plan = scratch / "plan.mcap"
        plan.write_bytes(data.draw(damaged_records(files.plan_source(source))).data)
        use_plan(in_process(cli), plan, command, files, as_json)


@st.composite
def garbled_content(draw: st.DrawFn, content: McapContent, topics: list[str] | None = None) -> McapContent:
    """`content` with one to three messages garbled (payload or times) or dropped, a schema or a channel spoiled."""
    result = McapContent(content.profile, content.library, list(content.items))
    channels = {item.id: item for item in content.items if isinstance(item, Channel)}
    messages = [i for i, item in enumerate(content.items) if isinstance(item, Message)
                and (topics is None or channels[item.channel_id].topic in topics)]
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["payload", "payload", "payload", "times", "schema", "channel", "drop"]))
        if kind in ("payload", "times", "drop"):
            index = draw(st.sampled_from(messages))
            message = result.items[index]
            if message is None:
                continue
            topic = channels[message.channel_id].topic
            if kind == "payload":
                garbled = draw(garbled_cdr(message.data))
                result.items[index] = replace(message, data=garbled.data)
                result.how.append(f"message {index} on {topic}: {'; '.join(garbled.how)}")
            elif kind == "times":
                log_time = draw(st.sampled_from([0, 1, (1 << 63) - 1, (1 << 64) - 1, max(message.log_time - 10**9, 0),
                                                 min(message.log_time + 10**18, (1 << 64) - 1)]))
                result.items[index] = replace(message, log_time=log_time, publish_time=log_time)
                result.how.append(f"message {index} on {topic}: log and publish time {log_time}")
            else:
                result.items[index] = None
                result.how.append(f"message {index} on {topic} dropped")
        elif kind == "schema":
            index = draw(st.sampled_from([i for i, item in enumerate(result.items) if isinstance(item, Schema)]))
            schema = result.items[index]
            text = draw(st.sampled_from([b"", b"int32 x", b"float64[] positions", b"string data\n===\n",
                                         b"MSG: x/Y\nint8 a", schema.data[: len(schema.data) // 2],
                                         schema.data.replace(b"float64", b"float32"),
                                         schema.data.replace(b"string", b"uint64"),
                                         schema.data.replace(b"[]", b"[3]")]))
            name = draw(st.sampled_from([schema.name, "", "std_msgs/msg/String", "sensor_msgs/msg/JointState",
                                         "nope/msg/Nope", "a" * 300, "x\x1b[31m/msg/Y"]))
            encoding = draw(st.sampled_from([schema.encoding, "ros2idl", "", "jsonschema"]))
            result.items[index] = replace(schema, name=name, encoding=encoding, data=text)
            result.how.append(f"schema {schema.id} ({schema.name}): name {name!r}, encoding {encoding!r}, "
                              f"text {text[:40]!r}... ({len(text)} bytes)")
        else:
            index = draw(st.sampled_from([i for i, item in enumerate(result.items) if isinstance(item, Channel)]))
            channel = result.items[index]
            topic = draw(st.sampled_from([channel.topic, "", "/joint_states", "/planned_trajectory",
                                          "/robot_description", "/tf", "/joint\x1b[2Jstates", "/a\rb"]))
            encoding = draw(st.sampled_from([channel.message_encoding, "json", "", "cdr"]))
            schema_id = draw(st.sampled_from([channel.schema_id, 0, 99]))
            metadata = draw(st.sampled_from([channel.metadata, {}, {"offered_qos_profiles": "- {history: [}"},
                                             {"offered_qos_profiles": "nan"}]))
            result.items[index] = replace(channel, schema_id=schema_id, topic=topic, message_encoding=encoding,
                                          metadata=metadata)
            result.how.append(f"channel {channel.id} ({channel.topic}): topic {topic!r}, encoding {encoding!r}, "
                              f"schema {schema_id}, metadata {metadata!r}")
    result.items = [item for item in result.items if item is not None]
    return result


@fuzz(80)
@given(data=st.data(), layout=LAYOUTS, command=st.sampled_from(PLAN_COMMANDS), as_json=st.booleans())
def test_a_plan_whose_messages_or_schemas_are_garbled_is_refused_in_one_line_or_used(
    cli: Cli, files: Files, data: st.DataObject, layout: Layout, command: str, as_json: bool
) -> None:
    with scratch_folder() as scratch:
        plan = scratch / "plan.mcap"
        plan.write_bytes(write_mcap(data.draw(garbled_content(files.plan_content)), layout))
        use_plan(in_process(cli), plan, command, files, as_json)


@st.composite
def spoiled_plan_records(draw: st.DrawFn, content: McapContent) -> McapContent:
    """`content` (a plan's) with its "moveplan" metadata's JSON values or an attached config file spoiled."""
    result = McapContent(content.profile, content.library, list(content.items))
    for _ in range(draw(st.integers(1, 2))):
        if draw(st.booleans()):
            index = next(i for i, item in enumerate(result.items)
                         if isinstance(item, Metadata) and item.name == "moveplan")
            metadata = dict(result.items[index].metadata)
            key = draw(st.sampled_from(sorted(metadata)))
            try:
                value = json.loads(metadata[key])
            except ValueError:
                value = metadata[key]
            spoilt = json.dumps(draw(spoiled(value)) if isinstance(value, dict | list) else draw(HOSTILE_VALUES))
            metadata[key] = draw(st.sampled_from([spoilt, spoilt, spoilt, "", "{", "nan", "[]", "null"]))
            if draw(st.integers(0, 4)) == 0:
                del metadata[key]
            result.items[index] = replace(result.items[index], metadata=metadata)
            result.how.append(f"moveplan metadata {key!r}: {metadata.get(key, '(dropped)')[:300]!r}")
        else:
            index = draw(st.sampled_from([i for i, item in enumerate(result.items) if isinstance(item, Attachment)]))
            attachment = result.items[index]
            try:  # a config file, not one spoiled and renamed .yaml already
                parsed = yaml.safe_load(attachment.data) if attachment.name.endswith(".yaml") else None
            except yaml.YAMLError:
                parsed = None
            if parsed is not None:
                text = dump(draw(spoiled(parsed)))
            else:
                text = draw(st.sampled_from(["", "<robot/>", "<robot name='x'><link name='a'/></robot>", "<<<",
                                             attachment.data.decode()[: len(attachment.data) // 2]]))
            name = draw(st.sampled_from([attachment.name, attachment.name, "", "../../x.yaml", "a.urdf"]))
            result.items[index] = replace(attachment, name=name, data=text.encode())
            result.how.append(f"attachment {attachment.name} named {name!r}, text {text[:300]!r}")
    return result


@fuzz(50)
@given(data=st.data(), command=st.sampled_from(PLAN_COMMANDS), as_json=st.booleans())
def test_a_plan_with_spoiled_metadata_or_attached_config_is_refused_in_one_line_or_used(
    cli: Cli, files: Files, data: st.DataObject, command: str, as_json: bool
) -> None:
    with scratch_folder() as scratch:
        plan = scratch / "plan.mcap"
        plan.write_bytes(write_mcap(data.draw(spoiled_plan_records(files.plan_content)), Layout()))
        use_plan(in_process(cli), plan, command, files, as_json)


# ------------------------------------------------------------------------------------------- recordings

CHECK_FLAGS = st.sampled_from([(), (), ("--start", "all"), ("--skip-damaged",), ("--time-source", "log"),
                               ("--start", "0.5"), ("--topic", "/joint_trajectory_controller/controller_state")])


def use_recording(invoke: Invoke, recording: Path, plan: Path, flags: tuple[str, ...], inspect: bool,
                  as_json: bool) -> None:
    """Check `recording` against `plan` (or inspect it) and assert a clean outcome."""
    extra = ["--json"] if as_json else []
    if inspect:
        assert_clean(invoke("inspect", recording, *[f for f in flags if f == "--skip-damaged"], *extra), {0, 3})
    else:
        assert_clean(invoke("check-tolerances", plan, recording, *flags, *extra), {0, 3, 5})


@fuzz(60)
@given(data=st.data(), ours=st.booleans(), flags=CHECK_FLAGS, inspect=st.booleans(), as_json=st.booleans())
def test_a_recording_with_damaged_bytes_or_records_is_judged_or_refused_in_one_line(
    cli: Cli, files: Files, data: st.DataObject, ours: bool, flags: tuple[str, ...], inspect: bool, as_json: bool
) -> None:
    if ours:  # the plan's own execution, intact or as written plain (uncompressed, without CRCs)
        plan, source = files.plan, data.draw(st.sampled_from([files.executed_bytes, files.plain_executed]))
    else:
        plan, source = SAMPLE_PLAN, data.draw(st.sampled_from(SAMPLE_RECORDINGS)).read_bytes()
    damage = damaged_records if data.draw(st.booleans()) else damaged_bytes
    with scratch_folder() as scratch:
        recording = scratch / "recording.mcap"
        recording.write_bytes(data.draw(damage(source)).data)
        use_recording(in_process(cli), recording, plan, flags, inspect, as_json)


@fuzz(60)
@given(data=st.data(), layout=LAYOUTS, flags=CHECK_FLAGS, inspect=st.booleans(), as_json=st.booleans(),
       topics=st.sampled_from([["/joint_states"], None]))
def test_a_recording_whose_joint_states_are_garbled_is_judged_or_refused_in_one_line(
    cli: Cli, files: Files, data: st.DataObject, layout: Layout, flags: tuple[str, ...], inspect: bool,
    as_json: bool, topics: list[str] | None
) -> None:
    with scratch_folder() as scratch:
        recording = scratch / "recording.mcap"
        recording.write_bytes(write_mcap(data.draw(garbled_content(files.executed_content, topics)), layout))
        use_recording(in_process(cli), recording, files.plan, flags, inspect, as_json)


DB3_DAMAGE = [
    "UPDATE messages SET timestamp = {value} WHERE id = {row}",
    "UPDATE messages SET data = {blob} WHERE id = {row}",
    "UPDATE messages SET data = substr(data, 1, {small}) WHERE id = {row}",
    "UPDATE messages SET topic_id = {value} WHERE id = {row}",
    "DELETE FROM messages WHERE id = {row}",
    "INSERT INTO messages (timestamp, topic_id, data) SELECT timestamp, topic_id, data FROM messages WHERE id = {row}",
    "UPDATE topics SET type = {text}",
    "UPDATE topics SET name = {text}",
    "UPDATE topics SET serialization_format = {text}",
    "UPDATE topics SET offered_qos_profiles = {text}",
    "UPDATE topics SET id = {value}",
    "UPDATE messages SET id = {value} WHERE id = {row}",
    "DELETE FROM topics",
    "INSERT INTO topics (name, type, serialization_format, offered_qos_profiles) "
    "SELECT name, type, serialization_format, offered_qos_profiles FROM topics",
    "UPDATE schema SET schema_version = {value}",
    "DROP TABLE schema",
    "DROP INDEX timestamp_idx",
    "DELETE FROM messages",
]
LOOSE_TABLES = "".join(
    f"ALTER TABLE {table} RENAME TO old_{table}; CREATE TABLE {table}({columns}); "
    f"INSERT INTO {table} SELECT * FROM old_{table}; DROP TABLE old_{table};"
    for table, columns in (("schema", "schema_version, ros_distro"), ("messages", "id, topic_id, timestamp, data"),
                           ("topics", "id, name, type, serialization_format, offered_qos_profiles")))
"""SQL rebuilding a rosbag2 sqlite3 file's tables with columns of no type, key or constraint."""
SQL_VALUES = ["NULL", "0", "-1", "9223372036854775807", "-9223372036854775808", "1e300", "'nan'", "'x'", "x''",
              "1.5", "timestamp * 2", "-timestamp"]
SQL_TEXTS = ["NULL", "''", "'x'", "'sensor_msgs/msg/JointState'", "'std_msgs/msg/String'", "x'00ff'", "1",
             "'/joint_states'", "'cdr'", "'- {history: [}'", "'/j' || char(27) || '[2J'", "'a' || char(13) || 'b'"]


@st.composite
def damaged_db3_sql(draw: st.DrawFn) -> list[str]:
    """One to three SQL statements damaging a rosbag2 sqlite3 file's rows as no rosbag2 writes them."""
    statements = []
    for _ in range(draw(st.integers(1, 3))):
        template = draw(st.sampled_from(DB3_DAMAGE))
        blob = draw(st.binary(max_size=48))
        statements.append(template.format(
            value=draw(st.sampled_from(SQL_VALUES)), row=draw(st.integers(1, 600)),
            blob=draw(st.sampled_from([f"x'{blob.hex()}'", "NULL", "'text'", "zeroblob(100000)", "1.5"])),
            small=draw(st.integers(0, 40)), text=draw(st.sampled_from(SQL_TEXTS))))
    return statements


@fuzz(50)
@given(data=st.data(), flags=CHECK_FLAGS, inspect=st.booleans(), as_json=st.booleans(),
       level=st.sampled_from(["rows", "rows", "bytes", "folder"]))
def test_a_damaged_db3_recording_or_bag_folder_is_judged_or_refused_in_one_line(
    cli: Cli, files: Files, data: st.DataObject, flags: tuple[str, ...], inspect: bool, as_json: bool, level: str
) -> None:
    with scratch_folder() as scratch:
        bag = scratch / "run"
        bag.mkdir()
        recording = bag / "run_0.db3"
        shutil.copy(files.db3, recording)
        if level == "rows":
            connection = sqlite3.connect(recording)
            if data.draw(st.booleans()):  # columns without types or keys: any value goes into any of them
                connection.executescript(LOOSE_TABLES)
            for statement in data.draw(damaged_db3_sql()):
                with contextlib.suppress(sqlite3.Error):  # a constraint refusing the damage: that part stays intact
                    connection.execute(statement)
            connection.commit()
            connection.close()
        elif level == "bytes":
            recording.write_bytes(data.draw(damaged_bytes(recording.read_bytes())).data)
        else:
            metadata = yaml.safe_load((Path(__file__).parents[1] / "data" / "db3" / "metadata.yaml").read_text())
            information = metadata["rosbag2_bagfile_information"]
            information["relative_file_paths"] = ["run_0.db3"]
            information["files"] = information["files"][:1]
            information["files"][0]["path"] = "run_0.db3"
            (bag / "metadata.yaml").write_text(dump(data.draw(spoiled(metadata))))
            recording = bag
        use_recording(in_process(cli), recording, files.plan, flags, inspect, as_json)


# ------------------------------------------------------------------------------------------- config YAML

def ur10e_request() -> dict[str, Any]:
    """A MoveIt MotionPlanRequest for the ur10e: from START to a joint goal."""
    return {
        "start_state": {"joint_state": {"name": list(JOINTS), "position": [float(v) for v in START.split(",")]}},
        "goal_constraints": [{"name": "", "joint_constraints": [
            {"joint_name": name, "position": value, "tolerance_above": 0.001, "tolerance_below": 0.001,
             "weight": 1.0} for name, value in zip(JOINTS, [0.0, -1.5708, -1.5708, 0.0, 0.0, 0.0], strict=True)],
            "position_constraints": [], "orientation_constraints": []}],
        "group_name": "manipulator", "planner_id": "RRTConnect", "num_planning_attempts": 1,
        "allowed_planning_time": 0.05, "max_velocity_scaling_factor": 0.1, "max_acceleration_scaling_factor": 0.1,
    }


def ur10e_task() -> dict[str, Any]:
    """A two-step task of the ur10e in the workshop scene, robot and scene named by absolute paths."""
    task = yaml.safe_load((SAMPLES / "ur10e_pick_and_place.yaml").read_text())
    task["robot"] = str(UR10E)
    task["scene"] = str(SAMPLES / "ur10e_workshop_scene.yaml")
    task["steps"] = task["steps"][:1] + task["steps"][-1:]
    return task


CONTROLLER_FILES = [UR10E / "ros2_controllers.yaml", SAMPLES / "ur10e_mistuned_controllers.yaml",
                    SAMPLES / "ur10e_velocity_controllers.yaml", RECORDINGS / "ur10e_goal_time_controllers.yaml"]


@fuzz(30)
@given(data=st.data(), source=st.sampled_from(CONTROLLER_FILES), execute=st.booleans(), as_json=st.booleans())
def test_spoiled_controller_values_execute_or_are_refused_in_one_line(
    cli: Cli, files: Files, data: st.DataObject, source: Path, execute: bool, as_json: bool
) -> None:
    flags = ["--json"] if as_json else []
    invoke = in_process(cli)
    with scratch_folder() as scratch:
        controllers = scratch / "controllers.yaml"
        controllers.write_text(dump(data.draw(st.one_of(spoiled(yaml.safe_load(source.read_text())), DOCUMENTS))))
        if execute:
            out = scratch / "e.mcap"
            outcome = invoke("execute", files.plan, "--fake", "--controllers", controllers, "-o", out, *flags)
            assert_clean(outcome, {0, 3, 5})
            assert out.exists() == (outcome.code in (0, 5))
        else:
            assert_clean(invoke("check-tolerances", files.plan, files.executed, "--controllers", controllers, *flags),
                         {0, 3, 5})


CONFIG_FILES = ["joint_limits.yaml", "initial_positions.yaml", "moveit_controllers.yaml", "moveplan.yaml",
                "ros2_controllers.yaml"]


@fuzz(40)
@given(data=st.data(), name=st.sampled_from(CONFIG_FILES), command=st.sampled_from(["robot", "state", "plan"]),
       as_json=st.booleans())
def test_a_robot_config_with_spoiled_yaml_loads_or_is_refused_in_one_line(
    cli: Cli, data: st.DataObject, name: str, command: str, as_json: bool
) -> None:
    flags = ["--json"] if as_json else []
    invoke = in_process(cli)
    document = yaml.safe_load((UR10E / name).read_text())
    with scratch_folder() as scratch:
        config = scratch / "ur10e"
        shutil.copytree(UR10E, config)
        (config / name).write_text(dump(data.draw(st.one_of(spoiled(document), spoiled(document), DOCUMENTS))))
        if command == "robot":
            assert_clean(invoke("robot", config, *flags), {0, 3})
        elif command == "state":
            assert_clean(invoke("state", "--robot", config, "--named", "home", *flags), {0, 3})
        else:
            out = scratch / "p.mcap"
            outcome = invoke("plan", "--robot", config, "--named", "home", "--start-joints", START,
                             "--planning-time", "0.05", "-o", out, *flags)
            assert_clean(outcome, {0, 3, 4})
            assert out.exists() == (outcome.code == 0)


@fuzz(40)
@given(data=st.data(), kind=st.sampled_from(["task", "request", "scene", "state-scene"]), as_json=st.booleans())
def test_a_spoiled_task_scene_or_request_plans_or_is_refused_in_one_line(
    cli: Cli, data: st.DataObject, kind: str, as_json: bool
) -> None:
    flags = ["--json"] if as_json else []
    invoke = in_process(cli)
    if kind in ("task", "request"):
        intact = ur10e_task() if kind == "task" else ur10e_request()
    else:
        source = data.draw(st.sampled_from([SAMPLES / "ur10e_workshop_scene.yaml", SAMPLES / "ur10e_table_scene.yaml"]))
        intact = yaml.safe_load(source.read_text())
    document = data.draw(st.one_of(spoiled(intact), spoiled(intact), DOCUMENTS))
    with scratch_folder() as scratch:
        out, path = scratch / "p.mcap", scratch / f"{kind}.yaml"
        path.write_text(dump(document))
        if kind == "state-scene":
            frame = data.draw(st.sampled_from(["base_link", "target_1", "object", "table"]))
            assert_clean(invoke("state", "--robot", "ur10e", "--scene", path, "--named", "home", "--frame", frame,
                                *flags), {0, 3})
            return
        if kind == "task":
            outcome = invoke("plan", path, "--planning-time", "0.05", "-o", out, *flags)
        elif kind == "request":
            outcome = invoke("plan", "--robot", "ur10e", "--request", path, "--planning-time", "0.05", "-o", out,
                             *flags)
        else:
            outcome = invoke("plan", "--robot", "ur10e", "--scene", path, "--named", "home", "--start-joints", START,
                             "--planning-time", "0.05", "-o", out, *flags)
        # A task without steps, or a request without goal constraints, names no goal: a usage error (2).
        assert_clean(outcome, {0, 2, 3, 4} if kind in ("task", "request") else {0, 3, 4})
        assert out.exists() == (outcome.code == 0)


# ------------------------------------------------------------------------------------------- bounded processes

HUGE = st.sampled_from([(1 << 31) - 1, 1 << 31, (1 << 32) - 1, 1 << 40, (1 << 63) - 1, (1 << 64) - 1])


@st.composite
def huge_field(draw: st.DrawFn, source: bytes) -> Damaged:
    """`source` (an MCAP file written plain) with eight bytes of one record's content set to a huge size."""
    record = draw(st.sampled_from([r for r in mcap_records(source) if r.length >= 8]))
    offset = draw(st.integers(0, record.length - 8))
    result = bytearray(source)
    value = draw(HUGE)
    result[record.at + 9 + offset : record.at + 17 + offset] = pack_int(value, 8)
    return Damaged(bytes(result), (f"u64 at content byte {offset} of the record at {record.at} (opcode "
                                   f"{record.opcode}) set to {value}",))


@fuzz(3)
@given(data=st.data())
def test_a_plan_or_recording_declaring_huge_sizes_stays_within_time_and_memory(files: Files, data: st.DataObject
                                                                                ) -> None:
    with scratch_folder() as scratch:
        plan, recording = scratch / "plan.mcap", scratch / "recording.mcap"
        plan.write_bytes(data.draw(huge_field(files.plain_plan)).data)
        recording.write_bytes(data.draw(huge_field(files.plain_executed)).data)
        use_plan(as_process, plan, data.draw(st.sampled_from(["inspect", "execute"])), files, False)
        use_recording(as_process, recording, files.plan, (), False, False)


def test_a_chunk_declaring_2_64_bytes_of_records_is_refused_within_time_and_memory(files: Files) -> None:
    with scratch_folder() as scratch:
        plan = scratch / "plan.mcap"
        damaged = bytearray(files.plain_plan)
        chunk = next(record for record in mcap_records(files.plain_plan) if record.opcode == CHUNK)
        damaged[chunk.at + 9 + 16 : chunk.at + 9 + 24] = pack_int((1 << 64) - 1, 8)  # its uncompressed_size
        plan.write_bytes(bytes(damaged))
        for command in ("inspect", "execute", "state"):
            use_plan(as_process, plan, command, files, False)


# ------------------------------------------------------------------------------------------- regressions

def with_log_time(content: McapContent, topic: str, index: int, log_time: int) -> McapContent:
    """`content` with the `index`-th message on `topic` logged (and published) at `log_time`."""
    result = McapContent(content.profile, content.library, list(content.items))
    topics = {item.id: item.topic for item in content.items if isinstance(item, Channel)}
    at = [i for i, item in enumerate(result.items) if isinstance(item, Message) and topics[item.channel_id] == topic]
    result.items[at[index]] = replace(result.items[at[index]], log_time=log_time, publish_time=log_time)
    return result


@pytest.mark.parametrize("chunked", [False, True])
@pytest.mark.parametrize("flags", [(), ("--time-source", "log"), ("--start", "all")])
def test_a_joint_state_logged_at_the_largest_mcap_time_is_judged_or_refused_in_one_line(
    cli: Cli, files: Files, chunked: bool, flags: tuple[str, ...]
) -> None:
    # Found by the fuzzer: a log time of 2**64 - 1 (a u64 in MCAP) in a file read by the linear scan
    # overflowed an int64 array in core/bag/container/topic_reader.py (an internal error).
    content = with_log_time(files.executed_content, "/joint_states", 12, (1 << 64) - 1)
    with scratch_folder() as scratch:
        recording = scratch / "recording.mcap"
        recording.write_bytes(write_mcap(content, Layout(chunk_size=2048, chunked=chunked, crcs=False)))
        assert_clean(in_process(cli)("check-tolerances", files.plan, recording, *flags), {0, 3, 5})
        assert_clean(in_process(cli)("inspect", recording), {0, 3})


def test_a_record_length_of_4_gib_in_a_plan_is_refused_without_reading_4_gib(cli: Cli, files: Files) -> None:
    # Found by the fuzzer: the mcap package read a record's padding with stream.read(length), and a
    # BufferedReader allocates `length` bytes first: 4 GiB for the Header's length set to 2**32 - 1
    # (a MemoryError under the memory limit). core/bag clamps those reads to the file's size.
    header = next(record for record in mcap_records(files.plan_bytes) if record.opcode == 1)
    for length in ((1 << 32) - 1, 1 << 40, (1 << 64) - 1):
        damaged = bytearray(files.plan_bytes)
        damaged[header.at + 1 : header.at + 9] = pack_int(length, 8)
        with scratch_folder() as scratch:
            plan = scratch / "plan.mcap"
            plan.write_bytes(bytes(damaged))
            for command in PLAN_COMMANDS:
                use_plan(in_process(cli), plan, command, files, False)


@pytest.mark.parametrize("name", ["", "std_msgs/msg/String", "a" * 300])
@pytest.mark.parametrize("text", [b"", b"MSG: x/Y\nint8 a", b"string data\n===\n", b"\xff\xfe"])
def test_a_plan_whose_own_topic_has_an_unparsable_schema_is_refused_in_one_line(
    cli: Cli, files: Files, name: str, text: bytes
) -> None:
    # Found by the fuzzer: the /robot_description schema named '' (or text no ros2msg parser
    # takes) raised mcap_ros2's InvalidResourceName out of core/bag/plan_file.py (an internal error).
    content = McapContent(files.plan_content.profile, files.plan_content.library, list(files.plan_content.items))
    for index, item in enumerate(content.items):
        if isinstance(item, Schema) and item.name in ("std_msgs/msg/String", "trajectory_msgs/msg/JointTrajectory"):
            content.items[index] = replace(item, name=name, data=text)
    with scratch_folder() as scratch:
        plan = scratch / "plan.mcap"
        plan.write_bytes(write_mcap(content, Layout()))
        for command in PLAN_COMMANDS:
            use_plan(in_process(cli), plan, command, files, False)
        assert in_process(cli)("inspect", plan).code == 3


DROP = object()
"""A limit's value that stands for the key dropped."""


@pytest.mark.parametrize("joint_limits", [
    {"max_velocity": math.nan}, {"max_velocity": "2.0"}, {"max_acceleration": 0}, {"max_acceleration": math.inf},
    {"lower": 1.0, "upper": -1.0}, {"upper": math.nan}, {"max_velocity": True}, {"max_velocity": None},
    {"max_acceleration": DROP}, {"max_velocity": DROP},
])
def test_a_plan_whose_recorded_limits_are_no_limits_is_refused_in_one_line(
    cli: Cli, files: Files, joint_limits: dict[str, Any]
) -> None:
    # Found by the fuzzer: the "moveplan" metadata's limits were taken as float(value), NaN and "2.0"
    # alike, and a joint's max_acceleration dropped made inspect fail (a KeyError; then NaN in its JSON).
    content = McapContent(files.plan_content.profile, files.plan_content.library, list(files.plan_content.items))
    index = next(i for i, item in enumerate(content.items) if isinstance(item, Metadata) and item.name == "moveplan")
    limits = json.loads(content.items[index].metadata["limits"])
    limits["elbow_joint"].update(joint_limits)
    limits["elbow_joint"] = {key: value for key, value in limits["elbow_joint"].items() if value is not DROP}
    metadata = {**content.items[index].metadata, "limits": json.dumps(limits)}
    content.items[index] = replace(content.items[index], metadata=metadata)
    with scratch_folder() as scratch:
        plan = scratch / "plan.mcap"
        plan.write_bytes(write_mcap(content, Layout()))
        for command in PLAN_COMMANDS:
            outcome = in_process(cli)(*{"inspect": ["inspect", plan], "state": ["state", "--from", plan],
                                        "execute": ["execute", plan, "--fake", "-o", scratch / "e.mcap"],
                                        "check-tolerances": ["check-tolerances", plan, files.executed]}[command])
            assert_clean(outcome, {3})
            assert "limits of joint elbow_joint" in outcome.stderr


@pytest.mark.parametrize("length", [1 << 63, (1 << 64) - 1])
def test_a_record_of_unknown_kind_in_a_chunk_with_a_length_beyond_2_63_is_refused_in_one_line(
    cli: Cli, files: Files, length: int
) -> None:
    # Found by fuzzing (a peer's fuzzer first, /tmp/fuzz_repro/plan_inner_record_length): inside an
    # uncompressed chunk, the mcap package skips a record of unknown opcode with BytesIO.read(length),
    # which raises OverflowError for a length of 2**63 or more (an internal error).
    inner = next(record for record in mcap_records(files.plain_plan) if record.inner)
    damaged = bytearray(files.plain_plan)
    damaged[inner.at : inner.at + 9] = bytes([0x80]) + pack_int(length, 8)
    with scratch_folder() as scratch:
        plan = scratch / "plan.mcap"
        plan.write_bytes(bytes(damaged))
        for command in PLAN_COMMANDS:
            use_plan(in_process(cli), plan, command, files, False)


@pytest.mark.parametrize("damage", [
    "UPDATE topics SET id = NULL", "UPDATE topics SET id = 'x'", "UPDATE topics SET id = 1.5",
    "UPDATE messages SET id = 'x' WHERE id = 7", "UPDATE messages SET id = x'00' WHERE id = 7",
    "UPDATE schema SET schema_version = 'nan'",
])
def test_a_db3_recording_with_ids_that_are_no_integers_is_refused_in_one_line(
    cli: Cli, files: Files, damage: str
) -> None:
    # Found by the fuzzer: in tables declared without types (any value in any column), a topic id
    # of NULL raised TypeError from int() in core/bag/container/_db3.py (an internal error); text ids too.
    with scratch_folder() as scratch:
        recording = scratch / "run.db3"
        shutil.copy(files.db3, recording)
        connection = sqlite3.connect(recording)
        connection.executescript(LOOSE_TABLES)
        connection.execute(damage)
        connection.commit()
        connection.close()
        use_recording(in_process(cli), recording, files.plan, (), inspect=False, as_json=False)
        use_recording(in_process(cli), recording, files.plan, (), inspect=True, as_json=True)


def with_payload_replaced(content: McapContent, topic: str, old: bytes, new: bytes) -> McapContent:
    """`content` with `old` replaced by `new` (as long) in the payload of every message on `topic`."""
    result = McapContent(content.profile, content.library, list(content.items))
    topics = {item.id: item.topic for item in content.items if isinstance(item, Channel)}
    for index, item in enumerate(result.items):
        if isinstance(item, Message) and topics[item.channel_id] == topic:
            result.items[index] = replace(item, data=item.data.replace(old, new))
    return result


@pytest.mark.parametrize(("old", "new"), [
    (b"shoulder_pan_joint", b"\x00\x00\x00ulder_pan_joint"), (b"elbow_joint", b"elbow_join\x1b"),
    (b"wrist_2_joint", b"wrist_1_joint"),
])
def test_a_plan_whose_joint_names_are_garbled_is_refused_in_one_line(
    cli: Cli, files: Files, old: bytes, new: bytes
) -> None:
    # Found by the fuzzer: a string length of 0 in a JointTrajectory left NULs in a joint name, which
    # then reached an error message raw (and core/pipeline/inspection.py as a key it lacks).
    content = with_payload_replaced(files.plan_content, "/planned_trajectory", old, new)
    with scratch_folder() as scratch:
        plan = scratch / "plan.mcap"
        plan.write_bytes(write_mcap(content, Layout()))
        for command in PLAN_COMMANDS:
            use_plan(in_process(cli), plan, command, files, False)
        outcome = in_process(cli)("inspect", plan)
        assert outcome.code == 3 and "joint" in outcome.stderr, outcome


@pytest.mark.parametrize("length", [0, 1, 20, 39])
@pytest.mark.parametrize("summary", [True, False])
@pytest.mark.parametrize("flags", [(), ("--skip-damaged",)])
def test_a_chunk_too_short_for_its_header_is_damage_skipped_or_refused_in_one_line(
    cli: Cli, files: Files, length: int, summary: bool, flags: tuple[str, ...]
) -> None:
    # Found by the fuzzer: a chunk record's length set below the 40 bytes of a chunk's header made
    # core/bag/container/_mcap_linear.py unpack past it (struct.error: an internal error of check-tolerances
    # --skip-damaged in a file without a summary) and inspect refuse the file with struct's message.
    for source in (files.executed_bytes, files.plain_executed):
        chunk = next(record for record in mcap_records(source) if record.opcode == CHUNK)
        damaged = bytearray(source)
        damaged[chunk.at + 1 : chunk.at + 9] = pack_int(length, 8)
        with scratch_folder() as scratch:
            recording = scratch / "recording.mcap"
            recording.write_bytes(bytes(damaged if summary else damaged[:-30]))  # no footer: a linear scan
            use_recording(in_process(cli), recording, files.plan, flags, inspect=False, as_json=False)
            use_recording(in_process(cli), recording, files.plan, flags, inspect=True, as_json=False)
            outcome = in_process(cli)("inspect", recording, *flags)
            assert "unpack" not in outcome.stderr, outcome
