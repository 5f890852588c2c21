"""The ``rendering`` family: irradiance and reflected radiance at one receiving
point under area lights, with occluders (docs/EQUATIONS.md, R-H and R-A).
Everything the harness knows about it: reading its ``scene``, its quantities
and sample counts, the scene in Mitsuba 3, and the two computations.

lightquad evaluates each value by several forms of the same integral (``E_area``
over the lights' surfaces, ``E_hemisphere``, ``E_cosine``, ``E_cone`` over
directions; likewise ``L_*``); they are one number, and Mitsuba computes it once
per family of forms: irradiance ``E`` for every ``E_*`` quantity, reflected
radiance ``L`` for every ``L_*`` one.

How Mitsuba computes them:

* The receiver is a small disk at the receiving point, facing its ``normal``,
  with a ``diffuse`` BSDF; a 1x1 ``radiancemeter`` (box filter) looks at it
  from along ``toward_viewer`` (along the normal for irradiance), and the
  ``direct`` integrator (one emitter and one BSDF sample per pass, combined by
  MIS) gives the radiance it reflects. With reflectance 1 that radiance is
  ``E / pi``; with the BRDF's albedo ``rho`` it is ``L = rho / pi E``.
* Lights are ``area`` emitters on Mitsuba shapes (``rectangle`` with the
  parallelogram's edges as its transform, ``disk``, a one-triangle OBJ mesh,
  ``sphere``) or a ``constant`` environment, all one-sided with lightquad's
  orientation (rectangle ``edge_u x edge_v``, triangle ``(b - a) x (c - b)``,
  disk its normal, sphere outward). Every shape has a black ``diffuse`` BSDF:
  lightquad's lights and occluders reflect nothing.
* The scene is moved so the receiving point is the origin and scaled by
  ``SCALE`` = 1000. Irradiance and radiance depend only on directions, so
  neither changes. Mitsuba starts every ray it spawns from a surface about
  ``(1 + max|p|) 8.9e-5`` along the normal (its ray epsilon): at the file's
  own scale a light 1e-6 above the receiver (r-coaxial-disk-1e-6) is behind
  the shadow rays' origins and E comes out 0 (measured), where the scaled
  scene gives 3.1415936 +- 4e-7 against pi / (1 + 1e-12). On a scene without
  near surfaces the scaling changes nothing measurable (the tilted rectangle:
  0.2702180 and 0.2702177, both +- 1.4e-5, against 0.2702189).

Not expressible: a ``cap`` light (Mitsuba 3 has no light of a cone of
directions: ``directional`` is a delta, ``envmap`` a pixelised map). Not
computed: reflected radiance of a Phong lobe (Mitsuba 3 has no Phong BSDF) or of
lightquad's GGX (Mitsuba's ``roughconductor`` uses the separable Smith masking
``G1(wi) G1(wo)``, lightquad's GGX the height-correlated one: another BRDF).
"""

import math
import os
import tempfile
from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..mitsuba3 import mean_of_renders, require_mitsuba
from ..spec import SpecError, number, unit, vec3

QUANTITIES = ("E_hemisphere", "E_cosine", "E_cone", "E_area",
              "L_hemisphere", "L_cosine", "L_brdf", "L_cone", "L_area")
EMITTER_TYPES = ("rectangle", "disk", "triangle", "sphere", "environment", "cap")
OCCLUDER_TYPES = ("rectangle", "disk", "triangle", "sphere")
BRDF_TYPES = ("lambert", "phong", "normalized-phong", "ggx")

SCALE = 1000.0
"""The factor the scene is scaled by about the receiving point (module text)."""

NO_PHONG = ("Mitsuba 3 has no Phong BSDF (its BSDFs are diffuse, conductors, dielectrics, "
            "plastics and the principled one), so it has no counterpart of the documents' "
            "cos^n lobe")
NO_GGX = ("Mitsuba 3's roughconductor masks with the separable Smith term G1(wi) G1(wo); "
          "lightquad's GGX uses the height-correlated G2, a different BRDF (they differ by "
          "up to a few percent at grazing angles), so no value is computed")


# ----------------------------------------------------------------------------
# The scene


@dataclass
class Scene:
    point: tuple  # the receiving point x
    normal: tuple  # unit
    brdf: Optional[dict]
    toward_viewer: Optional[tuple]  # unit
    emitters: list  # the file's dicts, each checked
    occluders: list


LARGEST_RADIANCE = 1e30
"""The largest radiance accepted: float32 (Mitsuba) overflows near 3.4e38."""


def read_scene(scene) -> Scene:
    """The ``scene`` object of a rendering experiment file."""
    if not isinstance(scene, dict):
        raise SpecError("scene", f"expected an object, got {scene!r}")
    r = scene.get("receiver")
    if not isinstance(r, dict):
        raise SpecError("scene.receiver", f"expected an object, got {r!r}")
    point = vec3(r.get("point"), "scene.receiver.point")
    normal = unit(vec3(r.get("normal"), "scene.receiver.normal"), "scene.receiver.normal")
    viewer = r.get("toward_viewer")
    if viewer is not None:
        viewer = unit(vec3(viewer, "scene.receiver.toward_viewer"),
                      "scene.receiver.toward_viewer")
    brdf = r.get("brdf")
    if brdf is not None:
        if not isinstance(brdf, dict) or brdf.get("type") not in BRDF_TYPES:
            raise SpecError("scene.receiver.brdf.type",
                            f"unknown BRDF {brdf!r}; known: {', '.join(BRDF_TYPES)}")
        if brdf["type"] == "lambert":
            number(brdf.get("albedo"), "scene.receiver.brdf.albedo", 0.0, 1.0)

    emitters = _list(scene.get("emitters"), "scene.emitters")
    for k, e in enumerate(emitters):
        path = f"scene.emitters[{k}]"
        if not isinstance(e, dict) or e.get("type") not in EMITTER_TYPES:
            raise SpecError(f"{path}.type",
                            f"unknown emitter {e!r}; known: {', '.join(EMITTER_TYPES)}")
        number(e.get("radiance"), f"{path}.radiance", 0.0, LARGEST_RADIANCE)
        _check_shape(e, path)
    occluders = _list(scene.get("occluders"), "scene.occluders")
    for k, o in enumerate(occluders):
        path = f"scene.occluders[{k}]"
        if not isinstance(o, dict) or o.get("type") not in OCCLUDER_TYPES:
            raise SpecError(f"{path}.type",
                            f"unknown occluder {o!r}; known: {', '.join(OCCLUDER_TYPES)}")
        _check_shape(o, path)
    return Scene(point, normal, brdf, viewer, list(emitters), list(occluders))


def _list(value, path):
    if value is None:
        return []
    if not isinstance(value, list):
        raise SpecError(path, f"expected a list, got {value!r}")
    return value


def _check_shape(item, path):
    """The fields of a rectangle, disk, triangle or sphere: points, a
    radius > 0, a parallelogram or triangle of non-zero area."""
    kind = item["type"]
    if kind in ("disk", "sphere"):
        number(item.get("radius"), f"{path}.radius", 1e-300, 1e300)
        vec3(item.get("centre"), f"{path}.centre")
        if kind == "disk":
            unit(vec3(item.get("normal"), f"{path}.normal"), f"{path}.normal")
    elif kind == "rectangle":
        vec3(item.get("origin"), f"{path}.origin")
        eu = np.asarray(vec3(item.get("edge_u"), f"{path}.edge_u"))
        ev = np.asarray(vec3(item.get("edge_v"), f"{path}.edge_v"))
        if not np.linalg.norm(np.cross(eu, ev)) > 0.0:
            raise SpecError(path, "a parallelogram of zero area (parallel or zero edges)")
    elif kind == "triangle":
        a, b, c = (np.asarray(vec3(item.get(v), f"{path}.{v}")) for v in ("a", "b", "c"))
        if not np.linalg.norm(np.cross(b - a, c - a)) > 0.0:
            raise SpecError(path, "a triangle of zero area (collinear corners)")


# ----------------------------------------------------------------------------
# What is computed, and how


class Settings:
    """Sample counts: full accuracy, or ``quick`` for a smoke run."""

    def __init__(self, quick: bool = False):
        self.quick = quick
        self.passes = 64 if quick else 16384  # renders, averaged in float64
        self.spp = 4096  # per render: a film accumulating much more drifts in float32

    def as_dict(self):
        return {"mode": "quick" if self.quick else "full", "passes": self.passes,
                "spp_per_pass": self.spp, "scale": SCALE}


def require_expressible(exp):
    """A SpecError naming the path of a light Mitsuba cannot express."""
    for k, e in enumerate(exp.scene.emitters):
        if e["type"] == "cap":
            raise SpecError(
                f"scene.emitters[{k}].type",
                "Mitsuba 3 has no light of a cone of directions at infinity (`directional` "
                "is a delta, `envmap` a pixelised map, whose pixels would move the cap's "
                "edge): a `cap` light is not expressible")


def unsupported_reason(exp, quantity):
    """Why ``quantity`` is not computed for ``exp``, or None if it is."""
    if not quantity.startswith("L_"):
        return None
    brdf = exp.scene.brdf
    if brdf is None:
        return "the receiver has no BRDF: no reflected radiance"
    if brdf["type"] in ("phong", "normalized-phong"):
        return NO_PHONG
    if brdf["type"] == "ggx":
        return NO_GGX
    if exp.scene.toward_viewer is None:
        return "the receiver has no toward_viewer: no reflected radiance"
    return None


def compute(exp, quantity, settings):
    """``E`` for an ``E_*`` quantity, ``L`` for an ``L_*`` one (computed once
    per experiment object and settings, and reused by the other forms)."""
    reflected = quantity.startswith("L_")
    cache = exp.__dict__.setdefault("_rendering_values", {})
    key = (reflected, settings.passes, settings.spp)
    if key not in cache:
        cache[key] = reflected_radiance(exp, settings, irradiance=not reflected)
    result = dict(cache[key])
    result["form"] = (f"{quantity} is the same integral as every other "
                      f"{'L' if reflected else 'E'}_* form: one value for all")
    return result


# ----------------------------------------------------------------------------
# The Mitsuba scene


def _local(p, x):
    """A point of the file in the scaled scene: ``SCALE (p - x)``."""
    return SCALE * (np.asarray(p, dtype=np.float64) - np.asarray(x, dtype=np.float64))


def _frame(n):
    """Two unit tangents completing the unit normal ``n`` to a right-handed frame."""
    n = np.asarray(n, dtype=np.float64)
    n = n / np.linalg.norm(n)
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t = np.cross(n, a)
    t /= np.linalg.norm(t)
    return t, np.cross(n, t), n


def _matrix(c0, c1, c2, origin):
    mi, _ = require_mitsuba()
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = c0, c1, c2, origin
    return mi.ScalarTransform4f(m.tolist())


def _disk_to_world(centre, normal, radius):
    """Mitsuba's unit disk (z = 0, normal +z) onto the disk ``centre, normal, radius``."""
    t, b, n = _frame(normal)
    return _matrix(radius * t, radius * b, n, centre)


def _shape(item, x, path, tmp):
    """A Mitsuba shape dict for a lightquad rectangle, disk, triangle or sphere
    (``item``), in the scaled scene."""
    kind = item["type"]
    if kind == "rectangle":
        o = _local(vec3(item.get("origin"), f"{path}.origin"), x)
        eu = SCALE * np.asarray(vec3(item.get("edge_u"), f"{path}.edge_u"))
        ev = SCALE * np.asarray(vec3(item.get("edge_v"), f"{path}.edge_v"))
        n = np.cross(eu, ev)  # non-zero: read_scene checked the area
        # Mitsuba's rectangle is [-1, 1]^2 at z = 0 with normal +z; a third
        # column along edge_u x edge_v keeps that orientation.
        return {"type": "rectangle",
                "to_world": _matrix(eu / 2, ev / 2, n / np.linalg.norm(n), o + (eu + ev) / 2)}
    if kind == "disk":
        c = _local(vec3(item.get("centre"), f"{path}.centre"), x)
        n = unit(vec3(item.get("normal"), f"{path}.normal"), f"{path}.normal")
        return {"type": "disk", "to_world": _disk_to_world(c, n, SCALE * float(item["radius"]))}
    if kind == "sphere":
        c = _local(vec3(item.get("centre"), f"{path}.centre"), x)
        return {"type": "sphere", "center": c.tolist(), "radius": SCALE * float(item["radius"])}
    # A triangle: a one-face OBJ (Mitsuba's face normal (b - a) x (c - a) is
    # lightquad's (b - a) x (c - b)). Written in float64 digits; Mitsuba
    # rounds the vertices to float32 like every other coordinate.
    verts = [_local(vec3(item.get(v), f"{path}.{v}"), x) for v in ("a", "b", "c")]
    fd, obj = tempfile.mkstemp(suffix=".obj", dir=tmp)
    with os.fdopen(fd, "w") as f:
        for v in verts:
            f.write("v {:.17g} {:.17g} {:.17g}\n".format(*v))
        f.write("f 1 2 3\n")
    return {"type": "obj", "filename": obj, "face_normals": True}


def build_scene(exp, tmp, receiver=None, sensor=None):
    """The Mitsuba scene of the lights and occluders (scaled-scene
    coordinates); with ``receiver = (reflectance, radius)`` the receiver disk,
    with ``sensor = (origin, direction, spp)`` a radiancemeter."""
    mi, _ = require_mitsuba()
    s = exp.scene
    black = {"type": "diffuse", "reflectance": 0.0}
    parts = {"type": "scene", "integrator": {"type": "direct"}}
    for k, e in enumerate(s.emitters):
        if e["type"] == "environment":
            parts[f"emitter{k}"] = {"type": "constant", "radiance": float(e["radiance"])}
            continue
        shape = _shape(e, s.point, f"scene.emitters[{k}]", tmp)
        shape["emitter"] = {"type": "area", "radiance": float(e["radiance"])}
        shape["bsdf"] = black
        parts[f"emitter{k}"] = shape
    for k, o in enumerate(s.occluders):
        shape = _shape(o, s.point, f"scene.occluders[{k}]", tmp)
        shape["bsdf"] = black
        parts[f"occluder{k}"] = shape
    if receiver is not None:
        reflectance, radius = receiver
        parts["receiver"] = {"type": "disk",
                             "to_world": _disk_to_world(np.zeros(3), s.normal, radius),
                             "bsdf": {"type": "diffuse", "reflectance": float(reflectance)}}
    if sensor is not None:
        origin, direction, spp = sensor
        parts["sensor"] = {
            "type": "radiancemeter", "origin": np.asarray(origin).tolist(),
            "direction": np.asarray(direction).tolist(),
            "film": {"type": "hdrfilm", "width": 1, "height": 1, "rfilter": {"type": "box"},
                     "pixel_format": "rgb", "component_format": "float32"},
            "sampler": {"type": "independent", "sample_count": spp}}
    return mi.load_dict(parts)


def _viewer_distance(exp, view, tmp):
    """Where the radiancemeter sits along ``view`` from the receiving point:
    half the way to the first surface on that ray, at most 1 (scaled units,
    1e-3 of the file's)."""
    mi, _ = require_mitsuba()
    probe = build_scene(exp, tmp)
    si = probe.ray_intersect(mi.Ray3f(mi.Point3f(0.0, 0.0, 0.0), mi.Vector3f(*view.tolist())))
    # (In a vectorised variant such as llvm_ad_rgb each is an array of one.)
    valid = bool(np.asarray(si.is_valid()).reshape(-1)[0])
    t = float(np.asarray(si.t, dtype=np.float64).reshape(-1)[0]) if valid else math.inf
    return min(1.0, 0.5 * t)


def reflected_radiance(exp, settings, irradiance):
    """Mitsuba's radiance reflected by the receiver toward the viewer: with
    reflectance 1 viewed along the normal for ``irradiance`` (returned as
    ``E = pi L``), with the Lambertian BRDF's albedo for ``L``."""
    require_expressible(exp)
    s = exp.scene
    if irradiance:
        reflectance, view, scale = 1.0, np.asarray(s.normal), math.pi
    else:
        if s.brdf is None or s.brdf["type"] != "lambert" or s.toward_viewer is None:
            raise AssertionError("unsupported_reason screens these")
        reflectance, view, scale = float(s.brdf["albedo"]), np.asarray(s.toward_viewer), 1.0
        if float(np.dot(view, s.normal)) <= 0.0:
            raise SpecError("scene.receiver.toward_viewer",
                            "the viewer is below the receiver's plane: it sees no reflection")
    with tempfile.TemporaryDirectory() as tmp:
        # The receiver disk: small beside the viewer's distance, which is
        # below the distance to any surface above the receiving point. Only
        # the radiancemeter's ray meets it, at the receiving point, and it
        # blocks no light from above its plane.
        d = _viewer_distance(exp, view, tmp)
        scene = build_scene(exp, tmp, receiver=(reflectance, 0.1 * d),
                            sensor=(d * view, -view, settings.spp))
        value, std_error = mean_of_renders(scene, settings.passes, settings.spp, exp.seed)
    what = "E = pi L of a white (reflectance 1)" if irradiance else \
        f"L of the Lambertian (albedo {reflectance})"
    return {
        "value": scale * value,
        "std_error": scale * std_error,
        "samples": int(settings.passes * settings.spp),
        "method": f"Mitsuba direct integrator (one emitter and one BSDF sample, MIS): {what} "
                  f"receiver disk seen by a 1x1 radiancemeter with a box filter, the scene "
                  f"moved to the receiving point and scaled by {SCALE:g}; float64 mean of "
                  f"{settings.passes} renders of {settings.spp} spp, standard error over "
                  f"renders",
        "viewer_distance": d / SCALE,
    }
