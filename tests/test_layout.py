"""The package's shape: no import cycles between modules (import-linter holds the districts' order)."""

from __future__ import annotations

import tomllib
from pathlib import Path

import grimp

ROOT = Path(__file__).resolve().parents[1]


def test_no_module_imports_itself_through_others() -> None:
    graph = grimp.build_graph("moveplan.core", "moveplan.cli", "moveplan.commander")
    cycles = sorted({tuple(sorted((module, imported)))
                     for module in graph.modules
                     for imported in graph.find_modules_directly_imported_by(module)
                     if graph.chain_exists(importer=imported, imported=module)})
    assert not cycles


def test_every_package_folder_is_shipped_by_pyproject() -> None:
    """A sub-package missing from pyproject's list works in a checkout and is absent from an installed moveplan."""
    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    folders = {"moveplan." + ".".join(init.parent.relative_to(ROOT).parts)
               for top in ("core", "cli", "commander", "configs") for init in (ROOT / top).rglob("__init__.py")}
    assert folders - listed == set()
