"""The hardware a robot config's motions execute on in simulation: moveplan.yaml's `plant`.

    plant:
      model: pid            # mirror (state = command), lag (first order) or pid (drive and inertia)
      drive_tau: 0.1        # [s] and the other parameters of `--plant-param`, for all joints ...
      load.wrist_joint: 0.05   # ... or one joint

`execute --fake` and `tune-pid` run on it unless `--plant` names another; `--plant-param`
overrides its parameters one by one. The parameters are checked against the model where the
plant is built (core/control/plants), as `--plant-param` is.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..errors import ConfigError, known
from .fields import mapping, number

__all__ = ["PLANT_MODELS", "PlantSettings", "parse_plant"]

PLANT_MODELS = ("mirror", "lag", "pid")
"""The simulated hardware models, the default first."""


@dataclass(frozen=True)
class PlantSettings:
    """A plant model and its parameters (name -> value, `name.<joint>` for one joint)."""

    model: str = "mirror"
    params: dict[str, float] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        """Return the settings as moveplan.yaml writes them."""
        return {"model": self.model, **self.params}


def parse_plant(value: Any, where: str) -> PlantSettings | None:
    """Return moveplan.yaml's `plant` mapping as settings, None without one; ConfigError naming the key."""
    if value is None:
        return None
    entry = mapping(value, where)
    model = entry.get("model", PLANT_MODELS[0])
    if model not in PLANT_MODELS:
        raise ConfigError(f"{where}.model: unknown plant {model!r}; known: {known(PLANT_MODELS)}")
    params = {str(key): number(item, f"{where}.{key}") for key, item in entry.items() if key != "model"}
    return PlantSettings(str(model), params)
