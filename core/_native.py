"""numba kernels compiled ahead of time into an extension module, loaded in milliseconds without numba.

numba's own disk cache still costs a fresh process 0.5-0.7 s before the first kernel runs: importing
numba (~0.3 s), its typing and lowering registries (which import scipy.linalg for BLAS), then
each kernel's machine code. Too much for a one-shot plan whose step takes milliseconds, so such a
plan did without the sphere filter. numba's `pycc` compiles the same Python functions through the
same pipeline into a plain CPython extension module: imported in ~2 ms, no numba at run time,
the same numbers (tests/foundation/test_native_kernels.py).

A kernel set is built once per install (~35 s for both; numba's own compilation took ~20 s) and
kept where numba keeps its cache for that package (beside the source in __pycache__, or under
NUMBA_CACHE_DIR): the same trust as numba's cache, never moveplan's own cache folder, whose
entries are data only (docs/formats.md). Its file name carries a hash of the kernel sources and signatures, so a
changed source is never served stale code. Where no module can be built (no C compiler, a numba
without pycc) the caller falls back to numba's JIT: the same functions, the same numbers, and
numba's start-up cost.
"""

from __future__ import annotations

import hashlib
import importlib.machinery
import importlib.util
import logging
import os
import tempfile
import warnings
from collections.abc import Callable, Mapping, Sequence
from functools import cache
from pathlib import Path
from types import ModuleType, SimpleNamespace
from typing import Any

__all__ = ["build", "built", "cache_folder", "failed", "kernels", "load"]

logger = logging.getLogger(__name__)

Signatures = Mapping[str, str]
"""Per exported name, the numba signature it is compiled for: the types its callers pass, exactly."""
Dispatchers = Callable[[], Mapping[str, Any]]
"""Returns, per exported name, its numba dispatcher: asked for only when needed, since it imports numba."""
_SAID: set[str] = set()  # why builds failed in this process, each warned about once


def kernels(name: str, sources: Sequence[Path], signatures: Signatures, dispatchers: Dispatchers) -> Any:
    """Return the kernels by exported name: the built module, else one built now, else numba's JIT dispatchers."""
    module = load(name, sources, signatures) or build(name, sources, signatures, dispatchers)
    return module if module is not None else SimpleNamespace(**dispatchers())


def cache_folder(package: Path) -> Path | None:
    """Return the folder numba caches a package folder's kernels in (its first two locators), or None."""
    configured = os.environ.get("NUMBA_CACHE_DIR")
    if configured:
        return Path(configured) / f"{package.name}_{hashlib.sha1(str(package).encode()).hexdigest()}"
    if os.access(package, os.W_OK):
        return package / "__pycache__"
    return None


def _module_name(name: str, sources: Sequence[Path], signatures: Signatures) -> str:
    """Return the extension module's name: `name` and a hash of the sources' bytes and the signatures."""
    digest = hashlib.sha256(repr(sorted(signatures.items())).encode())
    for source in sources:
        status = source.stat()
        digest.update(_file_digest(str(source), status.st_mtime_ns, status.st_size))
    return f"{name}_{digest.hexdigest()[:16]}"


@cache
def _file_digest(file: str, mtime_ns: int, size: int) -> bytes:
    """Return the sha256 of a file's bytes; keyed by its time and size too, read again once it changes."""
    return hashlib.sha256(Path(file).read_bytes()).digest()


def _where(name: str, sources: Sequence[Path], signatures: Signatures) -> tuple[str, Path] | None:
    """Return the module's name and file, in the cache folder of the first source's package; None if none.

    None too where the sources cannot be read.
    """
    folder = cache_folder(sources[0].parent)
    if folder is None:
        return None
    try:
        module = _module_name(name, sources, signatures)
    except OSError:
        return None
    # The interpreter's own extension suffix (ABI and platform): sysconfig's would cost 5 ms to initialise.
    return module, folder / f"{module}{importlib.machinery.EXTENSION_SUFFIXES[0]}"


def built(name: str, sources: Sequence[Path], signatures: Signatures) -> bool:
    """Return True if the module for these sources and signatures is built, without loading it."""
    where = _where(name, sources, signatures)
    return where is not None and where[1].is_file()


def failed(name: str, sources: Sequence[Path], signatures: Signatures) -> bool:
    """Return True if building the module for these sources and signatures failed here: numba's JIT serves them."""
    where = _where(name, sources, signatures)
    return where is not None and _failure_mark(*where).is_file()


def _checksum(path: Path) -> Path:
    """Return the file holding the sha256 of the built module at `path`."""
    return path.with_name(f"{path.name}.sha256")


def _intact(path: Path) -> bool:
    """Return True if the module at `path` has the bytes its build wrote (~1 ms a megabyte).

    A truncated shared object is not refused by the loader: it kills the process (SIGBUS) when
    its missing pages are touched.
    """
    try:
        return _checksum(path).read_text().strip() == hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError:
        return False


def _remove_stale(name: str, module_name: str, folder: Path) -> None:
    """Remove the modules of `name` built for other sources (an upgrade, an edit) from `folder`; return None.

    A process still running one keeps it: the file goes, its mapping stays.
    """
    for stale in folder.glob(f"{name}_*"):
        if not stale.name.startswith(f"{module_name}."):
            stale.unlink(missing_ok=True)


def _failure_mark(module_name: str, path: Path) -> Path:
    """Return the file that marks a failed build of the module."""
    return path.with_name(f"{module_name}.failed")


def load(name: str, sources: Sequence[Path], signatures: Signatures) -> ModuleType | None:
    """Return the built module for these sources and signatures, imported; None if it is not built or will not load."""
    where = _where(name, sources, signatures)
    if where is None or not where[1].is_file():
        return None
    module_name, path = where
    if not _intact(path):
        logger.debug("compiled kernels %s are damaged or incomplete: built again", path)
        return None
    loader = importlib.machinery.ExtensionFileLoader(module_name, str(path))
    spec = importlib.util.spec_from_file_location(module_name, path, loader=loader)
    if spec is None or spec.loader is None:  # pragma: no cover - an extension file always gets a spec
        return None
    try:
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    except ImportError as exc:  # a file another Python or platform wrote, or damaged: rebuilt, or the JIT serves
        logger.debug("compiled kernels %s do not load: %s", path, exc)
        return None
    return module


def build(name: str, sources: Sequence[Path], signatures: Signatures, dispatchers: Dispatchers) -> ModuleType | None:
    """Compile the dispatchers' functions into the module for `sources` and `signatures`; return it loaded.

    Returns None where it cannot be built (no writable cache folder, no C compiler or Python
    headers, a numba without pycc): the caller then runs numba's JIT. A failed build is marked and
    not tried again for these sources. Concurrent builders each compile in a folder of their own
    and rename the result: the file is always complete.
    """
    where = _where(name, sources, signatures)
    if where is None:
        return None
    module_name, path = where
    mark = _failure_mark(module_name, path)
    if mark.exists():
        return None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # pycc is pending deprecation in numba; it is what loads without numba
            from numba.pycc import CC  # type: ignore[attr-defined]

            compiler = CC(module_name, source_module=__name__)  # type: ignore[no-untyped-call]
        with tempfile.TemporaryDirectory(prefix=f".{module_name}.", dir=path.parent) as scratch:
            compiler.output_dir = scratch
            for exported, dispatcher in dispatchers().items():
                compiler.export(exported, signatures[exported])(dispatcher.py_func)  # type: ignore[no-untyped-call]
            compiler.compile()
            staged = Path(scratch) / path.name
            Path(scratch, _checksum(path).name).write_text(hashlib.sha256(staged.read_bytes()).hexdigest())
            os.replace(staged, path)
            os.replace(Path(scratch, _checksum(path).name), _checksum(path))
        _remove_stale(name, module_name, path.parent)
    except Exception as exc:  # noqa: BLE001 - whatever stops an optional build, numba's JIT does the work
        # The first sentence: numba's own message goes on with advice for conda.
        reason = str(exc).strip().splitlines()[0].split(". ")[0] if str(exc).strip() else type(exc).__name__
        # Said once per process: without a compiler every kernel set fails alike.
        logger.log(logging.DEBUG if reason in _SAID else logging.WARNING,
                   "kernels %s not compiled ahead of time (%s): numba's JIT runs them, which adds ~0.7 s to every "
                   "process that plans with them; with a C compiler and Python's headers, remove %s to try again",
                   module_name, reason, mark)
        _SAID.add(reason)
        try:
            mark.write_text(f"{exc}\n")
        except OSError:
            pass
        return None
    return load(name, sources, signatures)
