"""No code runs from a data file: xacro expressions, plan files and the on-disk caches (issue 26).

Each hostile file would create a marker file if its code ran. Every case is refused (exit 3,
one line naming the file, no traceback) or, where the command documents going on without the
file's data, a warning; and the marker never appears.
"""

from __future__ import annotations

import hashlib
import os
import pickle
import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from conftest import FILTERED_PLAN, SAMPLES, UR10E, Cli
from mcap.reader import make_reader
from mcap.writer import Writer

from moveplan.core import _native
from moveplan.core.collision import _cache
from moveplan.core.collision import _kernel_cache as kernel_cache
from moveplan.core.collision._pair_tables import PairTable
from moveplan.core.collision._sphere_fit import SphereSet
from moveplan.core.config import _xacro_expressions as xacro_expressions
from moveplan.core.config import _xacro_sandbox as xacro_sandbox
from moveplan.core.config.xacro import PackagePath, process_xacro
from moveplan.core.errors import ConfigError

PLAN = SAMPLES / "recordings" / "tool_up_plan.mcap"  # shipped: its embedded config is configs/ur10e
RECORDING = SAMPLES / "recordings" / "tool_up_ok.mcap"

URDF = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="arm">
  EXTRA
  <link name="base"/><link name="l1"/><link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="tip"/><origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" velocity="1" effort="1"/></joint>
</robot>
"""
SRDF = """<?xml version="1.0"?>
<robot name="arm"><group name="arm"><chain base_link="base" tip_link="tip"/></group></robot>
"""


def one_line(result: Any) -> str:
    """Return the error's one line on stderr (asserting it is the only line and no traceback)."""
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, result.stderr
    assert "Traceback" not in result.stderr and "internal error" not in result.stderr
    return lines[0]


def escapes(marker: Path) -> dict[str, str]:
    """Return xacro text that runs `touch marker` in xacro 2.1.1 itself, by the kind of escape."""
    touch = f"('os').system('touch {marker}')"
    return {
        # xacro checks the names of the expression's own code, not of a comprehension's.
        "comprehension": "<link name=\"${[s()._module.__builtins__['__import__']" + touch
                         + " for x in [()] for s in x.__class__.__base__.__subclasses__()"
                         " if s.__name__ == 'catch_warnings']}\"/>",
        # $(eval ...) runs with every builtin; the text comes from a property, past the lexer's ')'.
        "eval_substitution": f"<xacro:property name=\"f\" value='eval(\"_\"+\"_import_\"+\"_\")(\"os\")"
                             f".system(\"touch {marker}\")'/><link name=\"$(eval ${{f}})\"/>",
        "import": "<link name=\"${__import__" + touch + "}\"/>",
        # str.format reads attributes in its fields: the property's text is out of the expression's sight.
        "format_field": "<xacro:property name=\"f\" value=\"{0.__class__.__base__}\"/><link name=\"${f.format(1)}\"/>",
        "lambda": "<link name=\"${(lambda: 1)()}\"/>",
        "type_builtin": "<link name=\"${python.type('X', (), dict())}\"/>",
    }


def arm_config(folder: Path, extra: str) -> Path:
    """Write a two-joint arm whose moveplan.yaml names arm.urdf.xacro, `extra` inside its <robot>."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "arm.urdf.xacro").write_text(URDF.replace("EXTRA", extra))
    (folder / "arm.srdf").write_text(SRDF)
    (folder / "moveplan.yaml").write_text("name: arm\nurdf: arm.urdf.xacro\nsrdf: arm.srdf\n")
    return folder / "moveplan.yaml"


def rewrite_plan(source: Path, out: Path, attachments: Mapping[str, bytes | None],
                 drop_metadata: tuple[str, ...] = ()) -> Path:
    """Copy a plan file with its attachments replaced (None removes one), as a hostile author would."""
    with source.open("rb") as stream, out.open("wb") as target:
        reader = make_reader(stream)
        writer = Writer(target)
        header = reader.get_header()
        writer.start(header.profile, header.library)
        schemas: dict[int, int] = {}
        channels: dict[int, int] = {}
        for schema, channel, message in reader.iter_messages(log_time_order=True):
            if schema is not None and schema.id not in schemas:
                schemas[schema.id] = writer.register_schema(schema.name, schema.encoding, schema.data)
            if channel.id not in channels:
                channels[channel.id] = writer.register_channel(channel.topic, channel.message_encoding,
                                                               schemas.get(channel.schema_id, 0), channel.metadata)
            writer.add_message(channels[channel.id], message.log_time, message.data, message.publish_time,
                               message.sequence)
        for record in reader.iter_metadata():
            writer.add_metadata(record.name, {k: v for k, v in record.metadata.items() if k not in drop_metadata})
        kept = {a.name: a.data for a in reader.iter_attachments()}
        kept.update(attachments)
        for name, data in kept.items():
            if data is not None:
                writer.add_attachment(0, 0, name, "application/octet-stream", data)
        writer.finish()
    return out


def manifest_of(plan: Path) -> str:
    with plan.open("rb") as stream:
        return next(a.data for a in make_reader(stream).iter_attachments() if a.name == "moveplan.yaml").decode()


# -- 1. xacro in the user's own files: evaluated, but no escape from its expressions ------------------------------


@pytest.mark.parametrize("kind", list(escapes(Path("m"))))
def test_xacro_code_escape_is_a_config_error_and_runs_nothing(cli: Cli, tmp_path: Path, kind: str) -> None:
    marker = tmp_path / "ran"
    config = arm_config(tmp_path / "arm", escapes(marker)[kind])
    result = cli("robot", config)
    assert result.exit_code == 3
    line = one_line(result)
    assert "arm.urdf.xacro" in line and "xacro" in line
    assert not marker.exists()


def test_refused_xacro_expression_is_named_shortened(cli: Cli, tmp_path: Path) -> None:
    long_name = "x" * 200
    config = arm_config(tmp_path / "arm", f"<link name=\"${{''.__class__.__name__ + '{long_name}'}}\"/>")
    line = one_line(cli("robot", config))
    assert "arm.urdf.xacro: xacro: expression ${''.__class__.__name__ + 'xxx" in line
    assert "...} refused: '__class__' reaches Python's internals" in line
    assert "x" * 100 not in line


@pytest.mark.parametrize(("expression", "why"), [
    ("9**9**9", "an integer of more than 4,096 bits"),
    ("1 &lt;&lt; 10**9", "an integer of more than 4,096 bits"),
    ("'a' * 10**10", "a value of more than 1,000,000 items"),
    ("'a'.ljust(10**10)", "a value of more than 1,000,000 items"),
    ("python.sum(python.range(10**15))", "a range of more than 1,000,000 items"),
    ("math.factorial(10**7)", "factorial(10000000) is an integer"),
    ("python.len([0 for a in python.range(2000) for b in python.range(2000)])", "more than 1,000,000 steps"),
    ("1" + "+1" * 1500, "longer than 2,000 characters"),
])
def test_runaway_xacro_arithmetic_is_refused_quickly(cli: Cli, tmp_path: Path, expression: str, why: str) -> None:
    config = arm_config(tmp_path / "arm", f'<link name="${{{expression}}}"/>')
    line = one_line(cli("robot", config))
    assert "arm.urdf.xacro: xacro: expression ${" in line and why in line


def test_doubling_through_properties_is_refused(cli: Cli, tmp_path: Path) -> None:
    doubling = "".join(f'<xacro:property name="p{i}" value="${{[p{i - 1}, p{i - 1}]}}"/>' for i in range(1, 40))
    config = arm_config(tmp_path / "arm", f'<xacro:property name="p0" value="${{[0]*1000}}"/>{doubling}'
                                          '<link name="${python.len(p39)}"/>')
    assert "a value of more than 1,000,000 items" in one_line(cli("robot", config))


def test_macro_bomb_is_refused_at_the_element_bound(cli: Cli, tmp_path: Path) -> None:
    macros = "".join(f'<xacro:macro name="m{i}"><xacro:m{i - 1}/><xacro:m{i - 1}/></xacro:macro>' for i in range(1, 30))
    config = arm_config(tmp_path / "arm", f'<xacro:macro name="m0"><link name="l"/></xacro:macro>{macros}<xacro:m29/>')
    line = one_line(cli("robot", config))
    assert line.endswith(f"xacro: the document expands to more than {xacro_sandbox.MAX_ELEMENTS:,} elements")


def test_file_including_itself_is_refused_by_depth(cli: Cli, tmp_path: Path) -> None:
    config = arm_config(tmp_path / "arm", '<xacro:include filename="arm.urdf.xacro"/>')
    assert one_line(cli("robot", config)).endswith(
        f"xacro: files included more than {xacro_sandbox.MAX_INCLUDE_DEPTH} deep (a file that includes itself?)")


def test_oversized_yaml_for_xacro_is_refused_before_reading(cli: Cli, tmp_path: Path) -> None:
    config = arm_config(tmp_path / "arm", "<link name=\"${xacro.load_yaml('big.yaml')}\"/>")
    with (tmp_path / "arm" / "big.yaml").open("wb") as big:
        big.truncate(xacro_sandbox.MAX_FILE_BYTES + 1)
    assert f"a file xacro reads may have {xacro_sandbox.MAX_FILE_BYTES:,}" in one_line(cli("robot", config))


def test_xacro_that_descriptions_use_still_evaluates(tmp_path: Path) -> None:
    (tmp_path / "params.yaml").write_text("arm: {reach: 0.5, names: [a, b]}\nangle: !degrees 90\n")
    source = tmp_path / "r.urdf.xacro"
    source.write_text("""<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r">
  <xacro:arg name="prefix" default="left_"/>
  <xacro:property name="p" value="${xacro.load_yaml('params.yaml')}"/>
  <xacro:property name="type" value="pal-gripper"/>
  <xacro:macro name="m" params="n:=2 *b"><g n="${n}"><xacro:insert_block name="b"/></g></xacro:macro>
  <a v="${pi/2 + radians(90) + math.cos(0) + python.len([1, 2]) + 2**10 + python.abs(-1)}"/>
  <xacro:property name="fmt" value="{}link"/>
  <b v="${fmt.format('$(arg prefix)')} ${p.arm.reach * 2} ${p['arm']['names'][1]} ${p.angle}"/>
  <c v="${[x * 2 for x in python.range(3)]} ${python.sum([1, 2])} ${python.sorted([2, 1])} ${type == 'pal-gripper'}"/>
  <d v="$(eval 1 + 2 * pi)" w="${'%.2f' % 1.5} ${xacro.tokenize('a b')} ${python.isinstance(1, python.int)}"/>
  <xacro:m><e/></xacro:m>
</robot>
""")
    text = process_xacro(source, {}, PackagePath(()), "r.urdf.xacro").text
    assert '<a v="1031.14159265359"/>' in text
    assert '<b v="left_link 1.0 b 1.5707963267948966"/>' in text
    assert '<c v="[0, 2, 4] 3 [1, 2] True"/>' in text
    assert '<d v="7.283185307179586" w="1.50 [\'a\', \'b\'] True"/>' in text
    assert '<g n="2">' in text


def test_refusal_leaves_xacro_as_it_was(tmp_path: Path) -> None:
    import xacro

    saved = (xacro.safe_eval, xacro._global_symbols, xacro.eval_all, xacro.parse)
    source = tmp_path / "r.urdf.xacro"
    source.write_text('<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r"><a v="${9**9**9}"/></robot>')
    with pytest.raises(ConfigError, match="9\\*\\*9\\*\\*9"):
        process_xacro(source, {}, PackagePath(()), "r.urdf.xacro")
    assert (xacro.safe_eval, xacro._global_symbols, xacro.eval_all, xacro.parse) == saved
    assert xacro_expressions.MAX_INT_BITS == 4096


# -- 2. plan files: the config they carry is data, never code, and names nothing outside them -------------------


XACRO_PLAN_COMMANDS = {
    "execute": ("execute", "{plan}", "--fake", "-o", "{out}"),
    "state": ("state", "--from", "{plan}"),
    "check-tolerances": ("check-tolerances", "{plan}", str(RECORDING)),
}


@pytest.fixture()
def xacro_plan(tmp_path: Path) -> tuple[Path, Path]:
    """A plan whose embedded moveplan.yaml names a xacro URDF that would touch a marker: (plan, marker)."""
    marker = tmp_path / "ran"
    urdf = (UR10E / "ur10e.urdf").read_text().replace(
        '<robot name="ur10e">', '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="ur10e">'
        + escapes(marker)["comprehension"])
    manifest = manifest_of(PLAN).replace("urdf: ur10e.urdf", "urdf: ur10e.urdf.xacro")
    plan = rewrite_plan(PLAN, tmp_path / "hostile.mcap", {"ur10e.urdf.xacro": urdf.encode(), "ur10e.urdf": None,
                                                          "moveplan.yaml": manifest.encode()})
    return plan, marker


@pytest.mark.parametrize("command", list(XACRO_PLAN_COMMANDS))
def test_plan_file_carrying_xacro_is_refused_and_runs_nothing(
    cli: Cli, xacro_plan: tuple[Path, Path], command: str
) -> None:
    plan, marker = xacro_plan
    out = plan.parent / "executed.mcap"
    result = cli(*(a.format(plan=plan, out=out) for a in XACRO_PLAN_COMMANDS[command]))
    assert result.exit_code == 3
    assert one_line(result).endswith(f"{plan}: the plan carries xacro (ur10e.urdf.xacro); moveplan evaluates no "
                                     "code from a plan file: re-plan it with this version of moveplan")
    assert not marker.exists() and not out.exists()


def test_inspect_of_a_plan_carrying_xacro_warns_and_runs_nothing(
    cli: Cli, xacro_plan: tuple[Path, Path], caplog: pytest.LogCaptureFixture
) -> None:
    plan, marker = xacro_plan  # it records no end states: inspect would compute them from its config
    result = cli("inspect", plan)
    assert result.exit_code == 0  # as for any plan whose config does not load: the summary stands
    warnings = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert warnings == [f"{plan}: no end states: {plan}: the plan carries xacro (ur10e.urdf.xacro); moveplan "
                        "evaluates no code from a plan file: re-plan it with this version of moveplan"]
    assert not marker.exists()


@pytest.mark.parametrize(("key", "value"), [
    ("urdf", "/etc/hostname"), ("urdf", "../x.urdf"), ("urdf", "package://ur_description/urdf/ur10e.urdf"),
    ("urdf", "file:///etc/hostname"), ("joint_limits", "/etc/passwd"), ("controllers", "../../ros2_controllers.yaml"),
])
def test_embedded_config_naming_a_host_path_is_refused(cli: Cli, tmp_path: Path, key: str, value: str) -> None:
    manifest = "\n".join(f"{key}: {value}" if line.startswith(f"{key}:") else line
                         for line in manifest_of(PLAN).splitlines())
    plan = rewrite_plan(PLAN, tmp_path / "hostile.mcap", {"moveplan.yaml": manifest.encode()})
    result = cli("execute", plan, "--fake")
    assert result.exit_code == 3
    assert one_line(result).endswith(
        f"{plan}: embedded config: moveplan.yaml: {key}: '{value}' is not a file the plan carries; a plan's config "
        "is read from its own attachments only (no path of this machine, no package:// URI, no xacro)")


@pytest.mark.parametrize("name", [".", "ur10e.urdf/x"])
def test_attachment_that_is_no_file_name_is_an_input_error(cli: Cli, tmp_path: Path, name: str) -> None:
    plan = rewrite_plan(PLAN, tmp_path / "hostile.mcap", {name: b"x"})
    result = cli("execute", plan, "--fake")
    assert result.exit_code == 3
    assert f"{plan}: attachment name '{name}' is not a file name" in one_line(result)


def test_embedded_package_paths_and_xacro_args_are_not_read(cli: Cli, tmp_path: Path) -> None:
    manifest = manifest_of(PLAN) + "package_paths: [/etc, ../..]\nxacro_args: {a: b}\n"
    plan = rewrite_plan(PLAN, tmp_path / "plan.mcap", {"moveplan.yaml": manifest.encode()})
    assert cli("execute", plan, "--fake").exit_code == 0


def test_embedded_controllers_get_no_launch_substitutions(cli: Cli, tmp_path: Path, monkeypatch: Any) -> None:
    monkeypatch.delenv("MOVEPLAN_UNSET_VARIABLE", raising=False)
    with PLAN.open("rb") as stream:
        controllers = next(a.data for a in make_reader(stream).iter_attachments() if a.name == "ros2_controllers.yaml")
    # Substituted, this line would read the environment and fail on the unset variable.
    hostile = b"# $(env MOVEPLAN_UNSET_VARIABLE)\n" + controllers
    plan = rewrite_plan(PLAN, tmp_path / "plan.mcap", {"ros2_controllers.yaml": hostile})
    result = cli("execute", plan, "--fake")
    assert result.exit_code == 0, result.stderr


def test_tune_pid_of_a_plans_own_controllers_gets_no_launch_substitutions(
    cli: Cli, tmp_path: Path, monkeypatch: Any
) -> None:
    monkeypatch.delenv("MOVEPLAN_UNSET_VARIABLE", raising=False)
    config = tmp_path / "ur10e"
    config.mkdir()
    for file in UR10E.iterdir():
        if file.is_file():
            (config / file.name).write_bytes(file.read_bytes())
    (config / "ros2_controllers.yaml").write_bytes((SAMPLES / "ur10e_velocity_controllers.yaml").read_bytes())
    planned = tmp_path / "plan.mcap"
    assert cli("plan", "--robot", config, "--start-joints", "0,-1,-1,0,0,0", "--named", "home", "-o", planned,
               "-q").exit_code == 0
    with planned.open("rb") as stream:
        controllers = next(a.data for a in make_reader(stream).iter_attachments() if a.name == "ros2_controllers.yaml")
    plan = rewrite_plan(planned, tmp_path / "hostile.mcap",
                        {"ros2_controllers.yaml": b"# $(env MOVEPLAN_UNSET_VARIABLE)\n" + controllers})
    result = cli("tune-pid", plan, "-o", tmp_path / "tuned.yaml", "-q")
    assert result.exit_code == 0, result.stderr
    assert (tmp_path / "tuned.yaml").read_text().startswith("# $(env MOVEPLAN_UNSET_VARIABLE)\n")


def test_state_of_a_plan_reads_no_mesh_file_its_embedded_scene_names(
    cli: Cli, tmp_path: Path, monkeypatch: Any
) -> None:
    """A PlanningScene's mesh `resource` names a file of the machine that planned; the plan carries none."""
    mesh = tmp_path / "tray.stl"
    mesh.write_text("solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\nvertex 0 0.1 0\n"
                    "endloop\nendfacet\nendsolid t\n")
    scene = tmp_path / "scene.yaml"
    scene.write_text(
        "world:\n  collision_objects:\n  - id: tray\n    header: {frame_id: base_link}\n"
        "    pose: {position: {x: 2.0, y: 0.0, z: 0.0}, orientation: {w: 1.0}}\n"
        f"    meshes: [{{resource: {mesh}}}]\n    mesh_poses: [{{orientation: {{w: 1.0}}}}]\n")
    plan = tmp_path / "plan.mcap"
    assert cli("plan", "--robot", UR10E, "--scene", scene, "--start-joints", "0,-1,-1,0,0,0", "--named", "home",
               "-o", plan, "-q").exit_code == 0
    mesh.unlink()  # had state opened it, the tray would now be "mesh file not found"
    opened: list[str] = []
    real_open = os.open
    monkeypatch.setattr(os, "open", lambda path, *args, **kw: opened.append(str(path)) or real_open(path, *args, **kw))
    code, document = cli.json("state", "--from", plan)
    assert code == 0, document
    assert str(mesh) not in opened


def test_plan_of_a_xacro_config_carries_the_expanded_urdf(cli: Cli, tmp_path: Path) -> None:
    config = tmp_path / "ur10e"
    config.mkdir()
    for file in UR10E.iterdir():
        if file.is_file():
            (config / file.name).write_bytes(file.read_bytes())
    (config / "ur10e.urdf").rename(config / "ur10e.urdf.xacro")
    manifest = config / "moveplan.yaml"
    manifest.write_text(manifest.read_text().replace("urdf: ur10e.urdf", "urdf: ur10e.urdf.xacro"))
    out = tmp_path / "plan.mcap"
    result = cli("plan", "--robot", manifest, "--start-joints", "0,-1,-1,0,0,0", "--named", "home", "-o", out)
    assert result.exit_code == 0, result.stderr
    with out.open("rb") as stream:
        names = [a.name for a in make_reader(stream).iter_attachments()]
    assert "ur10e.urdf" in names and not [n for n in names if n.lower().endswith(".xacro")]
    assert "urdf: ur10e.urdf\n" in manifest_of(out)
    assert cli("execute", out, "--fake").exit_code == 0


# -- 3. caches: data checked before use, never unpickled -------------------------------------------------------


class _Touch:
    """Pickles to a call that creates a marker file when unpickled."""

    def __init__(self, marker: Path) -> None:
        self.marker = marker

    def __reduce__(self) -> tuple[Any, ...]:
        return (Path.touch, (self.marker,))


def planted(payload: bytes) -> bytes:
    """Return a cache entry of the current format whose checksum matches `payload`, as anyone can write one."""
    return b"moveplan-cache %d %s\n" % (_cache.FORMAT, hashlib.sha256(payload).hexdigest().encode()) + payload


def test_planted_pickle_in_the_cache_is_not_loaded(tmp_path: Path, caplog: pytest.LogCaptureFixture) -> None:
    marker = tmp_path / "ran"
    where = tmp_path / "spheres.entry"
    where.write_bytes(planted(pickle.dumps(_Touch(marker))))
    assert _cache.read(where, SphereSet) is None
    assert len(caplog.records) == 1 and "recomputing it" in caplog.records[0].getMessage()
    assert not marker.exists()


@pytest.mark.parametrize("payload", [
    b'{"$dataclass":["Path",{"x":1}]}\n',  # a class outside the table
    b'{"$dataclass":["SphereSet",{"centres":1}]}\n',  # fields that do not match
    b'{"$array":["|O",[1],0,8]}\n' + b"\0" * 8,  # an object array
    b'{"$array":["<f8",[1000000],0,8000000]}\n' + b"\0" * 8,  # an array larger than the entry
    b'{"$dict":[[[1],2]]}\n',  # an unhashable key
    b"[" * 100000 + b"\n",  # nested beyond any entry
])
def test_malformed_cache_payload_is_rebuilt_with_one_warning(
    tmp_path: Path, caplog: pytest.LogCaptureFixture, payload: bytes
) -> None:
    where = tmp_path / "entry.entry"
    where.write_bytes(planted(payload))
    assert _cache.read(where, object) is None
    assert len(caplog.records) == 1 and "cannot be used" in caplog.records[0].getMessage()


def test_cache_entries_read_back_the_values_computed(tmp_path: Path) -> None:
    spheres = SphereSet(np.arange(6.0).reshape(2, 3), np.array([0.1, 0.2]), np.array([1, 2], dtype=np.int64),
                        ("link_a", "link_b"))
    tables = (PairTable("upper", "lower", (3, 4), (-1.5, 0.0), (0.25, 0.5), np.linspace(0, 1, 12).reshape(3, 4),
                        0.01),)
    _cache.write(tmp_path / "spheres.entry", spheres)
    _cache.write(tmp_path / "pairs.entry", tables)
    back = _cache.read(tmp_path / "spheres.entry", SphereSet)
    for name in ("centres", "radii", "joints"):
        np.testing.assert_array_equal(getattr(back, name), getattr(spheres, name))
        assert getattr(back, name).dtype == getattr(spheres, name).dtype
    assert back.owners == spheres.owners
    (table,) = _cache.read(tmp_path / "pairs.entry", tuple)
    assert (table.upper, table.lower, table.q_index, table.start, table.step, table.margin) == \
        ("upper", "lower", (3, 4), (-1.5, 0.0), (0.25, 0.5), 0.01)
    np.testing.assert_array_equal(table.distances, tables[0].distances)
    assert b"pickle" not in (tmp_path / "pairs.entry").read_bytes()


def test_cache_entry_of_an_unknown_type_is_not_written(tmp_path: Path) -> None:
    with pytest.raises(TypeError, match="cannot hold a PosixPath"):
        _cache.write(tmp_path / "entry.entry", (Path("x"),))
    assert list(tmp_path.iterdir()) == []


def test_planted_cache_entries_run_nothing_when_planning(tmp_path: Path) -> None:
    cache, marker = tmp_path / "cache", tmp_path / "ran"
    env = {**os.environ, "MOVEPLAN_CACHE_DIR": str(cache)}

    def plan(out: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-c", FILTERED_PLAN, SAMPLES / "panda_shelf_bays.yaml", tmp_path / out],
                              env=env, capture_output=True, text=True, timeout=300)

    assert plan("first.mcap").returncode == 0
    entries = sorted(cache.iterdir())
    assert entries
    for entry in entries:  # what an attacker with write access to a shared CI cache can do
        entry.write_bytes(planted(pickle.dumps(_Touch(marker))))
    second = plan("second.mcap")
    assert second.returncode == 0, second.stderr
    assert second.stderr.count("cannot be used") == len(entries)
    assert not marker.exists()
    assert (tmp_path / "second.mcap").read_bytes() == (tmp_path / "first.mcap").read_bytes()


def test_numba_index_is_checked_without_unpickling(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    marker = tmp_path / "ran"
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "numba"))
    source = Path(kernel_cache.__file__).resolve().parent.parent / "collision" / "_kernels.py"
    folder = _native.cache_folder(source.parent)
    assert folder is not None
    folder.mkdir(parents=True)
    text = source.read_bytes()
    lines = kernel_cache._first_lines(text)
    version = pickle.dumps(kernel_cache.metadata.version("numba"), protocol=pickle.HIGHEST_PROTOCOL)
    stamp = hashlib.sha256(text).digest()
    index = folder / f"_kernels.classify-{lines['classify']}.py{sys.version_info[0]}{sys.version_info[1]}.nbi"
    kernel_cache.kernels_cached.cache_clear()
    try:
        index.write_bytes(pickle.dumps(_Touch(marker)) + stamp)
        assert kernel_cache.kernels_cached() is False
        assert not marker.exists()
        assert kernel_cache._index_matches(index, kernel_cache.metadata.version("numba"), stamp) is False
        index.write_bytes(version + pickle.dumps((stamp, {})))
        assert kernel_cache._index_matches(index, kernel_cache.metadata.version("numba"), stamp) is True
    finally:
        kernel_cache.kernels_cached.cache_clear()
