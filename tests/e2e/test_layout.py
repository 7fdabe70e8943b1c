"""The package's shape: no import cycles between modules (import-linter holds the districts' order)."""

from __future__ import annotations

import ast
import importlib
import tomllib
from pathlib import Path

import grimp
import pytest

ROOT = Path(__file__).resolve().parents[2]


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


def _scope(module: str) -> str:
    """Return the package whose insides may import `module` directly (moveplan.core's districts are moveplan's)."""
    parent = module.rsplit(".", 1)[0]
    return "moveplan" if parent == "moveplan.core" else parent


def _faces() -> list[str]:
    return sorted("moveplan." + ".".join(init.parent.relative_to(ROOT).parts)
                  for init in (ROOT / "core").rglob("__init__.py") if "msgs" not in init.parts)


def test_imports_between_packages_go_through_the_packages_face() -> None:
    """Renaming a module breaks only its own package: everyone outside imports the package's __init__."""
    graph = grimp.build_graph("moveplan.core", "moveplan.cli", "moveplan.commander")
    reaching_in = sorted(f"{importer} -> {imported}"
                         for imported in graph.modules
                         for importer in graph.find_modules_that_directly_import(imported)
                         if not (importer + ".").startswith(_scope(imported) + "."))
    assert reaching_in == []


@pytest.mark.parametrize("face", _faces())
def test_a_face_exports_what_it_lists_and_loads_it_on_first_use(face: str) -> None:
    """`from moveplan.core.X import name` gives the name, typed for mypy, and no name hides a submodule."""
    package = importlib.import_module(face)
    tree = ast.parse(Path(package.__file__).read_text())
    typed = {alias.asname or alias.name for node in ast.walk(tree) if isinstance(node, ast.If)
             for inner in node.body if isinstance(inner, ast.ImportFrom) for alias in inner.names}
    exported = set(getattr(package, "__all__", ()))
    assert typed == exported
    children = {child.stem for child in Path(package.__file__).parent.iterdir()
                if child.suffix == ".py" or (child / "__init__.py").exists()}
    assert exported & children == set()
    for name in exported:
        assert getattr(package, name) is not None


def test_the_packages_ship_their_types() -> None:
    """`moveplan.commander` users' type checkers read moveplan's annotations (PEP 561: py.typed in the package)."""
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    for package, folder in (("moveplan.core", "core"), ("moveplan.cli", "cli"), ("moveplan.commander", "commander")):
        assert (ROOT / folder / "py.typed").is_file()
        assert "py.typed" in data[package]
