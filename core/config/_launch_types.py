"""Controller types a package's launch files hand the spawner, read without running them.

PAL's TIAGo keeps one controller a file with no controller_manager section: its type is an
argument of the launch file that loads it (`generate_load_controller_launch_description(
controller_name='arm_controller', controller_type='joint_trajectory_controller/...',
controller_params_file=os.path.join(..., 'arm_controller.yaml'))`). The Python launch files of the
package holding the parameter file are parsed (ast, never executed) for calls whose keywords name
a controller, its type and a params file ending in the file's name.
"""

from __future__ import annotations

import ast
import logging
from pathlib import Path

from ..errors import ConfigError
from .fields import read_input_text

__all__ = ["spawned_types"]

logger = logging.getLogger(__name__)

_MAX_LAUNCH_FILES = 200  # a package's launch folder holds tens; past this, none is read


def spawned_types(params_file: Path) -> dict[str, str]:
    """Return controller name -> type that the launch files of `params_file`'s package give it with that file."""
    package = next((folder for folder in params_file.resolve().parents if (folder / "package.xml").is_file()), None)
    if package is None or not (package / "launch").is_dir():
        return {}
    files = sorted((package / "launch").glob("*.launch.py"))[:_MAX_LAUNCH_FILES]
    found: dict[str, str] = {}
    for launch in files:
        try:
            tree = ast.parse(read_input_text(launch), str(launch))
        except (SyntaxError, ConfigError, ValueError):
            continue  # a launch file moveplan cannot read names no type; the controller stays unknown
        for call in (node for node in ast.walk(tree) if isinstance(node, ast.Call)):
            keywords = {k.arg: k.value for k in call.keywords if k.arg}
            name, kind = _text(keywords.get("controller_name")), _text(keywords.get("controller_type"))
            params = keywords.get("controller_params_file")
            if name and kind and params is not None and _names_file(params, params_file.name):
                found.setdefault(name, kind)
                logger.debug("%s: controller %s is a %s", launch, name, kind)
    return found


def _text(node: ast.expr | None) -> str:
    """Return a string literal's text, "" for anything else."""
    return node.value if isinstance(node, ast.Constant) and isinstance(node.value, str) else ""


def _names_file(node: ast.expr, name: str) -> bool:
    """Return True if a string literal within `node` (a path expression) ends in the file's name."""
    return any(isinstance(part, ast.Constant) and isinstance(part.value, str) and part.value.endswith(name)
               for part in ast.walk(node))
