"""The ``exchange`` family: light between two surfaces, a receiving patch
under rectangle, disk and triangle lights with occluders (R-3P and R-A over
both surfaces). Everything the harness knows about it: reading its
``scene``, its quantities, the Mitsuba 3 scene and the computation.

lightquad computes each value by three forms of one integral (``_area``,
``_cone``, ``_contour``); Mitsuba computes the value once for every form.

How Mitsuba computes it: an ``irradiancemeter`` sensor on the receiving
shape (a ``rectangle``, ``disk`` or one-triangle OBJ with the receiving
side's normal) samples a point uniformly on the shape and a cosine-weighted
direction about its normal, weighting the radiance found there by pi: its
expectation is the mean irradiance over the receiver, ``E_mean = (1/A_r)
int E dA``. The ``path`` integrator with ``max_depth`` 1 returns the
radiance of the emitter a ray meets first (the lights' and occluders'
BSDFs are black, as lightquad's lights and occluders reflect nothing). Then

* ``E_mean_*`` is that mean;
* ``Phi_*`` is ``A_r E_mean``;
* ``F_*`` is ``E_mean / pi`` of the same scene with every light's radiance
  set to 1: the form factor from the receiver to the lights, whatever their
  radiances.

As in the rendering family the scene is moved to the receiver's centre and
scaled by ``SCALE`` (the sensor starts its rays ``8.9e-5 (1 + max|p|)``
along them, Mitsuba's ray epsilon; scaling keeps that small beside the
scene); a mean irradiance depends only on directions, so it does not change.
"""

import math
import tempfile
from dataclasses import dataclass

import numpy as np

from ..mitsuba3 import mean_of_renders, require_mitsuba
from ..spec import SpecError, number, vec3
from .rendering import LARGEST_RADIANCE, _check_shape, _list, _shape

FORMS = ("area", "cone", "contour")
QUANTITIES = tuple(f"{v}_{f}" for v in ("F", "Phi", "E_mean") for f in FORMS)
SHAPES = ("rectangle", "disk", "triangle")
OCCLUDER_TYPES = ("rectangle", "disk", "triangle", "sphere")

SCALE = 1000.0
"""The factor the scene is scaled by about the receiver's centre."""


@dataclass
class Scene:
    receiver: dict  # the file's dict, checked
    centre: tuple  # the receiver's centroid
    area: float
    emitters: list
    occluders: list


def _centre_and_area(r):
    kind = r["type"]
    if kind == "rectangle":
        o, eu, ev = (np.asarray(r[k], dtype=np.float64) for k in ("origin", "edge_u", "edge_v"))
        return o + (eu + ev) / 2, float(np.linalg.norm(np.cross(eu, ev)))
    if kind == "disk":
        return np.asarray(r["centre"], dtype=np.float64), math.pi * float(r["radius"]) ** 2
    a, b, c = (np.asarray(r[k], dtype=np.float64) for k in ("a", "b", "c"))
    return (a + b + c) / 3, 0.5 * float(np.linalg.norm(np.cross(b - a, c - a)))


def read_scene(scene) -> Scene:
    """The ``scene`` object of an exchange experiment file."""
    if not isinstance(scene, dict):
        raise SpecError("scene", f"expected an object, got {scene!r}")
    r = scene.get("receiver")
    if not isinstance(r, dict) or r.get("type") not in SHAPES:
        raise SpecError("scene.receiver.type",
                        f"unknown receiving surface {r!r}; known: {', '.join(SHAPES)}")
    _check_shape(r, "scene.receiver")
    emitters = _list(scene.get("emitters"), "scene.emitters")
    if not emitters:
        raise SpecError("scene.emitters", "an empty list: give at least one emitter")
    for k, e in enumerate(emitters):
        path = f"scene.emitters[{k}]"
        if not isinstance(e, dict) or e.get("type") not in SHAPES:
            raise SpecError(f"{path}.type",
                            f"unknown emitter {e!r}; known: {', '.join(SHAPES)}")
        number(e.get("radiance"), f"{path}.radiance", 0.0, LARGEST_RADIANCE)
        _check_shape(e, path)
    occluders = _list(scene.get("occluders"), "scene.occluders")
    for k, o in enumerate(occluders):
        path = f"scene.occluders[{k}]"
        if not isinstance(o, dict) or o.get("type") not in OCCLUDER_TYPES:
            raise SpecError(f"{path}.type",
                            f"unknown occluder {o!r}; known: {', '.join(OCCLUDER_TYPES)}")
        _check_shape(o, path)
    centre, area = _centre_and_area(r)
    return Scene(r, tuple(centre), area, list(emitters), list(occluders))


class Settings:
    """Sample counts: full accuracy, or ``quick`` for a smoke run."""

    def __init__(self, quick: bool = False):
        self.quick = quick
        self.passes = 64 if quick else 16384  # renders, averaged in float64
        self.spp = 4096  # per render

    def as_dict(self):
        return {"mode": "quick" if self.quick else "full", "passes": self.passes,
                "spp_per_pass": self.spp, "scale": SCALE}


def require_expressible(exp):
    """Every exchange scene is expressible (checked by read_scene)."""
    return None


def unsupported_reason(exp, quantity):
    """Every quantity is computed."""
    return None


def build_scene(exp, tmp, unit_radiance, spp):
    """The Mitsuba scene: lights, occluders and the receiving shape with its
    irradiance meter, in scaled coordinates about the receiver's centre."""
    mi, _ = require_mitsuba()
    s = exp.scene
    black = {"type": "diffuse", "reflectance": 0.0}
    parts = {"type": "scene", "integrator": {"type": "path", "max_depth": 1}}
    for k, e in enumerate(s.emitters):
        shape = _shape(e, s.centre, f"scene.emitters[{k}]", tmp)
        radiance = 1.0 if unit_radiance else float(e["radiance"])
        shape["emitter"] = {"type": "area", "radiance": radiance}
        shape["bsdf"] = black
        parts[f"emitter{k}"] = shape
    for k, o in enumerate(s.occluders):
        shape = _shape(o, s.centre, f"scene.occluders[{k}]", tmp)
        shape["bsdf"] = black
        parts[f"occluder{k}"] = shape
    receiver = _shape(s.receiver, s.centre, "scene.receiver", tmp)
    receiver["bsdf"] = black
    receiver["sensor"] = {
        "type": "irradiancemeter",
        "film": {"type": "hdrfilm", "width": 1, "height": 1, "rfilter": {"type": "box"},
                 "pixel_format": "rgb", "component_format": "float32"},
        "sampler": {"type": "independent", "sample_count": spp}}
    parts["receiver"] = receiver
    return mi.load_dict(parts)


def mean_irradiance(exp, settings, unit_radiance):
    """Mitsuba's mean irradiance over the receiver, and its standard error."""
    with tempfile.TemporaryDirectory() as tmp:
        scene = build_scene(exp, tmp, unit_radiance, settings.spp)
        return mean_of_renders(scene, settings.passes, settings.spp, exp.seed)


def compute(exp, quantity, settings):
    """``F``, ``Phi`` or ``E_mean`` (each computed once per experiment object
    and settings, and reused by the other forms)."""
    value_name = quantity.rsplit("_", 1)[0]
    unit = value_name == "F"
    cache = exp.__dict__.setdefault("_exchange_values", {})
    key = (unit, settings.passes, settings.spp)
    if key not in cache:
        cache[key] = mean_irradiance(exp, settings, unit)
    e, se = cache[key]
    scale = {"F": 1.0 / math.pi, "Phi": exp.scene.area, "E_mean": 1.0}[value_name]
    what = {"F": "E_mean / pi with every light's radiance 1",
            "Phi": f"A_r E_mean (A_r = {exp.scene.area:.17g})",
            "E_mean": "E_mean"}[value_name]
    return {
        "value": scale * e,
        "std_error": scale * se,
        "samples": int(settings.passes * settings.spp),
        "method": f"Mitsuba irradiancemeter on the receiving shape (a uniform point and a "
                  f"cosine-weighted direction per sample), path integrator with max_depth 1 "
                  f"(the emitted radiance met first): {what}; the scene moved to the "
                  f"receiver's centre and scaled by {SCALE:g}; float64 mean of "
                  f"{settings.passes} renders of {settings.spp} spp, standard error over "
                  f"renders",
        "form": f"{quantity} is the same integral as every other {value_name}_* form: one "
                f"value for all",
    }
