"""Reading a lightquad experiment file (the format of /README.md and
src/experiment/spec.rs) into the few things the Mitsuba harness needs.

This is not a validator: ``lightquad check FILE`` is. Only what the harness
uses is read and checked here, with the JSON path in every error.
"""

import json
import math
from dataclasses import dataclass, field
from typing import Optional

QUANTITIES = ("tau", "I_E", "I_B", "I_L", "I")
MEDIUM_TYPES = ("constant-sphere", "gaussian-blobs", "linear-gradient", "voxel-grid")


class SpecError(ValueError):
    """A fault in an experiment file, or a scene element Mitsuba cannot express;
    the message names the JSON path."""

    def __init__(self, path: str, message: str):
        super().__init__(f"at `{path}`: {message}")
        self.path = path


@dataclass
class Light:
    toward_light: tuple  # unit vector from a point toward the light
    intensity: float  # I_p
    albedo: Optional[float]  # None: the document's reduced V-L


@dataclass
class Experiment:
    name: str
    path: str
    origin: tuple
    direction: tuple  # normalised: t is arc length, as in lightquad
    t_min: float
    t_max: float
    medium: Optional[dict]
    lam: float  # lambda in sigma = lambda * v_r
    emission: Optional[dict]
    background: Optional[float]
    light: Optional[Light]
    quantities: list
    seed: int
    raw: dict = field(repr=False, default_factory=dict)


def _vec3(value, path):
    if not (isinstance(value, list) and len(value) == 3 and all(_is_num(x) for x in value)):
        raise SpecError(path, f"expected three numbers, got {value!r}")
    return tuple(float(x) for x in value)


def _is_num(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _unit(v, path):
    n = math.sqrt(sum(x * x for x in v))
    if not n > 0.0:
        raise SpecError(path, f"expected a non-zero vector, got {list(v)}")
    return tuple(x / n for x in v)


def load(path) -> Experiment:
    """Reads the experiment file at ``path``."""
    with open(path, "rb") as f:
        raw = json.loads(f.read().decode("utf-8"))
    if not isinstance(raw, dict):
        raise SpecError(".", "an experiment file is a JSON object")
    for key in ("name", "scene", "quantities"):
        if key not in raw:
            raise SpecError(key, "missing field")
    scene = raw["scene"]
    if "ray" not in scene:
        raise SpecError("scene.ray", "missing field")
    origin = _vec3(scene["ray"].get("origin"), "scene.ray.origin")
    direction = _unit(_vec3(scene["ray"].get("direction"), "scene.ray.direction"),
                      "scene.ray.direction")
    t_min = 0.0 if scene.get("t_min") is None else float(scene["t_min"])
    t_max = math.inf if scene.get("t_max") is None else float(scene["t_max"])

    medium = scene.get("medium")
    if medium is not None and medium.get("type") not in MEDIUM_TYPES:
        raise SpecError("scene.medium.type", f"unknown medium type {medium.get('type')!r}")

    light = None
    if scene.get("light") is not None:
        l = scene["light"]
        light = Light(
            toward_light=_unit(_vec3(l.get("toward_light"), "scene.light.toward_light"),
                               "scene.light.toward_light"),
            intensity=float(l["intensity"]),
            albedo=None if l.get("albedo") is None else float(l["albedo"]),
        )

    quantities = list(raw["quantities"])
    for i, q in enumerate(quantities):
        if q not in QUANTITIES:
            raise SpecError(f"quantities[{i}]", f"unknown quantity {q!r}; known: {QUANTITIES}")

    lam = scene.get("lambda")
    return Experiment(
        name=str(raw["name"]),
        path=str(path),
        origin=origin,
        direction=direction,
        t_min=t_min,
        t_max=t_max,
        medium=medium,
        lam=1.0 if lam is None else float(lam),
        emission=scene.get("emission"),
        background=scene.get("background"),
        light=light,
        quantities=quantities,
        seed=int(raw.get("seed", 0)),
        raw=raw,
    )
