"""Hostile robot descriptions: numbers urdfdom chokes on, robots too large to check, xacro args that are
no text, include cycles, files that are no UTF-8 text, unreadable workspace folders. Each is one line
naming the file, the element and the value (exit 3), or the flag (exit 2), with nothing of urdfdom's
log on stderr."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import Cli, run_process
from test_hostile_packages import MESH_LINK, URDF, arm_package, description_package, one_line

from moveplan.core.collision._certify import MAX_REACH_M, MAX_STATES
from moveplan.core.config._urdf import MAX_DEGREES_OF_FREEDOM, MAX_LINKS

PLAN_ARGS = ("--start-joints", "0,0", "--joints", "0.5,0.5")
ORIGIN = 'xyz="0 0 0.5"/><axis'


def with_origin(tmp_path: Path, xyz: str) -> Path:
    """Return an arm package whose joint j2 has origin `xyz`."""
    package = arm_package(tmp_path)
    urdf = package / "config" / "arm.urdf"
    urdf.write_text(urdf.read_text().replace(ORIGIN, f'xyz="{xyz}"/><axis'))
    return package


@pytest.mark.parametrize(("xyz", "problem"), [
    ("0 nan 0.5", "'nan' is not a finite number"),
    ("0 -inf 0.5", "'-inf' is not a finite number"),
    ("0 1e300 0.5", "'1e300' is beyond moveplan's bound of 1e+06"),
])
def test_a_urdf_origin_that_is_no_finite_length_names_joint_and_value(
    cli: Cli, tmp_path: Path, xyz: str, problem: str
) -> None:
    result = cli("plan", "--robot", with_origin(tmp_path, xyz), *PLAN_ARGS, "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3
    line = one_line(result)
    assert f"arm.urdf: joint 'j2' <origin xyz='{xyz}'>: {problem}" in line
    assert not (tmp_path / "p.mcap").exists()


def test_a_shape_size_that_is_nan_names_the_link(cli: Cli, tmp_path: Path) -> None:
    link = '<link name="m"><collision><geometry><box size="0.1 nan 0.1"/></geometry></collision></link>' \
           '<joint name="jm" type="fixed"><parent link="tip"/><child link="m"/></joint>'
    package = arm_package(tmp_path, urdf_extra=link)
    result = cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3
    assert "arm.urdf: link 'm' <box size='0.1 nan 0.1'>: 'nan' is not a finite number" in one_line(result)


def test_a_number_urdfdom_cannot_read_is_its_reason_in_one_line_without_its_log(tmp_path: Path) -> None:
    package = with_origin(tmp_path, "0 x 0.5")
    result = run_process("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap")
    assert result.returncode == 3
    assert result.stderr.count("\n") == 1 and "Error:" not in result.stderr, result.stderr
    assert "pinocchio cannot load the URDF: Unable to parse component [x] to a double" in result.stderr


def chain(tmp_path: Path, count: int, kind: str = "revolute") -> tuple[Path, Path]:
    """Return a URDF of `count` links in a chain of `kind` joints, and an SRDF of a group of its first joint."""
    links = "".join(f'<link name="l{i}"/>' for i in range(count))
    joints = "".join(f'<joint name="j{i}" type="{kind if i else "revolute"}"><parent link="l{i}"/>'
                     f'<child link="l{i + 1}"/><axis xyz="0 0 1"/>'
                     '<limit lower="-1" upper="1" velocity="1" effort="1"/></joint>' for i in range(count - 1))
    (tmp_path / "big.urdf").write_text(f'<robot name="big">{links}{joints}</robot>')
    (tmp_path / "big.srdf").write_text('<robot name="big"><group name="arm"><joint name="j0"/></group></robot>')
    return tmp_path / "big.urdf", tmp_path / "big.srdf"


def test_a_robot_beyond_the_link_limit_is_refused_before_it_is_loaded(cli: Cli, tmp_path: Path) -> None:
    count = MAX_LINKS + 1
    urdf, srdf = chain(tmp_path, count, "fixed")
    result = cli("plan", "--robot", urdf, "--srdf", srdf, "--joints", "0.1", "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3
    assert one_line(result).endswith(f"big.urdf: {count:,} links; moveplan loads robots of at most {MAX_LINKS} links")


def test_a_robot_beyond_the_joint_limit_is_refused_before_pinocchio_sizes_its_tables(cli: Cli, tmp_path: Path) -> None:
    # pinocchio's model data grows with the cube of the joints: 1,000 revolute joints take 32 GB per copy.
    urdf, srdf = chain(tmp_path, MAX_DEGREES_OF_FREEDOM + 2)
    result = cli("plan", "--robot", urdf, "--srdf", srdf, "--joints", "0.1", "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3
    assert one_line(result).endswith(f"big.urdf: {MAX_DEGREES_OF_FREEDOM + 1} degrees of freedom in its joints; "
                                     f"moveplan loads robots of at most {MAX_DEGREES_OF_FREEDOM}")


def test_joint_data_urdfdom_refuses_names_the_joint_and_value(cli: Cli, tmp_path: Path) -> None:
    package = with_origin(tmp_path, '0 0 0.5"/><safety_controller soft_lower_limit="nan" k_velocity="1')
    result = cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3
    assert "arm.urdf: joint 'j2' <safety_controller soft_lower_limit='nan'>: 'nan' is not a finite number" \
        in one_line(result)


def test_a_shape_of_negative_size_is_refused_not_a_shape_that_never_collides(cli: Cli, tmp_path: Path) -> None:
    link = '<link name="m"><collision><geometry><sphere radius="-0.1"/></geometry></collision></link>' \
           '<joint name="jm" type="fixed"><parent link="tip"/><child link="m"/></joint>'
    result = cli("plan", "--robot", arm_package(tmp_path, urdf_extra=link), *PLAN_ARGS, "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3
    assert "arm.urdf: link 'm' <sphere radius='-0.1'>: '-0.1' is negative" in one_line(result)


@pytest.mark.parametrize(("geometry", "problem"), [
    ('<box size="0.1 0.1"/>', "Parser found 2 elements but 3 expected while parsing vector [0.1 0.1]"),
    ('<cone radius="0.1"/>', "Unknown geometry type 'cone'"),
])
def test_a_collision_shape_urdfdom_drops_is_refused_in_one_line_without_its_log(
    tmp_path: Path, geometry: str, problem: str
) -> None:
    link = f'<link name="m"><collision><geometry>{geometry}</geometry></collision></link>' \
           '<joint name="jm" type="fixed"><parent link="tip"/><child link="m"/></joint>'
    package = arm_package(tmp_path, urdf_extra=link)
    result = run_process("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap")
    assert result.returncode == 3
    assert result.stderr.count("\n") == 1 and "Error:" not in result.stderr, result.stderr
    assert f"arm.urdf: urdfdom cannot read part of the URDF: {problem}; " \
           "Could not parse collision element for Link [m]" in result.stderr


FAR_LINK = '<link name="far"><collision><geometry><sphere radius="0.1"/></geometry></collision></link>' \
           '<joint name="jf" type="fixed"><parent link="tip"/><child link="far"/><origin xyz="XYZ"/></joint>'


def test_a_robot_kilometres_long_is_refused_before_its_motions_take_millions_of_checks(
    cli: Cli, tmp_path: Path
) -> None:
    # Within the URDF's bound of 1e6 m, yet a half-radian turn would move the link 50 km: 10,000,000 checks.
    package = arm_package(tmp_path, urdf_extra=FAR_LINK.replace("XYZ", "100000 0 0"))
    result = cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3
    line = one_line(result)
    assert "arm.urdf: joint 'j1' carries collision geometry up to 100001 m from its axis" in line
    assert f"within {MAX_REACH_M:,.0f} m of each joint" in line


def test_a_goal_many_turns_away_is_refused_before_its_checks_exhaust_memory(cli: Cli, tmp_path: Path) -> None:
    package = arm_package(tmp_path, urdf_extra=FAR_LINK.replace("XYZ", "0 0 0.1"))
    urdf = package / "config" / "arm.urdf"
    urdf.write_text(urdf.read_text().replace('lower="-2" upper="2"', 'lower="-1e16" upper="1e16"', 1))
    result = cli("plan", "--robot", package, "--start-joints", "0,0", "--joints", "100000,0", "-o",
                 tmp_path / "p.mcap")
    assert result.exit_code == 3
    line = one_line(result)
    assert "step 'goal': a motion moves robot points up to" in line
    assert f"collision checks, more than moveplan's {MAX_STATES:,}" in line
    assert not (tmp_path / "p.mcap").exists()


XACRO = """<?xml version="1.0"?>
<robot name="arm" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="reach" default="0.5"/>
  <link name="base"/><link name="tip"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="tip"/><origin xyz="0 0 $(arg reach)"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>
  INCLUDE
</robot>
"""
SRDF = '<?xml version="1.0"?>\n<robot name="arm"><group name="arm"><joint name="j1"/></group></robot>\n'


def xacro_robot(tmp_path: Path, include: str = "") -> tuple[Path, Path]:
    """Return a one-joint xacro URDF (arg `reach`, including `include`) and its SRDF."""
    (tmp_path / "arm.urdf.xacro").write_text(XACRO.replace("INCLUDE", include))
    (tmp_path / "arm.srdf").write_text(SRDF)
    return tmp_path / "arm.urdf.xacro", tmp_path / "arm.srdf"


@pytest.mark.parametrize(("arg", "problem"), [
    ("reach:=0.5\udcff", "--xacro-arg 'reach:=0.5\\udcff': not UTF-8 text"),
    ("reach:=" + "9" * 5000, "5,000 characters; at most 4,096"),
    ("reach=0.5", "--xacro-arg 'reach=0.5': expected name:=value"),
])
def test_a_xacro_arg_that_is_no_text_or_too_long_is_a_usage_error(
    cli: Cli, tmp_path: Path, arg: str, problem: str
) -> None:
    urdf, srdf = xacro_robot(tmp_path)
    result = cli("robot", urdf, "--srdf", srdf, "--xacro-arg", arg)
    assert result.exit_code == 2
    assert problem in one_line(result)


def test_a_xacro_arg_given_twice_is_a_usage_error(cli: Cli, tmp_path: Path) -> None:
    urdf, srdf = xacro_robot(tmp_path)
    result = cli("robot", urdf, "--srdf", srdf, "--xacro-arg", "reach:=0.4", "--xacro-arg", "reach:=0.6")
    assert result.exit_code == 2
    assert one_line(result) == "moveplan: error: --xacro-arg reach: given twice"


def test_a_huge_xacro_arg_in_an_origin_is_refused_by_the_urdf_bound(cli: Cli, tmp_path: Path) -> None:
    urdf, srdf = xacro_robot(tmp_path)
    result = cli("robot", urdf, "--srdf", srdf, "--xacro-arg", "reach:=1e300")
    assert result.exit_code == 3
    assert "joint 'j1' <origin xyz='0 0 1e300'>: '1e300' is beyond moveplan's bound" in one_line(result)


def test_a_xacro_arg_beyond_a_float_in_an_expression_names_the_expression(cli: Cli, tmp_path: Path) -> None:
    urdf, srdf = xacro_robot(tmp_path, '<link name="x"/><joint name="jx" type="fixed"><parent link="tip"/>'
                                       '<child link="x"/><origin xyz="0 0 ${10 ** $(arg reach)}"/></joint>')
    result = cli("robot", urdf, "--srdf", srdf, "--xacro-arg", "reach:=1e300")
    assert result.exit_code == 3
    assert one_line(result).endswith("arm.urdf.xacro: xacro error: a number beyond a float's range; "
                                     "when evaluating expression '10 ** $(arg reach)'")


def test_an_include_cycle_is_one_short_line_naming_the_files_that_loop(cli: Cli, tmp_path: Path) -> None:
    urdf, srdf = xacro_robot(tmp_path, '<xacro:include filename="loop.xacro"/>')
    (tmp_path / "loop.xacro").write_text('<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro">'
                                         '<xacro:include filename="arm.urdf.xacro"/></robot>\n')
    result = cli("robot", urdf, "--srdf", srdf)
    assert result.exit_code == 3
    line = one_line(result)
    assert line.count("(included from") == 4, line
    assert "loop.xacro)" in line and "... 28 more" in line and "included more than 32 deep" in line


def test_a_missing_include_names_the_file_and_its_includer(cli: Cli, tmp_path: Path) -> None:
    urdf, srdf = xacro_robot(tmp_path, '<xacro:include filename="missing_part.xacro"/>')
    result = cli("robot", urdf, "--srdf", srdf)
    assert result.exit_code == 3
    line = one_line(result)
    assert "arm.urdf.xacro: cannot read " in line and line.endswith("missing_part.xacro: No such file or directory")
    assert line.count("missing_part.xacro") == 1


def test_an_include_of_a_folder_says_it_is_a_folder(cli: Cli, tmp_path: Path) -> None:
    urdf, srdf = xacro_robot(tmp_path, '<xacro:include filename="parts"/>')
    (tmp_path / "parts").mkdir()
    result = cli("robot", urdf, "--srdf", srdf)
    assert result.exit_code == 3
    assert one_line(result).endswith("parts is a folder, not a file")


def test_an_included_xacro_that_is_no_utf8_names_it_and_its_includer(cli: Cli, tmp_path: Path) -> None:
    urdf, srdf = xacro_robot(tmp_path, '<xacro:include filename="part.xacro"/>')
    (tmp_path / "part.xacro").write_bytes(b'<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="\xe9"/>'
                                          b'</robot>')
    result = cli("robot", urdf, "--srdf", srdf)
    assert result.exit_code == 3
    line = one_line(result)
    assert "part.xacro (included from " in line and "arm.urdf.xacro): cannot read: not UTF-8 text" in line


@pytest.mark.parametrize("file", ["arm.urdf", "arm.srdf", "arm.urdf.xacro"])
@pytest.mark.parametrize(("bad", "problem"), [(b"\xe9", "not UTF-8 text"), (b"\0", "malformed XML")])
def test_a_description_with_a_nul_or_no_utf8_names_the_file(
    cli: Cli, tmp_path: Path, file: str, bad: bytes, problem: str
) -> None:
    urdf, srdf = xacro_robot(tmp_path)
    (tmp_path / "arm.urdf").write_text(URDF.replace("EXTRA", ""))
    path = tmp_path / file
    path.write_bytes(path.read_bytes().replace(b'<link name="base"/>', b'<link name="b' + bad + b'se"/>', 1)
                     .replace(b'<group name="arm">', b'<group name="a' + bad + b'm">', 1))
    description = urdf if file.endswith(".xacro") else tmp_path / "arm.urdf"
    result = cli("robot", description, "--srdf", srdf)
    assert result.exit_code == 3
    line = one_line(result)
    assert f"{file}: " in line and problem in line


def test_a_urdf_whose_root_is_not_robot_is_named_as_no_urdf(cli: Cli, tmp_path: Path) -> None:
    urdf, srdf = xacro_robot(tmp_path)
    (tmp_path / "arm.urdf").write_text('<?xml version="1.0"?>\n<sdf version="1.6"><model name="arm"/></sdf>\n')
    result = cli("robot", tmp_path / "arm.urdf", "--srdf", srdf)
    assert result.exit_code == 3
    assert one_line(result).endswith("arm.urdf: not a URDF (root element is <sdf>, expected <robot>)")


@pytest.mark.parametrize("refused", ["listed", "entered"])
def test_an_unreadable_folder_in_the_workspace_is_passed_over_with_a_warning(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture, refused: str
) -> None:
    # As root, chmod refuses nothing: the system's refusal is simulated. A folder of mode r-- may be
    # listed, not entered (stat of what is in it fails); one of mode --- neither. The mesh's package
    # makes moveplan look through the workspace.
    package = arm_package(tmp_path, urdf_extra=MESH_LINK)
    description_package(package)
    private = package.parent / "zz_private"
    (private / "inside").mkdir(parents=True)
    listing, status = Path.iterdir, Path.stat

    def refusing_list(self: Path):  # noqa: ANN202 - Path.iterdir's generator
        if self == private:
            raise PermissionError(13, "Permission denied", str(self))
        return listing(self)

    def refusing_stat(self: Path, **kwargs: bool):  # noqa: ANN202 - os.stat_result
        if self.parent == private:
            raise PermissionError(13, "Permission denied", str(self))
        return status(self, **kwargs)
    monkeypatch.setattr(Path, "iterdir" if refused == "listed" else "stat",
                        refusing_list if refused == "listed" else refusing_stat)
    result = cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap")
    assert result.exit_code == 0, result.stderr
    assert f"{private}: cannot be read (Permission denied); packages in it are not looked at" in caplog.text
