"""Package faces that load on first use: a district's names imported only when one is asked for (PEP 562).

Every command pays for what its imports load: writing a plan needs none of the bag readers
(sqlite3, the linear MCAP scan), `--help` none of pinocchio or numba. A face lists each name
it exports and the module that holds it; the module is imported when the name is first used.
"""

from collections.abc import Callable, Mapping
from importlib import import_module
from typing import Any

__all__ = ["lazy_exports"]


def lazy_exports(package: str, homes: Mapping[str, str]) -> Callable[[str], Any]:
    """Return a module `__getattr__` giving each name in `homes` from the submodule of `package` that holds it."""

    def __getattr__(name: str) -> Any:
        if name not in homes:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(import_module(f"{package}.{homes[name]}"), name)

    return __getattr__
