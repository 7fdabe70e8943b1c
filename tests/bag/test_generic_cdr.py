"""The schema-driven CDR encoder, checked byte for byte against mcap_ros2's on every shipped type."""

from __future__ import annotations

import copy
from importlib.resources import files
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from reference_cdr import reference_cdr, schema

from moveplan.core.bag.cdr.definitions import Field, parse_definitions
from moveplan.core.bag.cdr.generic import encoder

SHIPPED = sorted(
    (distro.name, entry.name.removesuffix(".msg").replace("__", "/"))
    for distro in files("moveplan.core.bag.cdr.msgs").iterdir()
    if distro.is_dir() and distro.name.isalpha()
    for entry in distro.iterdir()
    if entry.name.endswith(".msg")
)
NAMES = ("", "a", "jo", "joi", "join", "joint", "joint_", "joint_1", "joint_12", "ünïcödé")
INTS = {
    "byte": (0, 255), "char": (0, 127), "int8": (-128, 127), "uint8": (0, 255), "int16": (-(2**15), 2**15 - 1),
    "uint16": (0, 2**16 - 1), "int32": (-(2**31), 2**31 - 1), "uint32": (0, 2**32 - 1),
    "int64": (-(2**63), 2**63 - 1), "uint64": (0, 2**64 - 1),
}
# Every primitive, arrays fixed, bounded and unbounded, defaults, constants, nested and empty messages.
TEST_SCHEMA = """# A message made to reach every path of the encoder
int32 KIND=3
string NAME="not a field"
bool flag true
byte b 7
char c 65
int8 i8 -3
uint8 u8
int16 i16 -300
uint16 u16 300
int32 i32
uint32 u32 42
int64 i64 -5
uint64 u64 5
float32 f32 1.5
float64 f64 -2.25  # a comment
string text "hello world"
string<=5 short_text
float64[3] fixed
float64[<=2] bounded
uint8[4] fixed_bytes
uint8[] byte_sequence
byte[<=3] bounded_bytes
string[2] two_names
string[] names
bool[] flags
int16[] shorts
Inner[2] inners
Inner[<=1] at_most_one
Inner[] many
Inner one
Nothing nothing
================================================================================
MSG: test_msgs/Inner
float64 x 1
Deep deep
Nothing[] nothings
================================================================================
MSG: test_msgs/Deep
int32 v 9
uint8 tail
================================================================================
MSG: test_msgs/Nothing
"""
TEST_TYPE = "test_msgs/msg/Test"


def random_value(definitions: dict[str, tuple[Field, ...]], field: Field, rng: np.random.Generator) -> Any:
    """A random value for `field`, arrays of random length around their size or bound."""
    if not field.array:
        return random_scalar(definitions, field.type, rng)
    length = int(rng.integers(0, (field.size or 3) + 3))
    values = [random_scalar(definitions, field.type, rng) for _ in range(length)]
    if field.type in ("uint8", "byte") and rng.random() < 0.5:
        return bytes(values)
    if field.primitive and rng.random() < 0.3:
        return tuple(values)
    return values


def random_scalar(definitions: dict[str, tuple[Field, ...]], type_name: str, rng: np.random.Generator) -> Any:
    if type_name in ("float32", "float64"):
        return float(rng.normal())
    if type_name in INTS:
        low, high = INTS[type_name]
        return int(rng.integers(low, high, endpoint=True, dtype=np.uint64 if low == 0 else np.int64))
    if type_name == "bool":
        return bool(rng.random() < 0.5)
    if type_name == "string":
        return str(rng.choice(NAMES))
    return random_message(definitions, type_name, rng)


def random_message(definitions: dict[str, tuple[Field, ...]], msgtype: str, rng: np.random.Generator) -> Any:
    """A random `msgtype`: some fields left out or None, as a dict or an object with attributes."""
    message = {}
    for field in definitions[msgtype]:
        draw = rng.random()
        if draw < 0.15:
            continue  # left out: the encoder writes its default
        message[field.name] = None if draw < 0.2 else random_value(definitions, field, rng)
    return SimpleNamespace(**message) if rng.random() < 0.2 else message


@pytest.mark.parametrize(("distro", "msgtype"), SHIPPED)
def test_every_shipped_type_encodes_as_mcap_ros2_encodes_it(distro: str, msgtype: str) -> None:
    text = schema(msgtype, distro)
    definitions = parse_definitions(msgtype, text)
    rng = np.random.default_rng(len(text))
    messages = [{}, *(random_message(definitions, msgtype, rng) for _ in range(30))]
    encoded = [encoder(msgtype, text.encode())(message) for message in messages]
    assert encoded == reference_cdr(msgtype, distro, copy.deepcopy(messages))


@pytest.mark.parametrize("seed", range(20))
def test_arrays_defaults_and_empty_messages_encode_as_mcap_ros2_encodes_them(seed: int) -> None:
    definitions = parse_definitions(TEST_TYPE, TEST_SCHEMA)
    rng = np.random.default_rng(seed)
    messages = [{}, None, *(random_message(definitions, TEST_TYPE, rng) for _ in range(20))]
    encoded = [encoder(TEST_TYPE, TEST_SCHEMA.encode())(message) for message in messages]
    # mcap_ros2 pads short fixed-size arrays of messages in place: give it copies.
    assert encoded == reference_cdr(TEST_TYPE, "jazzy", copy.deepcopy(messages), text=TEST_SCHEMA)


def test_definitions_are_found_by_both_names_with_defaults_and_without_constants() -> None:
    definitions = parse_definitions(TEST_TYPE, TEST_SCHEMA)
    assert definitions[TEST_TYPE] is definitions["test_msgs/Test"]
    assert definitions["test_msgs/Nothing"] == ()
    fields = {field.name: field for field in definitions[TEST_TYPE]}
    assert "KIND" not in fields and "NAME" not in fields
    assert (fields["flag"].default, fields["f64"].default, fields["text"].default) == (True, -2.25, "hello world")
    assert (fields["fixed"].fixed, fields["bounded"].fixed, fields["bounded"].size) == (True, False, 2)
    assert fields["one"].type == "test_msgs/Inner" and fields["short_text"].type == "string"
    quaternion = parse_definitions("geometry_msgs/msg/Quaternion", "float64 x 0\nfloat64 w 1\n")
    assert [field.default for field in quaternion["geometry_msgs/Quaternion"]] == [0.0, 1.0]


@pytest.mark.parametrize(
    ("message", "match"),
    [
        ({"many": ({},)}, "'many' has type test_msgs/Inner.. but was given a tuple"),
        ({"names": np.zeros(2)}, "'names' has type string.. but was given a ndarray"),
        ({"shorts": b"\x00\x01"}, "'shorts' has type int16.. but was given bytes"),
    ],
)
def test_a_value_that_is_not_the_fields_array_kind_raises_value_error(message: dict[str, Any], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        encoder(TEST_TYPE, TEST_SCHEMA.encode())(message)


def test_a_field_type_the_schema_does_not_define_raises_value_error() -> None:
    with pytest.raises(ValueError, match="no definition of 'test_msgs/Missing'"):
        encoder("test_msgs/msg/Broken", b"Missing field\n")
