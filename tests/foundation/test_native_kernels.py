"""Kernels compiled ahead of time (core/_native.py): built once, loaded without numba, never served stale."""

from __future__ import annotations

import importlib.util
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from moveplan.core import _native

KERNEL = '''import numba


@numba.njit(cache=True)
def scaled(values, factor):
    out = values.copy()
    for k in range(len(values)):
        out[k] = values[k] * factor + OFFSET
    return out


OFFSET = {offset}
'''
SIGNATURES = {"scaled": "float64[::1](float64[::1], float64)"}


def _kernel_file(folder: Path, offset: float) -> Path:
    """Return a kernel file in a package folder of its own, its constant `offset`."""
    folder.mkdir(exist_ok=True)
    source = folder / "kern.py"
    source.write_text(KERNEL.format(offset=offset))
    return source


def _dispatchers(source: Path) -> Any:
    """Return what `_native.build` asks for: the file's numba dispatchers, by exported name."""
    def dispatchers() -> dict[str, Any]:
        spec = importlib.util.spec_from_file_location(f"kern_{abs(hash(source.read_text()))}", source)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return {"scaled": module.scaled}
    return dispatchers


@pytest.fixture(autouse=True)
def _beside_the_source(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)  # built in the package's __pycache__, as numba caches


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Return a package folder whose kernel file is built ahead of time (in its __pycache__)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.delenv("NUMBA_CACHE_DIR", raising=False)
        source = _kernel_file(tmp_path_factory.mktemp("built") / "pkg", 0.5)
        assert not _native.built("demo", [source], SIGNATURES)
        assert _native.build("demo", [source], SIGNATURES, _dispatchers(source)) is not None
        assert _native.built("demo", [source], SIGNATURES)
    return source.parent


def test_a_built_module_loads_in_a_fresh_process_without_numba_and_computes_as_numba_does(built: Path) -> None:
    code = ("import sys\nimport numpy as np\nfrom pathlib import Path\nfrom moveplan.core import _native\n"
            f"module = _native.load('demo', [Path({str(built / 'kern.py')!r})], {SIGNATURES!r})\n"
            "print(module.scaled(np.array([1.0, 2.0]), 3.0).tolist(), 'numba' in sys.modules)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[3.5, 6.5] False"
    assert _dispatchers(built / "kern.py")()["scaled"](np.array([1.0, 2.0]), 3.0).tolist() == [3.5, 6.5]


def test_a_changed_kernel_file_is_built_again_not_served_stale(built: Path, tmp_path: Path) -> None:
    folder = tmp_path / "pkg"
    shutil.copytree(built, folder)
    source = _kernel_file(folder, 0.5)
    assert _native.load("demo", [source], SIGNATURES) is not None  # the copy's module, for the same bytes
    _kernel_file(folder, 2.0)  # a constant compiled in, as a kernel's inputs are
    assert _native.load("demo", [source], SIGNATURES) is None
    assert _native.kernels("demo", [source], SIGNATURES, _dispatchers(source)).scaled(np.ones(1), 1.0).tolist() == [3.0]
    assert len(list((folder / "__pycache__").glob("demo_*.so"))) == 1  # the stale one removed


def test_a_damaged_module_is_refused_not_loaded(built: Path, tmp_path: Path) -> None:
    shutil.copytree(built, tmp_path / "pkg")
    source = tmp_path / "pkg" / "kern.py"
    (module,) = (tmp_path / "pkg" / "__pycache__").glob("demo_*.so")
    damaged = module.with_name("damaged")
    damaged.write_bytes(module.read_bytes()[:1000])  # truncated, as by a full disk
    damaged.replace(module)  # a new file: this process has the old one mapped
    # A fresh process, as the next command: loading a truncated shared object would kill it (SIGBUS).
    code = (f"from pathlib import Path\nfrom moveplan.core import _native\n"
            f"print(_native.load('demo', [Path({str(source)!r})], {SIGNATURES!r}))")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "None"  # and `kernels` builds it again, as on first use


def test_a_failed_build_is_said_once_and_numbas_jit_serves_the_kernels(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    source = _kernel_file(tmp_path / "pkg", 0.5)
    monkeypatch.setenv("CC", str(tmp_path / "no-such-compiler"))
    monkeypatch.setattr(_native, "_SAID", set())  # as in a fresh process
    with caplog.at_level("WARNING", logger="moveplan.core._native"):
        first = _native.kernels("demo", [source], SIGNATURES, _dispatchers(source))
        second = _native.kernels("demo", [source], SIGNATURES, _dispatchers(source))
    assert [record.levelname for record in caplog.records] == ["WARNING"]
    assert "not compiled ahead of time" in caplog.records[0].getMessage()
    assert _native.failed("demo", [source], SIGNATURES) and not _native.built("demo", [source], SIGNATURES)
    for kernels in (first, second):
        assert type(kernels.scaled).__name__ == "CPUDispatcher"
        assert kernels.scaled(np.array([1.0, 2.0]), 3.0).tolist() == [3.5, 6.5]
