"""Mitsuba 3 side of the harness: importing it, and exporting a lightquad scene
(medium, light) into a Mitsuba scene.

Conventions (lightquad -> Mitsuba):

* ``sigma = lambda * v_r``: the medium's ``sigma_t`` holds ``v_r`` (``kappa`` of
  a constant sphere, or the voxel grid's data) and its ``scale`` is ``lambda``.
  Float ``sigma_t`` values are used throughout: an RGB ``sigma_t`` above 1 is
  rejected by Mitsuba's reflectance spectrum check.
* A medium lives inside a boundary shape with a ``null`` BSDF (a ``sphere``, or
  a ``cube`` scaled to the voxel grid's box).
* ``voxel-grid`` data (values at voxel centres, ``[z][y][x]``, x fastest) maps
  one-to-one onto a ``gridvolume`` whose unit cube is the box: Mitsuba also
  puts values at ``(i + 1/2) / n`` and reads them trilinearly with clamping,
  from a tensor laid out ``[z, y, x, channel]``.
* The light's ``toward_light`` points from a point toward the light; Mitsuba's
  ``directional`` ``direction`` is the direction the light travels, its
  negative. Its ``irradiance`` E is the power per unit area normal to that
  direction, i.e. a radiance ``E * delta(w - w_light)``: a scattering point
  receives ``E * Tr(shadow)``, exactly lightquad's ``I_p(t)`` with ``I_p = E``.
  (tests/test_lqref.py checks it against the closed form.)

Every Mitsuba variant computes in float32; this one is ``scalar_rgb``.
"""

import sys

import numpy as np

from .spec import SpecError

VARIANT = "scalar_rgb"
_MI = None


class MitsubaMissing(RuntimeError):
    """Mitsuba 3 (or the variant) is not available in this Python."""


def require_mitsuba():
    """Imports Mitsuba 3 and Dr.Jit and selects ``scalar_rgb``; returns ``(mi, dr)``.

    Raises MitsubaMissing with the install command when they are absent."""
    global _MI
    if _MI is not None:
        return _MI
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as e:
        raise MitsubaMissing(
            f"Mitsuba 3 is not installed for {sys.executable} ({e}).\n"
            "Install the pinned versions with:\n"
            "    pip install -r reference/requirements.txt"
        ) from e
    if VARIANT not in mi.variants():
        raise MitsubaMissing(
            f"this Mitsuba build has no `{VARIANT}` variant (it has {mi.variants()}); "
            "install the pinned wheel: pip install -r reference/requirements.txt"
        )
    mi.set_variant(VARIANT)
    _MI = (mi, dr)
    return _MI


def versions():
    mi, dr = require_mitsuba()
    return {"mitsuba_variant": VARIANT, "mitsuba_version": mi.__version__,
            "drjit_version": dr.__version__}


# ----------------------------------------------------------------------------
# Voxel grid export


def voxel_grid_tensor(medium: dict) -> np.ndarray:
    """lightquad's voxel data as the ``[z, y, x, 1]`` float32 array a Mitsuba
    ``VolumeGrid`` takes (x fastest in both, so it is a reshape, no transpose)."""
    nx, ny, nz = (int(n) for n in medium["resolution"])
    data = np.asarray(medium["data"], dtype=np.float64)
    if nx < 1 or ny < 1 or nz < 1 or data.size != nx * ny * nz:
        raise SpecError("scene.medium.data",
                        f"{data.size} values for resolution {[nx, ny, nz]}")
    return data.reshape(nz, ny, nx, 1).astype(np.float32)


def grid_to_world(medium: dict):
    """The transform taking the gridvolume's unit cube onto the box [min, max]."""
    mi, _ = require_mitsuba()
    lo = np.asarray(medium["min"], dtype=np.float64)
    hi = np.asarray(medium["max"], dtype=np.float64)
    return mi.ScalarTransform4f().translate(lo.tolist()) @ mi.ScalarTransform4f().scale(
        (hi - lo).tolist())


def gridvolume(medium: dict):
    """lightquad's voxel grid (a ``voxel-grid`` medium dict) as a Mitsuba ``gridvolume``."""
    mi, _ = require_mitsuba()
    return mi.load_dict({
        "type": "gridvolume",
        "grid": mi.VolumeGrid(voxel_grid_tensor(medium)),
        "to_world": grid_to_world(medium),
        "filter_type": "trilinear",
        "wrap_mode": "clamp",
    })


# ----------------------------------------------------------------------------
# Scene export


def medium_parts(exp, albedo: float):
    """``(medium_dict, shape_dict)`` for the experiment's medium: the Mitsuba
    medium (id ``medium``) and its null-BSDF boundary shape. A medium Mitsuba
    cannot express is an error naming ``scene.medium.type``."""
    mi, _ = require_mitsuba()
    m = exp.medium
    kind = m["type"]
    if kind == "constant-sphere":
        medium = {"type": "homogeneous", "sigma_t": float(m["kappa"]),
                  "scale": exp.lam, "albedo": float(albedo)}
        shape = {"type": "sphere", "center": [float(x) for x in m["centre"]],
                 "radius": float(m["radius"])}
    elif kind == "voxel-grid":
        medium = {"type": "heterogeneous", "sigma_t": gridvolume(m),
                  "scale": exp.lam, "albedo": float(albedo)}
        lo = np.asarray(m["min"], dtype=np.float64)
        hi = np.asarray(m["max"], dtype=np.float64)
        # Mitsuba's cube is [-1, 1]^3.
        to_world = mi.ScalarTransform4f().translate(((lo + hi) / 2).tolist()) @ \
            mi.ScalarTransform4f().scale(((hi - lo) / 2).tolist())
        shape = {"type": "cube", "to_world": to_world}
    else:
        raise SpecError(
            "scene.medium.type",
            f"Mitsuba 3 cannot express a `{kind}` medium: its media are homogeneous or "
            "voxel grids (gridvolume), and a voxelised copy would be a different field")
    shape["bsdf"] = {"type": "null"}
    shape["interior"] = {"type": "ref", "id": "medium"}
    return medium, shape


def build_scene(exp, albedo: float = 0.0, extra: dict = None):
    """A Mitsuba scene holding the experiment's medium (and ``extra`` objects);
    returns ``(scene, medium)``."""
    mi, _ = require_mitsuba()
    medium, shape = medium_parts(exp, albedo)
    d = {"type": "scene", "medium": medium, "boundary": shape}
    d.update(extra or {})
    scene = mi.load_dict(d)
    return scene, scene.shapes()[0].interior_medium()


def point(p):
    mi, _ = require_mitsuba()
    return mi.Point3f(float(p[0]), float(p[1]), float(p[2]))


def vector(v):
    mi, _ = require_mitsuba()
    return mi.Vector3f(float(v[0]), float(v[1]), float(v[2]))


def medium_chord(scene, exp, clip=True):
    """``(t_n, t_f)``: where the eye ray is inside the medium's boundary shape,
    cut to ``[t_min, t_max]``, by Mitsuba's own ray-shape intersection; None if
    it misses (``clip=False``: not cut).

    Both ends are found by rays that start outside the shape on the eye ray's
    line (the exit by a ray run backwards from beyond the shape), never by a
    ray re-spawned at the entry: Mitsuba offsets those by ~1.7e-4 along the
    normal, which moves the line and shortens the chord by ~1e-5 relative."""
    mi, _ = require_mitsuba()
    o = np.asarray(exp.origin)
    d = np.asarray(exp.direction)
    si = scene.ray_intersect(mi.Ray3f(point(o), vector(d)))
    if not si.is_valid():
        return None
    if float(np.dot(np.asarray(si.n), d)) > 0.0:
        t_n, t_f = 0.0, float(si.t)  # the origin is inside: the first hit is the exit
    else:
        t_n = float(si.t)
        bb = scene.bbox()
        span = float(np.linalg.norm(np.asarray(bb.max) - np.asarray(bb.min)))
        far = t_n + 1.5 * span
        back = scene.ray_intersect(mi.Ray3f(point(o + far * d), vector(-d)))
        if not back.is_valid() or float(np.dot(np.asarray(back.n), -d)) > 0.0:
            raise RuntimeError("could not find the exit of the eye ray from the medium")
        t_f = far - float(back.t)
    if clip:
        t_n, t_f = max(t_n, exp.t_min), min(t_f, exp.t_max)
    return (t_n, t_f) if t_n < t_f else None


def medium_interaction(p=(0.0, 0.0, 0.0)):
    """A zeroed MediumInteraction3f at ``p``."""
    mi, dr = require_mitsuba()
    mei = dr.zeros(mi.MediumInteraction3f)
    mei.p = point(p)
    return mei


def sigma_t_at(medium, points: np.ndarray) -> np.ndarray:
    """The medium's own extinction ``sigma_t`` (``get_scattering_coefficients``,
    scale included) at each row of ``points``, as float64 (values are float32)."""
    mei = medium_interaction()
    coeffs = medium.get_scattering_coefficients
    mi, _ = require_mitsuba()
    out = np.empty(len(points))
    for i, (x, y, z) in enumerate(np.asarray(points, dtype=np.float64).tolist()):
        mei.p = mi.Point3f(x, y, z)
        out[i] = coeffs(mei)[2][0]
    return out


def majorant(medium) -> float:
    """The medium's majorant (``get_majorant``: ``scale * max(grid)`` for a
    heterogeneous medium, ``sigma_t`` for a homogeneous one)."""
    return float(medium.get_majorant(medium_interaction())[0])
