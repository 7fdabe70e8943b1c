"""The files of a recording: one MCAP or rosbag2 sqlite3 (.db3) file, or a rosbag2 bag folder's splits.

A bag folder is what `ros2 bag record` writes: metadata.yaml, whose
rosbag2_bagfile_information.relative_file_paths lists the split files in order
(NAME_0.db3, NAME_1.db3, ... for Humble's default sqlite3 storage; .mcap for Jazzy's),
and the splits. A folder without metadata.yaml (a recorder that never closed the bag
writes it last) is read by its split files' names: NAME_0, NAME_1, ..., NAME_10 in order.
A file is told by its first bytes, not its name: the MCAP magic or the SQLite header.
"""

from __future__ import annotations

import re
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from ...config import load_yaml
from ...errors import InputError

__all__ = ["MCAP_MAGIC", "SQLITE_HEADER", "BagFile", "Storage", "bag_files", "check_regular", "split_order"]

MCAP_MAGIC = b"\x89MCAP0\r\n"
SQLITE_HEADER = b"SQLite format 3\x00"

Storage = Literal["mcap", "sqlite3"]
_SUFFIXES = {".mcap": "mcap", ".db3": "sqlite3"}


@dataclass(frozen=True)
class BagFile:
    """One file of a recording and its storage kind."""

    path: Path
    storage: Storage


def bag_files(source: Path) -> list[BagFile]:
    """Return the files of a recording in reading order: `source` itself, or a bag folder's splits.

    Raises:
        InputError: `source` is missing or unreadable, a file is neither MCAP nor SQLite,
            a folder holds no recording, or its metadata.yaml names a missing file or a
            compressed bag.

    """
    if source.is_dir():
        metadata = source / "metadata.yaml"
        paths = _listed(source, metadata) if metadata.is_file() else _found(source)
        return [BagFile(path, storage_of(path)) for path in paths]
    return [BagFile(source, storage_of(source))]


def storage_of(path: Path) -> Storage:
    """Return the storage kind of the file at `path`, told by its first bytes.

    Raises:
        InputError: The file is missing, unreadable, a folder, a device or pipe, or neither
            MCAP nor SQLite.

    """
    check_regular(path)
    try:
        with path.open("rb") as stream:
            head = stream.read(len(SQLITE_HEADER))
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    except IsADirectoryError:
        raise InputError(f"{path}: is a folder; give the .mcap file inside it") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror or exc}") from None
    if head.startswith(MCAP_MAGIC):
        return "mcap"
    if head == SQLITE_HEADER:
        return "sqlite3"
    if path.suffix == ".db3":
        raise InputError(f"{path}: not a rosbag2 sqlite3 file (it does not start with the "
                         "SQLite header)")
    raise InputError(f"{path}: not an MCAP file (it does not start with the MCAP magic)")


_KINDS = ((stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a pipe"),
          (stat.S_ISSOCK, "a socket"))


def check_regular(path: Path) -> None:
    """Raise InputError unless `path` is a regular file (or a folder, which the caller tells apart).

    A device or pipe is refused before it is opened: /dev/zero never ends, a pipe without a
    writer blocks the open itself, and neither can be read twice or from its end.
    """
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        raise InputError(f"{path}: file not found") from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror or exc}") from None
    kind = next((name for test, name in _KINDS if test(mode)), None)
    if kind is not None:
        raise InputError(f"{path}: not a regular file ({kind}); give an .mcap or .db3 file, or a bag folder")


def split_order(path: Path) -> tuple[str, int]:
    """Return a sort key putting rosbag2 splits name_0, name_1, ..., name_10 in order."""
    match = re.fullmatch(r"(.*?)(\d+)", path.stem)
    return (match.group(1), int(match.group(2))) if match else (path.stem, -1)


def _found(folder: Path) -> list[Path]:
    """Return a folder's .mcap and .db3 files in split order."""
    files = sorted((p for p in folder.iterdir() if p.suffix in _SUFFIXES and p.is_file()),
                   key=split_order)
    if not files:
        raise InputError(f"{folder}: folder holds no .mcap or .db3 file (and no metadata.yaml)")
    return files


def _listed(folder: Path, metadata: Path) -> list[Path]:
    """Return the split files metadata.yaml lists, in its order."""
    info = _information(metadata)
    mode = str(info.get("compression_mode") or "").upper()
    if mode not in ("", "NONE"):
        raise InputError(
            f"{metadata}: the bag is compressed (compression_mode {mode}, format "
            f"{info.get('compression_format') or '?'}); moveplan reads uncompressed bags: "
            "decompress it first (ros2 bag convert, or zstd -d on each split for FILE mode)")
    names = info.get("relative_file_paths")
    if not isinstance(names, list) or not names or not all(isinstance(n, str) and n.strip() for n in names):
        raise InputError(f"{metadata}: rosbag2_bagfile_information.relative_file_paths: expected "
                         "a list of file names")
    paths: list[Path] = []
    for name in names:
        path = _split(folder, metadata, name)
        if any(path.samefile(other) for other in paths):
            # Read twice, its messages would count twice and seem to go back in time.
            raise InputError(f"{metadata}: lists {name} twice (relative_file_paths); each split is read once")
        paths.append(path)
    return paths


def _split(folder: Path, metadata: Path, name: str) -> Path:
    """Return the split file `name` of metadata.yaml's list: a file inside the bag folder, not metadata.yaml."""
    if Path(name).is_absolute() or ".." in Path(name).parts:
        raise InputError(f"{metadata}: lists {name}, outside the bag folder {folder}; a bag's "
                         "relative_file_paths name files inside it")
    # Bags before version 4 name their files relative to the folder's parent.
    candidates = [folder / name, folder.parent / name, folder / Path(name).name]
    path = next((c for c in candidates if c.is_file()), None)
    if path is None:
        raise InputError(f"{metadata}: lists {name}, which is not in {folder}")
    if path.samefile(metadata):
        raise InputError(f"{metadata}: lists itself as a split file ({name}); relative_file_paths "
                         "name the .db3 or .mcap files beside it")
    return path


def _information(metadata: Path) -> dict[str, Any]:
    """Return the rosbag2_bagfile_information mapping of a metadata.yaml."""
    content = load_yaml(metadata)
    info = content.get("rosbag2_bagfile_information") if isinstance(content, dict) else None
    if not isinstance(info, dict):
        raise InputError(f"{metadata}: not a rosbag2 metadata.yaml (no "
                         "rosbag2_bagfile_information mapping)")
    return info
