"""`moveplan scene`: any scene moveplan reads, written as MoveIt's text `.scene` (what RViz's Import reads).

The scene is resolved against the robot first, so that objects given in scene frames or on robot
links are written where they are in the planning frame; attached objects are left out (a `.scene`
file holds world objects only), and so are subframes, each with a warning.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from ..bag import atomic_file
from ..collision import inline_mesh
from ..config import format_scene_text
from ..errors import UsageError
from ..model import Robot, load_scene
from .request import RobotSource

__all__ = ["SceneExport", "check_scene_path", "export_scene", "scene_document"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class SceneExport:
    """A scene written as a `.scene` file.

    Attributes:
        scene: The scene file read.
        output: The `.scene` file written.
        robot: The robot config's name.
        name: The scene name written: the one its file gives, else the file's stem.
        planning_frame: The frame of every pose written (the URDF root link).
        objects: The ids of the world objects written, in order.
        skipped: The ids of the attached objects left out.
    """

    scene: Path
    output: Path
    robot: str
    name: str
    planning_frame: str
    objects: tuple[str, ...]
    skipped: tuple[str, ...]


def check_scene_path(path: Path, flag: str = "-o") -> None:
    """Refuse an output name not ending in .scene, which moveplan and RViz would not read as a scene; return None."""
    if path.suffix != ".scene":
        raise UsageError(f"{flag} '{path}': expected a file name ending in .scene (MoveIt's text scene format)")


def export_scene(scene: Path, robot: RobotSource, output: Path) -> SceneExport:
    """Return what was written, after writing the scene at `scene`, resolved against the robot, to `output`.

    The file is written atomically: on any error `output` is left as it was.

    Raises:
        UsageError: `output` does not end in .scene, or cannot be an output file.
        InputError: The robot config or the scene is invalid, a mesh unreadable, or `output` cannot be written.
    """
    check_scene_path(output)
    model = Robot(robot.load())
    loaded = load_scene(scene, model)
    skipped = tuple(loaded.object_groups(attached=True))
    if skipped:
        logger.warning("%s: attached objects not written (%s): a .scene file holds world objects only",
                       loaded.source, ", ".join(skipped))
    objects = {object_id: tuple(replace(part, shape=inline_mesh(part.shape, f"{loaded.source}: object '{object_id}'"))
                                for part in parts)
               for object_id, parts in loaded.object_groups().items()}
    if subframes := [name for object_id in objects for name in loaded.subframes.get(object_id, ())]:
        logger.warning("%s: subframes not written (%s): moveplan writes objects without them", loaded.source,
                       ", ".join(subframes))
    name = loaded.name or scene.stem
    text = format_scene_text(name, objects, loaded.source)
    with atomic_file(output) as stream:
        stream.write(text.encode())
    return SceneExport(scene, output, model.config.name, name, model.root_link, tuple(objects), skipped)


def scene_document(result: SceneExport) -> dict[str, Any]:
    """Return the document of a scene written as `.scene`: files, robot, name, frame, objects written and left out."""
    return {"ok": True, "scene": str(result.scene), "output": str(result.output), "robot": result.robot,
            "name": result.name, "planning_frame": result.planning_frame, "objects": list(result.objects),
            "skipped": list(result.skipped), "error": None}
