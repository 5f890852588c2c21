"""One function per (quantity, medium) the harness computes with Mitsuba 3.

Each returns a dict with ``value``, ``std_error``, ``samples``, ``method`` and
some details. Values are averaged in float64; Mitsuba itself is float32.
"""

import math

import numpy as np

from . import mitsuba_scene as ms
from .spec import SpecError

FLOAT32_EPS = 2.0 ** -23


class Settings:
    """Sample counts: full accuracy, or ``quick`` for a smoke run."""

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


def _no_chord(value, what):
    return {"value": value, "std_error": 0.0, "samples": 0,
            "method": f"the eye ray misses the medium: {what}"}


# ----------------------------------------------------------------------------
# tau, constant sphere


def tau_constant_sphere(exp, settings=None):
    """V-tau through a ``constant-sphere``: Mitsuba's ``homogeneous`` medium's
    ``transmittance_eval_pdf`` over the chord that Mitsuba's ray-sphere
    intersection gives. Deterministic, exact up to float32."""
    mi, dr = ms.require_mitsuba()
    scene, medium = ms.build_scene(exp)
    chord = ms.medium_chord(scene, exp)
    if chord is None:
        return _no_chord(1.0, "tau = 1")
    t_n, t_f = chord
    length = t_f - t_n
    o, d = np.asarray(exp.origin), np.asarray(exp.direction)
    mei = ms.medium_interaction(o + t_n * d)
    mei.wi = ms.vector(-d)
    mei.sh_frame = mi.Frame3f(ms.vector(d))
    mei.mint = 0.0
    mei.t = dr.inf  # no interaction before the surface: the pdf branch of "passed through"
    mei.combined_extinction = medium.get_majorant(mei)
    si = dr.zeros(mi.SurfaceInteraction3f)
    si.t = length
    tr, _pdf = medium.transmittance_eval_pdf(mei, si, True)
    sigma = float(mei.combined_extinction[0])
    depth = sigma * length
    value = float(tr[0])
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
# tau, voxel grid


def ratio_tracking(medium, o, d, t_n, t_f, walks, rng, chunk=2 ** 17):
    """Ratio tracking along ``o + t d`` over ``[t_n, t_f]`` with the medium's own
    majorant and extinction. Returns the per-walk estimates (float64) and the
    number of extinction look-ups.

    Each walk takes tentative collisions at ``Exp(majorant)`` steps and carries
    the weight ``prod (1 - sigma_t(x_i) / majorant)``; its expectation is tau.
    The walks of a chunk advance together, one collision per round."""
    mu = ms.majorant(medium)
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
            weight[lo + alive] *= 1.0 - ms.sigma_t_at(medium, pts) / mu
            lookups += alive.size
    return weight, lookups


def ray_march_depth(medium, o, d, t_n, t_f, steps):
    """Optical depth by the composite midpoint rule with ``steps`` cells over the
    chord, extinction from the medium (``get_scattering_coefficients``)."""
    h = (t_f - t_n) / steps
    ts = t_n + (np.arange(steps) + 0.5) * h
    return h * float(np.sum(ms.sigma_t_at(medium, o[None, :] + ts[:, None] * d[None, :])))


def tau_voxel_grid(exp, settings):
    """V-tau through a ``voxel-grid``: the grid exported to a ``gridvolume`` in a
    ``heterogeneous`` medium (whose ``transmittance_eval_pdf`` is only
    exp(-majorant * distance), not its transmittance), estimated by ratio
    tracking over the medium's own coefficients; a midpoint ray march beside it."""
    ms.require_mitsuba()
    scene, medium = ms.build_scene(exp)
    chord = ms.medium_chord(scene, exp)
    if chord is None:
        return _no_chord(1.0, "tau = 1")
    t_n, t_f = chord
    o, d = np.asarray(exp.origin), np.asarray(exp.direction)

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
        "majorant": ms.majorant(medium),
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
# I_L, single scattering


def light_single_scattering(exp, settings):
    """V-L with single scattering (albedo, isotropic phase function): Mitsuba's
    ``volpath`` (max_depth 2: emitters seen directly, which a delta light never
    is, plus one scattering event with next-event estimation) with a
    ``directional`` emitter, read by a 1x1 ``radiancemeter`` with a box filter
    looking along the eye ray; no background, no other emitter.

    The radiancemeter starts at the eye ray's entry into the medium, inside it
    (its ``medium`` is the scene's medium): the part of the ray before the
    entry is vacuum and adds nothing, and a camera ray crossing the boundary
    would be re-spawned 1.7e-4 further in (a relative bias of about
    sigma * 1.7e-4). The radiancemeter also starts its ray ~8.9e-5 ahead of its
    ``origin`` (Mitsuba's ray epsilon); the origin is moved back by the offset
    it measures, so the ray starts at the entry itself (see ``_sensor_origin``).
    """
    mi, _ = ms.require_mitsuba()
    light = exp.light
    if light is None:
        raise SpecError("scene.light", "I_L needs a light")
    if light.albedo is None:
        raise SpecError(
            "scene.light.albedo",
            "Mitsuba cannot express the document's reduced V-L (no scattering "
            "coefficient, no phase function): give an albedo for single scattering")
    scene, _ = ms.build_scene(exp, albedo=light.albedo)
    full_chord = ms.medium_chord(scene, exp, clip=False)
    chord = ms.medium_chord(scene, exp)
    if chord is None:
        return _no_chord(0.0, "I_L = 0")
    if chord != full_chord:
        raise SpecError("scene.t_min" if chord[0] != full_chord[0] else "scene.t_max",
                        "Mitsuba's sensor ray cannot be cut inside the medium: "
                        "I_L with t_min/t_max inside the chord is not expressible")
    t_n, t_f = chord
    o, d = np.asarray(exp.origin), np.asarray(exp.direction)
    start, skipped = _inside_start(scene, o, d, t_n)

    film = {"type": "hdrfilm", "width": 1, "height": 1, "rfilter": {"type": "box"},
            "pixel_format": "rgb", "component_format": "float32"}
    origin, residual = _sensor_origin(start, d, film)
    medium_dict, shape_dict = ms.medium_parts(exp, light.albedo)
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
                   "sampler": {"type": "independent", "sample_count": settings.spp}},
    })
    values = np.empty(settings.passes)
    base = (exp.seed * 1_000_003) % 2 ** 32
    for k in range(settings.passes):
        img = np.asarray(mi.render(scene, spp=settings.spp, seed=(base + k) % 2 ** 32),
                         dtype=np.float64)
        values[k] = float(np.mean(img[0, 0, :3]))
    return {
        "value": float(np.mean(values)),
        "std_error": float(np.std(values, ddof=1) / math.sqrt(values.size)),
        "samples": int(settings.passes * settings.spp),
        "method": f"Mitsuba volpath, max_depth 2 (single scattering), directional emitter "
                  f"(irradiance = I_p), 1x1 radiancemeter inside the medium at the ray's "
                  f"entry, box filter; float64 mean of {settings.passes} renders of "
                  f"{settings.spp} spp, standard error over renders",
        "chord": [t_n, t_f],
        "sensor_start_offset": skipped,  # distance past t_n where the sensor ray starts
        "sensor_origin_residual": residual,
    }


def _inside_start(scene, o, d, t_n):
    """A point on the eye ray just past its entry ``t_n`` from which Mitsuba sees
    the exit as the first hit (so the sensor ray is inside the medium); returns
    it and how far past ``t_n`` it is (0 for an origin inside the medium)."""
    mi, _ = ms.require_mitsuba()
    if t_n == 0.0:
        return o.copy(), 0.0
    eta = 1e-6 * max(1.0, abs(t_n))
    for _ in range(20):
        p = o + (t_n + eta) * d
        si = scene.ray_intersect(mi.Ray3f(ms.point(p), ms.vector(d)))
        if si.is_valid() and float(np.dot(np.asarray(si.n), d)) > 0.0 and float(si.t) > eta:
            return p, eta
        eta *= 2.0
    raise RuntimeError("could not place the sensor inside the medium")


def _sensor_origin(start, d, film):
    """The radiancemeter ``origin`` whose sampled ray starts at ``start``: the
    radiancemeter offsets its ray's origin along the direction; measure that
    offset and take it off. Returns the origin and the residual distance
    between the sampled ray's origin and ``start``."""
    mi, _ = ms.require_mitsuba()

    def ray_origin(origin):
        sensor = mi.load_dict({"type": "radiancemeter", "origin": origin.tolist(),
                               "direction": d.tolist(), "film": film})
        ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(0.5, 0.5), mi.Point2f(0.5, 0.5))
        return np.asarray(ray.o, dtype=np.float64)

    origin = start - (ray_origin(start) - start)
    residual = float(np.linalg.norm(ray_origin(origin) - start))
    return origin, residual
