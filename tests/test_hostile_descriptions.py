"""Hostile robot descriptions: numbers urdfdom chokes on, robots too large to check, xacro args that are
no text, include cycles, unreadable workspace folders. Each is one line naming the file, the element
and the value (exit 3), or the flag (exit 2), with nothing of urdfdom's log on stderr."""

from __future__ import annotations

from pathlib import Path

import pytest
from conftest import Cli, run_process
from test_hostile_packages import arm_package, one_line

from moveplan.core.config.urdf import MAX_LINKS

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


def test_a_robot_beyond_the_link_limit_is_refused_before_it_is_loaded(cli: Cli, tmp_path: Path) -> None:
    count = MAX_LINKS + 1
    links = "".join(f'<link name="l{i}"/>' for i in range(count))
    joints = "".join(f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/>'
                     '<axis xyz="0 0 1"/><limit lower="-1" upper="1" velocity="1" effort="1"/></joint>'
                     for i in range(count - 1))
    (tmp_path / "big.urdf").write_text(f'<robot name="big">{links}{joints}</robot>')
    (tmp_path / "big.srdf").write_text('<robot name="big"><group name="arm"><joint name="j0"/></group></robot>')
    result = cli("plan", "--robot", tmp_path / "big.urdf", "--srdf", tmp_path / "big.srdf", "--joints", "0.1",
                 "-o", tmp_path / "p.mcap")
    assert result.exit_code == 3
    assert one_line(result).endswith(f"big.urdf: {count:,} links; moveplan loads robots of at most {MAX_LINKS} links")


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
    assert "arm.urdf.xacro" in line and "missing_part.xacro" in line and "No such file" in line


def test_an_unreadable_folder_in_the_workspace_is_passed_over(
    cli: Cli, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    package = arm_package(tmp_path)
    private = package.parent / "zz_private"
    (private / "inside").mkdir(parents=True)
    listing = Path.iterdir

    def refusing(self: Path):  # noqa: ANN202 - Path.iterdir's generator
        if self.name == "zz_private":
            raise PermissionError(13, "Permission denied", str(self))
        return listing(self)
    monkeypatch.setattr(Path, "iterdir", refusing)
    result = cli("plan", "--robot", package, *PLAN_ARGS, "-o", tmp_path / "p.mcap", "-q")
    assert result.exit_code == 0, result.stderr
