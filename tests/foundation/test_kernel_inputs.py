"""numba's disk cache keys a kernel by its own file's bytes: each kernel file names the sources it compiles in, by hash.

numba's documentation, "Notes on Caching", cache limitations: a change to a symbol defined in another
file does not invalidate the cache, and globals are compiled in as constants. A kernel file whose
callees or constants live elsewhere (core/collision/_clearance.py calls _kernels.py's placement;
core/timing/_compiled.py compiles trajectory.py's _velocity_extreme and reads _topp.py's STILL) would
keep its old machine code after such a change, in a working tree or an upgrade that leaves
__pycache__ behind. The line it carries with those sources' hashes changes its bytes with them.
"""

from __future__ import annotations

import ast
import hashlib
from pathlib import Path

import pytest
from conftest import ROOT

CORE = (ROOT / "core").resolve()
INPUTS = {
    "collision/_kernels.py": ("collision/_verdicts.py",),
    "collision/_clearance.py": ("collision/_kernels.py", "collision/_verdicts.py"),
    "collision/_states.py": (),
    "timing/_compiled.py": ("trajectory.py", "timing/_topp.py"),
}
"""Per file of compiled kernels (under core/), the files whose functions or constants its kernels compile in."""


def inputs_line(kernels: str) -> str:
    """Return the line `kernels` must carry: its inputs, each with the first 12 hex digits of its sha256."""
    return "# Compiled in (sha256): " + ", ".join(
        f"{source} {hashlib.sha256((CORE / source).read_bytes()).hexdigest()[:12]}" for source in INPUTS[kernels])


def core_imports(kernels: str) -> set[str]:
    """Return the files under core/ that `kernels` imports from, relative to core/."""
    found = set()
    for node in ast.parse((CORE / kernels).read_text()).body:
        if isinstance(node, ast.ImportFrom) and node.level:
            package = (CORE / kernels).parent.joinpath(*[".."] * (node.level - 1))
            for target in [node.module] if node.module else [alias.name for alias in node.names]:
                path = package.joinpath(*target.split(".")).resolve()
                module = path.with_suffix(".py") if path.with_suffix(".py").exists() else path / "__init__.py"
                found.add(module.relative_to(CORE).as_posix())
    return found


@pytest.mark.parametrize("kernels", sorted(k for k, inputs in INPUTS.items() if inputs))
def test_a_kernel_file_names_the_sources_it_compiles_in_as_they_are(kernels: str) -> None:
    line = inputs_line(kernels)
    assert line in (CORE / kernels).read_text().splitlines(), f"core/{kernels}: its 'Compiled in' line is now: {line}"


@pytest.mark.parametrize("kernels", sorted(INPUTS))
def test_every_module_a_kernel_file_imports_from_core_is_one_of_its_inputs(kernels: str) -> None:
    assert core_imports(kernels) - set(INPUTS[kernels]) == set()


def test_every_file_with_compiled_kernels_is_listed() -> None:
    compiled = {path.relative_to(CORE).as_posix() for path in CORE.rglob("*.py")
                if "numba.njit(" in path.read_text() and "import numba" in path.read_text()}
    assert compiled == set(INPUTS)


def test_the_modules_compiled_ahead_of_time_are_named_by_every_file_of_kernels() -> None:
    # Their file names hash these files' bytes (core/_native.py): a kernel file left out would be served stale.
    from moveplan.core.collision import compiled
    from moveplan.core.timing import _twins

    core = Path(compiled.__file__).resolve().parents[1]  # the installed package's, as it names them
    named = [path.relative_to(core).as_posix() for path in (*compiled.SOURCES, *_twins.SOURCES)]
    assert sorted(named) == sorted(INPUTS)

