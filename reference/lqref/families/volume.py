"""The ``volume`` family: emission, absorption and single scattering along one
ray through a participating medium (docs/EQUATIONS.md, V-*). Everything the
harness knows about it: reading its ``scene``, its quantities and sample
counts, exporting the medium and light to Mitsuba 3, and one function per
(quantity, medium) it computes there.

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

Each quantity function returns a dict with ``value``, ``std_error``,
``samples``, ``method`` and some details. Values are averaged in float64;
Mitsuba itself is float32.
"""

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..mitsuba3 import mean_of_renders, point, require_mitsuba, vector
from ..spec import SpecError, unit, vec3

QUANTITIES = ("tau", "ln_tau", "I_E", "I_B", "I_L", "I")
MEDIUM_TYPES = ("constant-sphere", "gaussian-blobs", "linear-gradient", "voxel-grid")
EXPRESSIBLE_MEDIA = ("constant-sphere", "voxel-grid")

NO_EMISSION = ("Mitsuba 3 media have no volumetric emission (homogeneous and heterogeneous "
               "media take no radiance): no counterpart of V-E")
FLOAT32_EPS = 2.0 ** -23


# ----------------------------------------------------------------------------
# The scene


@dataclass
class Light:
    toward_light: tuple  # unit vector from a point toward the light
    intensity: float  # I_p
    albedo: Optional[float]  # None: the document's reduced V-L


@dataclass
class Scene:
    origin: tuple
    direction: tuple  # normalised: t is arc length, as in lightquad
    t_min: float
    t_max: float
    medium: Optional[dict]
    lam: float  # lambda in sigma = lambda * v_r
    emission: Optional[dict]
    light: Optional[Light]


def read_scene(scene) -> Scene:
    """The ``scene`` object of a volume experiment file. Its ``depth_scheme``
    and ``shadow`` choose how lightquad computes optical depths, not what the
    quantities are: the harness does not read them."""
    if "ray" not in scene:
        raise SpecError("scene.ray", "missing field")
    origin = vec3(scene["ray"].get("origin"), "scene.ray.origin")
    direction = unit(vec3(scene["ray"].get("direction"), "scene.ray.direction"),
                     "scene.ray.direction")

    medium = scene.get("medium")
    if medium is not None and medium.get("type") not in MEDIUM_TYPES:
        raise SpecError("scene.medium.type", f"unknown medium type {medium.get('type')!r}")

    light = None
    if scene.get("light") is not None:
        l = scene["light"]
        light = Light(
            toward_light=unit(vec3(l.get("toward_light"), "scene.light.toward_light"),
                              "scene.light.toward_light"),
            intensity=float(l["intensity"]),
            albedo=None if l.get("albedo") is None else float(l["albedo"]),
        )

    lam = scene.get("lambda")
    return Scene(
        origin=origin,
        direction=direction,
        t_min=0.0 if scene.get("t_min") is None else float(scene["t_min"]),
        t_max=math.inf if scene.get("t_max") is None else float(scene["t_max"]),
        medium=medium,
        lam=1.0 if lam is None else float(lam),
        emission=scene.get("emission"),
        light=light,
    )


# ----------------------------------------------------------------------------
# What is computed, and how


class Settings:
    """Sample counts: full accuracy, or ``quick`` for a smoke run. A values
    file records them (``settings``)."""

    def __init__(self, quick: bool = False):
        self.quick = quick
        self.walks = 2 ** 14 if quick else 2 ** 22  # ratio-tracking walks
        self.march_steps = 2 ** 13 if quick else 2 ** 19  # ray-march midpoints
        self.passes = 64 if quick else 16384  # volpath renders, averaged in float64
        self.spp = 4096  # per render: a film accumulating much more drifts in float32

    def as_dict(self):
        return {"mode": "quick" if self.quick else "full", "walks": self.walks,
                "march_steps": self.march_steps, "passes": self.passes,
                "spp_per_pass": self.spp}


def require_expressible(exp):
    """A SpecError naming ``scene.medium.type`` for a medium Mitsuba cannot express."""
    medium = exp.scene.medium
    if medium is not None and medium["type"] not in EXPRESSIBLE_MEDIA:
        raise SpecError(
            "scene.medium.type",
            f"Mitsuba 3 cannot express a `{medium['type']}` medium: its media are "
            "homogeneous or voxel grids (gridvolume), and a voxelised copy would be a "
            "different field")


def unsupported_reason(exp, quantity):
    """Why ``quantity`` is not computed for ``exp``, or None if it is."""
    if quantity == "I_E":
        return NO_EMISSION
    if quantity == "ln_tau":
        return ("not computed separately: the tau entry carries log_value, Mitsuba's ln tau "
                "(float32 underflows where lightquad's ln tau stays exact)")
    if quantity == "I_B":
        return ("not computed by this harness: I_B = I_b * tau, use the tau value "
                "(or add a function for it)")
    if quantity == "I":
        if exp.scene.emission is not None:
            return "I = I_E + I_B + I_L needs I_E: " + NO_EMISSION
        return "not computed by this harness: I = I_B + I_L here, I_B is not computed"
    if quantity == "I_L" and exp.scene.light is None:
        return "the scene has no light"
    return None


def compute(exp, quantity, settings):
    """A supported quantity (``tau`` or ``I_L``) of ``exp``."""
    medium = exp.scene.medium
    if quantity == "tau":
        if medium is None:
            return {"value": 1.0, "std_error": 0.0, "samples": 0,
                    "method": "no medium: tau = 1"}
        if medium["type"] == "constant-sphere":
            return tau_constant_sphere(exp, settings)
        return tau_voxel_grid(exp, settings)
    if quantity == "I_L":
        if medium is None:
            return {"value": 0.0, "std_error": 0.0, "samples": 0,
                    "method": "no medium: nothing scatters, I_L = 0"}
        return light_single_scattering(exp, settings)
    raise AssertionError(quantity)  # unreachable: every quantity has a reason or a branch


# ----------------------------------------------------------------------------
# Mitsuba scene: voxel grid export


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
# Mitsuba scene: medium, boundary, chord


def medium_parts(exp, albedo: float):
    """``(medium_dict, shape_dict)`` for the experiment's medium: the Mitsuba
    medium (id ``medium``) and its null-BSDF boundary shape. A medium Mitsuba
    cannot express is an error naming ``scene.medium.type``."""
    mi, _ = require_mitsuba()
    require_expressible(exp)
    m = exp.scene.medium
    if m["type"] == "constant-sphere":
        medium = {"type": "homogeneous", "sigma_t": float(m["kappa"]),
                  "scale": exp.scene.lam, "albedo": float(albedo)}
        shape = {"type": "sphere", "center": [float(x) for x in m["centre"]],
                 "radius": float(m["radius"])}
    else:  # voxel-grid
        medium = {"type": "heterogeneous", "sigma_t": gridvolume(m),
                  "scale": exp.scene.lam, "albedo": float(albedo)}
        lo = np.asarray(m["min"], dtype=np.float64)
        hi = np.asarray(m["max"], dtype=np.float64)
        # Mitsuba's cube is [-1, 1]^3.
        to_world = mi.ScalarTransform4f().translate(((lo + hi) / 2).tolist()) @ \
            mi.ScalarTransform4f().scale(((hi - lo) / 2).tolist())
        shape = {"type": "cube", "to_world": to_world}
    shape["bsdf"] = {"type": "null"}
    shape["interior"] = {"type": "ref", "id": "medium"}
    return medium, shape


def build_scene(exp, albedo: float = 0.0):
    """A Mitsuba scene holding the experiment's medium; returns ``(scene, medium)``."""
    mi, _ = require_mitsuba()
    medium, shape = medium_parts(exp, albedo)
    scene = mi.load_dict({"type": "scene", "medium": medium, "boundary": shape})
    return scene, scene.shapes()[0].interior_medium()


def medium_chord(scene, exp, clip=True):
    """``(t_n, t_f)``: where the eye ray is inside the medium's boundary shape,
    cut to ``[t_min, t_max]``, by Mitsuba's own ray-shape intersection; None if
    it misses (``clip=False``: not cut).

    Both ends are found by rays that start outside the shape on the eye ray's
    line (the exit by a ray run backwards from beyond the shape), never by a
    ray re-spawned at the entry: Mitsuba offsets those by ~1.7e-4 along the
    normal, which moves the line and shortens the chord by ~1e-5 relative."""
    mi, _ = require_mitsuba()
    o = np.asarray(exp.scene.origin)
    d = np.asarray(exp.scene.direction)
    si = scene.ray_intersect(mi.Ray3f(point(o), vector(d)))
    if not si.is_valid():
        return None
    if float(np.dot(_flat(si.n), d)) > 0.0:
        t_n, t_f = 0.0, _scalar(si.t)  # the origin is inside: the first hit is the exit
    else:
        t_n = _scalar(si.t)
        bb = scene.bbox()
        span = float(np.linalg.norm(_flat(bb.max) - _flat(bb.min)))
        far = t_n + 1.5 * span
        back = scene.ray_intersect(mi.Ray3f(point(o + far * d), vector(-d)))
        if not back.is_valid() or float(np.dot(_flat(back.n), -d)) > 0.0:
            raise RuntimeError("could not find the exit of the eye ray from the medium")
        t_f = far - _scalar(back.t)
    if clip:
        t_n, t_f = max(t_n, exp.scene.t_min), min(t_f, exp.scene.t_max)
    return (t_n, t_f) if t_n < t_f else None


def _flat(v):
    """A Mitsuba vector or point as a float64 array of its three components
    (in a vectorised variant such as ``llvm_ad_rgb`` each is an array of one)."""
    return np.asarray(v, dtype=np.float64).reshape(-1)


def _scalar(x):
    """A Mitsuba number as a float (an array of one in a vectorised variant)."""
    return float(np.asarray(x, dtype=np.float64).reshape(-1)[0])


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


def _no_chord(value, what):
    """The result for an eye ray that misses the medium."""
    return {"value": value, "std_error": 0.0, "samples": 0,
            "method": f"the eye ray misses the medium: {what}"}


# ----------------------------------------------------------------------------
# Quantities: tau, constant sphere


def tau_constant_sphere(exp, settings=None):
    """V-tau through a ``constant-sphere``: Mitsuba's ``homogeneous`` medium's
    ``transmittance_eval_pdf`` over the chord that Mitsuba's ray-sphere
    intersection gives. Deterministic, exact up to float32."""
    mi, dr = require_mitsuba()
    scene, medium = build_scene(exp)
    chord = medium_chord(scene, exp)
    if chord is None:
        return _no_chord(1.0, "tau = 1")
    t_n, t_f = chord
    length = t_f - t_n
    o, d = np.asarray(exp.scene.origin), np.asarray(exp.scene.direction)
    mei = medium_interaction(o + t_n * d)
    mei.wi = vector(-d)
    mei.sh_frame = mi.Frame3f(vector(d))
    mei.mint = 0.0
    mei.t = dr.inf  # no interaction before the surface: the pdf branch of "passed through"
    mei.combined_extinction = medium.get_majorant(mei)
    si = dr.zeros(mi.SurfaceInteraction3f)
    si.t = length
    tr, _pdf = medium.transmittance_eval_pdf(mei, si, True)
    sigma = _scalar(mei.combined_extinction[0])
    depth = sigma * length
    value = _scalar(tr[0])
    return {
        "value": value,
        "std_error": 0.0,
        "samples": 1,
        "method": "Mitsuba homogeneous medium: transmittance_eval_pdf over the chord from "
                  "Mitsuba's ray-sphere intersection (scene.ray_intersect from both ends); "
                  "deterministic, float32",
        # float32: sigma, the chord and exp each to a few ulps; grows with the depth.
        "float32_error": value * FLOAT32_EPS * (2.0 + 4.0 * depth),
        "log_value": -depth,  # in float64 from Mitsuba's float32 sigma and chord
        "sigma_t": sigma,
        "chord": [t_n, t_f],
        **({"note": f"exp(-{depth:.6g}) underflows float32 (and float64): value 0; "
                    "log_value = -sigma_t * chord is Mitsuba's optical depth"}
           if value == 0.0 else {}),
    }


# ----------------------------------------------------------------------------
# Quantities: tau, voxel grid


def ratio_tracking(medium, o, d, t_n, t_f, walks, rng, chunk=2 ** 17):
    """Ratio tracking along ``o + t d`` over ``[t_n, t_f]`` with the medium's own
    majorant and extinction. Returns the per-walk estimates (float64) and the
    number of extinction look-ups.

    Each walk takes tentative collisions at ``Exp(majorant)`` steps and carries
    the weight ``prod (1 - sigma_t(x_i) / majorant)``; its expectation is tau.
    The walks of a chunk advance together, one collision per round."""
    mu = majorant(medium)
    if not mu > 0.0:
        return np.ones(walks), 0
    weight = np.ones(walks)
    lookups = 0
    for lo in range(0, walks, chunk):
        hi = min(lo + chunk, walks)
        t = np.full(hi - lo, float(t_n))
        alive = np.arange(hi - lo)
        while alive.size:
            t[alive] += rng.standard_exponential(alive.size) / mu
            alive = alive[t[alive] < t_f]
            if not alive.size:
                break
            pts = o[None, :] + t[alive, None] * d[None, :]
            weight[lo + alive] *= 1.0 - sigma_t_at(medium, pts) / mu
            lookups += alive.size
    return weight, lookups


def ray_march_depth(medium, o, d, t_n, t_f, steps):
    """Optical depth by the composite midpoint rule with ``steps`` cells over the
    chord, extinction from the medium (``get_scattering_coefficients``)."""
    h = (t_f - t_n) / steps
    ts = t_n + (np.arange(steps) + 0.5) * h
    return h * float(np.sum(sigma_t_at(medium, o[None, :] + ts[:, None] * d[None, :])))


def tau_voxel_grid(exp, settings):
    """V-tau through a ``voxel-grid``: the grid exported to a ``gridvolume`` in a
    ``heterogeneous`` medium (whose ``transmittance_eval_pdf`` is only
    exp(-majorant * distance), not its transmittance), estimated by ratio
    tracking over the medium's own coefficients; a midpoint ray march beside it."""
    require_mitsuba()
    scene, medium = build_scene(exp)
    chord = medium_chord(scene, exp)
    if chord is None:
        return _no_chord(1.0, "tau = 1")
    t_n, t_f = chord
    o, d = np.asarray(exp.scene.origin), np.asarray(exp.scene.direction)

    rng = np.random.default_rng([exp.seed, 0x7A75])
    est, lookups = ratio_tracking(medium, o, d, t_n, t_f, settings.walks, rng)
    value = float(np.mean(est))
    std_error = float(np.std(est, ddof=1) / math.sqrt(est.size))

    n = settings.march_steps
    depth_n = ray_march_depth(medium, o, d, t_n, t_f, n)
    depth_half = ray_march_depth(medium, o, d, t_n, t_f, n // 2)
    march = math.exp(-depth_n)
    # Midpoint rule: error ~ h^2 (the field is piecewise cubic along the ray with
    # kinks at voxel-centre planes), so Richardson |Q_n - Q_n/2| / 3; plus a
    # float32 floor of 8 ulps per look-up: Mitsuba's float32 trilinear
    # reconstruction sits ~3 ulps (systematically) off the float64 field.
    march_error = abs(march - math.exp(-depth_half)) / 3.0 + march * depth_n * 8 * FLOAT32_EPS
    return {
        "value": value,
        "std_error": std_error,
        "samples": int(est.size),
        "method": "ratio tracking (Python/NumPy over Mitsuba's heterogeneous medium: "
                  "get_majorant, get_scattering_coefficients of the exported gridvolume), "
                  "float64 mean of independent walks, standard error of the mean",
        "majorant": majorant(medium),
        "extinction_lookups": lookups,
        "chord": [t_n, t_f],
        "ray_march": {
            "value": march,
            "error_estimate": march_error,
            "log_value": -depth_n,
            "steps": n,
            "method": "composite midpoint rule for the optical depth with the medium's "
                      "sigma_t, Richardson estimate against half the steps plus a float32 "
                      "floor (8 ulps of the optical depth)",
        },
    }


# ----------------------------------------------------------------------------
# Quantities: I_L, single scattering


def light_single_scattering(exp, settings):
    """V-L with single scattering (albedo, isotropic phase function): Mitsuba's
    ``volpath`` (max_depth 2: emitters seen directly, which a delta light never
    is, plus one scattering event with next-event estimation) with a
    ``directional`` emitter, read by a 1x1 ``radiancemeter`` with a box filter
    looking along the eye ray (:func:`single_scattering_scene`); no background,
    no other emitter."""
    built = single_scattering_scene(exp, settings.spp)
    if built is None:
        return _no_chord(0.0, "I_L = 0")
    scene, (t_n, t_f), skipped, residual = built
    value, std_error = mean_of_renders(scene, settings.passes, settings.spp, exp.seed)
    return {
        "value": value,
        "std_error": std_error,
        "samples": int(settings.passes * settings.spp),
        "method": f"Mitsuba volpath, max_depth 2 (single scattering), directional emitter "
                  f"(irradiance = I_p), 1x1 radiancemeter inside the medium at the ray's "
                  f"entry, box filter; float64 mean of {settings.passes} renders of "
                  f"{settings.spp} spp, standard error over renders",
        "chord": [t_n, t_f],
        "sensor_start_offset": skipped,  # distance past t_n where the sensor ray starts
        "sensor_origin_residual": residual,
    }


def single_scattering_scene(exp, spp):
    """The Mitsuba scene of :func:`light_single_scattering` with ``spp`` samples
    per render, with the chord, how far past its entry the sensor ray starts
    and the sensor origin's residual; None where the eye ray misses the medium.

    The radiancemeter starts at the eye ray's entry into the medium, inside it
    (its ``medium`` is the scene's medium): the part of the ray before the
    entry is vacuum and adds nothing, and a camera ray crossing the boundary
    would be re-spawned 1.7e-4 further in (a relative bias of about
    sigma * 1.7e-4). The radiancemeter also starts its ray ~8.9e-5 ahead of its
    ``origin`` (Mitsuba's ray epsilon); the origin is moved back by the offset
    it measures, so the ray starts at the entry itself (see ``_sensor_origin``).
    """
    mi, _ = require_mitsuba()
    light = exp.scene.light
    if light is None:
        raise SpecError("scene.light", "I_L needs a light")
    if light.albedo is None:
        raise SpecError(
            "scene.light.albedo",
            "Mitsuba cannot express the document's reduced V-L (no scattering "
            "coefficient, no phase function): give an albedo for single scattering")
    scene, _ = build_scene(exp, albedo=light.albedo)
    full_chord = medium_chord(scene, exp, clip=False)
    chord = medium_chord(scene, exp)
    if chord is None:
        return None
    if chord != full_chord:
        raise SpecError("scene.t_min" if chord[0] != full_chord[0] else "scene.t_max",
                        "Mitsuba's sensor ray cannot be cut inside the medium: "
                        "I_L with t_min/t_max inside the chord is not expressible")
    t_n, _ = chord
    o, d = np.asarray(exp.scene.origin), np.asarray(exp.scene.direction)
    start, skipped = _inside_start(scene, o, d, t_n)

    film = {"type": "hdrfilm", "width": 1, "height": 1, "rfilter": {"type": "box"},
            "pixel_format": "rgb", "component_format": "float32"}
    origin, residual = _sensor_origin(start, d, film)
    medium_dict, shape_dict = medium_parts(exp, light.albedo)
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": 2},
        "medium": medium_dict,
        "boundary": shape_dict,
        # direction = where the light travels = -toward_light; irradiance = I_p.
        "light": {"type": "directional", "direction": [-x for x in light.toward_light],
                  "irradiance": float(light.intensity)},
        "sensor": {"type": "radiancemeter", "origin": origin.tolist(),
                   "direction": d.tolist(), "medium": {"type": "ref", "id": "medium"},
                   "film": film,
                   "sampler": {"type": "independent", "sample_count": spp}},
    })
    return scene, chord, skipped, residual


def _inside_start(scene, o, d, t_n):
    """A point on the eye ray just past its entry ``t_n`` from which Mitsuba sees
    the exit as the first hit (so the sensor ray is inside the medium); returns
    it and how far past ``t_n`` it is (0 for an origin inside the medium)."""
    mi, _ = require_mitsuba()
    if t_n == 0.0:
        return o.copy(), 0.0
    eta = 1e-6 * max(1.0, abs(t_n))
    for _ in range(20):
        p = o + (t_n + eta) * d
        si = scene.ray_intersect(mi.Ray3f(point(p), vector(d)))
        if si.is_valid() and float(np.dot(_flat(si.n), d)) > 0.0 and _scalar(si.t) > eta:
            return p, eta
        eta *= 2.0
    raise RuntimeError("could not place the sensor inside the medium")


def _sensor_origin(start, d, film):
    """The radiancemeter ``origin`` whose sampled ray starts at ``start``: the
    radiancemeter offsets its ray's origin along the direction; measure that
    offset and take it off. Returns the origin and the residual distance
    between the sampled ray's origin and ``start``."""
    mi, _ = require_mitsuba()

    def ray_origin(origin):
        sensor = mi.load_dict({"type": "radiancemeter", "origin": origin.tolist(),
                               "direction": d.tolist(), "film": film})
        ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(0.5, 0.5), mi.Point2f(0.5, 0.5))
        return _flat(ray.o)

    origin = start - (ray_origin(start) - start)
    residual = float(np.linalg.norm(ray_origin(origin) - start))
    return origin, residual
