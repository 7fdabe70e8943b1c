"""The plain YAML reader gives what PyYAML gives, or leaves the text to PyYAML: a file reads the same either way.

core/config/_plain_yaml.py reads scenes, requests and configs written in YAML's plain part
~3x faster than PyYAML. A user must never see the difference: every value, type, key order and
float bit is PyYAML's, and every error is PyYAML's (the reader only sees text libyaml parsed).
"""

from __future__ import annotations

import math
import random
from pathlib import Path
from typing import Any

import pytest
import yaml
from conftest import NOETIC, REALWORLD, ROOT
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from moveplan.core.config import fields, load_yaml
from moveplan.core.config._plain_yaml import DECLINED, read_plain
from moveplan.core.errors import ConfigError

# Scalars PyYAML reads as something else than their text (YAML 1.1 booleans, octal, sexagesimal,
# ROS's exponent floats, nulls, timestamps) beside names, numbers and plain words.
TRICKY = ["yes", "No", "ON", "off", "y", "n", "true", "False", "null", "~", "Null", "012", "0x1F", "0b101", "1_000",
          "1e3", "1.0e-3", "-1E+2", ".inf", "-.Inf", ".NaN", "1:30", "2002-12-14", "2001-12-14t21:59:43.10-05:00",
          "-0", "+0", "-0.0", "+.5", "1.", "0.", "=", "-", "- a", "a b", "a  b", "panda_link0", "/tf", "./x", "+",
          "(x)", "$HOME", "^", "a;b", "a,b", "a:b", "a: b", "#c", "a #c", "a#b", "", " ", "'q'", '"q"', "it's",
          "-1", "-1.5", "1.5", "0", "100", "3.141592653589793", "-2.356", "1e9", "x-y", "-x", ".", "..", "~x"]
SCALARS = st.one_of(
    st.sampled_from(TRICKY), st.integers(-10**6, 10**6), st.booleans(), st.none(),
    st.floats(allow_nan=False, allow_infinity=False, width=64),
    st.text(alphabet="abcxyz_019.-/ :#'\"[]{},", max_size=6))
KEYS = st.one_of(st.sampled_from(["a", "b", "name", "id", "position", "1", "true", "yes", "null", "~", "x.y", "/**"]),
                 st.text(alphabet="abz_1.-/", min_size=1, max_size=5))
TREES = st.recursive(SCALARS, lambda inner: st.one_of(st.lists(inner, max_size=4),
                                                       st.dictionaries(KEYS, inner, max_size=4)), max_leaves=18)


def same(a: Any, b: Any) -> bool:
    """Return whether two parsed documents are equal in value, type, key order and float bits."""
    if type(a) is not type(b):
        return False
    if isinstance(a, dict):
        return list(a) == list(b) and all(same(k, j) for k, j in zip(a, b, strict=True)) and all(
            same(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float):
        return (math.isnan(a) and math.isnan(b)) or (a == b and math.copysign(1, a) == math.copysign(1, b))
    return bool(a == b)


def pyyaml(text: str, merge: bool = False) -> Any:
    """Return what PyYAML alone reads (the loaders moveplan gives it)."""
    return yaml.load(text, Loader=fields._MergingLoader if merge else fields._Loader)  # noqa: S506 - safe loaders


def agrees(text: str, merge: bool = False) -> Any:
    """Assert the line reader declines `text` or reads it as PyYAML does; return its reading."""
    try:
        expected = pyyaml(text, merge)
    except yaml.YAMLError:
        return DECLINED  # parse_yaml reports PyYAML's error before the reader sees the text
    got = read_plain(text, fields._Loader, fields._merged if merge else None)
    assert got is DECLINED or same(got, expected), (text, got, expected)
    return got


def emit(value: Any, rng: random.Random, indent: int = 0, step: int = 2) -> list[str]:
    """Return block YAML lines for `value` in a style drawn from `rng`: flows, compact and indentless entries."""
    pad = " " * indent
    if isinstance(value, dict) and value and rng.random() < 0.8:
        lines = []
        for key, item in value.items():
            head = f"{pad}{flow(key)}:"
            if isinstance(item, list) and item and rng.random() < 0.5:
                same_indent = rng.random() < 0.4  # a sequence at its key's indent
                lines += [head, *emit(item, rng, indent if same_indent else indent + step, step)]
            elif isinstance(item, dict | list) and item and rng.random() < 0.7:
                lines += [head, *emit(item, rng, indent + step, step)]
            else:
                lines.append(f"{head} {flow(item)}" + (" # note" if rng.random() < 0.1 else ""))
        return lines
    if isinstance(value, list) and value and rng.random() < 0.8:
        lines = []
        for item in value:
            if isinstance(item, dict | list) and item and rng.random() < 0.7:
                nested = emit(item, rng, indent + step, step)
                lines.append(f"{pad}- {nested[0].lstrip(' ')}")  # compact: the first line on the entry's
                lines += nested[1:]
            else:
                lines.append(f"{pad}- {flow(item)}")
        return lines
    return [f"{pad}{flow(value)}"]


def flow(value: Any) -> str:
    """Return `value` written in flow style on one line, as yaml.safe_dump writes it (quotes where needed)."""
    return yaml.safe_dump(value, default_flow_style=True, width=10**6).removesuffix("\n...\n").removesuffix("\n")


@settings(max_examples=600, deadline=None, database=None)
@given(TREES, st.integers(0, 2**32 - 1))
def test_documents_written_in_any_style_read_as_pyyaml_reads_them(tree: Any, seed: int) -> None:
    rng = random.Random(seed)
    agrees("\n".join(emit(tree, rng, step=rng.choice([2, 4]))) + "\n")
    agrees(yaml.safe_dump(tree, default_flow_style=rng.choice([False, None, True]), sort_keys=False))
    agrees(yaml.safe_dump({"a": tree, "b": [tree, tree]}, sort_keys=False), merge=True)


EDITS = "\n -:#,[]{}'\"abc1.~"


@settings(max_examples=1500, deadline=None, database=None, suppress_health_check=[HealthCheck.too_slow])
@given(TREES, st.integers(0, 2**32 - 1), st.lists(st.tuples(st.integers(0, 10**4), st.sampled_from(EDITS),
                                                              st.sampled_from(["insert", "delete", "replace"])),
                                                    min_size=1, max_size=4))
def test_edited_documents_are_read_as_pyyaml_reads_them_or_left_to_it(tree: Any, seed: int, edits: list[Any]) -> None:
    text = "\n".join(emit(tree, random.Random(seed))) + "\n"
    for at, character, edit in edits:
        at %= len(text) + 1
        if edit == "insert":
            text = text[:at] + character + text[at:]
        elif edit == "delete":
            text = text[:at] + text[at + 1:]
        else:
            text = text[:at] + character + text[at + 1:]
    agrees(text)
    agrees(text, merge=True)


@pytest.mark.parametrize("text", [
    "a: 1\na: 2\n",                              # the later of a repeated key wins
    "1: a\ntrue: b\n",                           # keys resolve as values do
    "a:\n- x\n- y\nb: 1\n",                      # a sequence at its key's indent
    "- a: 1\n  b: [1, 2]\n- - x\n  - y\n-\n",    # compact entries, an empty one
    "a: [ 1 , x y , -2.5e3, 012, .inf ]\n",      # spaces in a flow list, an octal, an exponent, infinity
    "a: {b: [1, {c: d}], e: ''}\nf: \"g h\"\n",  # nested flows, quoted scalars
    "  a: 1\n  b:\n    c: 2\n",                   # a document indented as a whole
    "# only a comment\n\n",                      # an empty document: None
    "a: 1 # a comment\nb: x # another\n",
    "[1, 2]", "plain", "a: 2001-12-14\n",
])
def test_plain_documents_are_read_on_the_fast_path_as_pyyaml_reads_them(text: str) -> None:
    got = read_plain(text, fields._Loader)
    assert got is not DECLINED
    assert same(got, pyyaml(text))


@pytest.mark.parametrize("text", [
    "a: &x 1\nb: *x\n", "a: !!str 1\n", "a: |\n  text\n", "a: >\n  text\n", "a: 'it''s'\n", 'a: "tab\\t"\n',
    "a: b\n  c\n", "a: [1,\n  2]\n", "---\na: 1\n", "a:\tb\n", "a: 1\r\n", "a: é\n", "<<: {b: 1}\n", "? a\n: b\n",
    "a: 'x' # c\n", "a: x#y\n", "a: b:c\n", "a: [b: c]\n", "a: [1, 2,]\n", "a: -\n",
])
def test_text_outside_the_plain_part_is_left_to_pyyaml(text: str) -> None:
    assert read_plain(text, fields._Loader) is DECLINED
    assert agrees(text) is DECLINED


@pytest.mark.parametrize("text", [
    "".join(" " * k + "k:\n" for k in range(600)) + " " * 600 + "k: 1\n",  # past Python's recursion limit
    "a: " + "[" * 990 + "]" * 990 + "\n",                                   # just inside libyaml's nesting limit
])
def test_deeply_nested_documents_read_as_pyyaml_reads_them(tmp_path: Path, text: str) -> None:
    path = tmp_path / "deep.yaml"
    path.write_text(text)
    got, expected = load_yaml(path), pyyaml(text)
    while isinstance(expected, dict | list) and expected:  # one level at a time: == would recurse as deep
        key = next(iter(expected)) if isinstance(expected, dict) else 0
        assert type(got) is type(expected) and len(got) == len(expected)
        got, expected = got[key], expected[key]
    assert got == expected


def test_merging_repeated_keys_reads_as_rcl_merges_a_parameter_file(tmp_path: Path) -> None:
    path = tmp_path / "params.yaml"
    path.write_text("/**:\n  a: 1\n")  # `*` goes to PyYAML; the same merge without it reads on the fast path
    text = "node:\n  ros__parameters:\n    a: 1\n    b: {c: 2}\nnode:\n  ros__parameters:\n    b: {d: 3}\n"
    got = read_plain(text, fields._Loader, fields._merged)
    assert got == {"node": {"ros__parameters": {"a": 1, "b": {"c": 2, "d": 3}}}}
    assert same(got, pyyaml(text, merge=True))


def test_a_malformed_file_is_reported_by_pyyaml_with_its_line(tmp_path: Path) -> None:
    path = tmp_path / "scene.yaml"
    path.write_text("world:\n  collision_objects: [1, 2\n")
    with pytest.raises(ConfigError, match=r"scene\.yaml: line 3 malformed YAML"):
        load_yaml(path)


@pytest.mark.parametrize("text", ["name: 2002-13-45\n", "when: &d 2024-02-30\n"])  # the fast path, PyYAML's
def test_a_date_the_calendar_refuses_is_an_error_naming_the_file(tmp_path: Path, text: str) -> None:
    path = tmp_path / "scene.yaml"
    path.write_text(text)
    with pytest.raises(ConfigError, match=r"scene\.yaml: malformed YAML: (month|day) "):
        load_yaml(path)


def _yaml_files(root: Path) -> list[Path]:
    """Return the YAML files under `root`, sorted."""
    return sorted(p for p in root.rglob("*") if p.suffix in (".yaml", ".yml") and p.is_file())


def test_every_yaml_file_the_repository_carries_reads_as_pyyaml_reads_it() -> None:
    files = [p for folder in ("tests", "samples", "configs", "docs") for p in _yaml_files(ROOT / folder)]
    fast = sum(agrees(p.read_text(encoding="utf-8", errors="replace")) is not DECLINED for p in files)
    assert fast > len(files) // 2, f"{fast} of {len(files)} read on the fast path"


@pytest.mark.realworld
def test_every_yaml_file_of_the_vendors_packages_and_benchmarks_reads_as_pyyaml_reads_it() -> None:
    files = _yaml_files(REALWORLD) + _yaml_files(NOETIC)
    assert len(files) > 200
    for path in files:
        agrees(path.read_text(encoding="utf-8", errors="replace"))
