"""The ``furnace`` family: the full rendering equation in a closed Lambertian
enclosure (docs/EQUATIONS.md, R-H's recursion; lightquad's
src/rendering/furnace.rs). Everything the harness knows about it.

Mitsuba computes the white furnace (every wall emits, ``half_angle`` = pi):
``L`` (the whole series) and ``L_K`` (``K = scene.bounces`` reflections) with
its ``path`` integrator seen by a radiancemeter inside the enclosure.

* In a closed enclosure whose every wall emits ``L_e`` and reflects with
  albedo ``rho``, the radiance incident at every wall point after ``k``
  reflections is ``L_e rho^k`` whatever the enclosure's shape, so
  ``L_K = L_e sum_{k=0}^{K} rho^k`` and ``L = L_e / (1 - rho)`` hold for a
  cube as for lightquad's sphere. Mitsuba's enclosure is a cube with inward
  normals: its ``sphere`` sampled from a point on itself is biased (measured
  with the path integrator at ``rho`` = 0.5: ``L_3`` = 1.8811 +- 0.0003
  against 1.875, where the cube gives 1.8751 +- 0.0010; see the module's
  test), so the sphere is not used.
* ``max_depth`` = ``K + 1`` (Mitsuba counts the segment from the sensor as
  the first); for ``L``, ``K`` is chosen so the truncation ``rho^(K+1)`` is
  below 1e-9 of ``L``. Russian roulette is off (``rr_depth`` past
  ``max_depth``): Mitsuba caps its survival probability at 0.95, so with walls
  of albedo 0.999 the surviving paths' weights grow as (0.999 / 0.95)^k.
* float32: the albedo is rounded to float32 before anything is computed,
  which moves ``L = L_e / (1 - rho)`` by ``rho``'s rounding times
  ``1 / (1 - rho)^2`` (+1.3e-5 relative at 0.999), and ``L`` is accumulated
  in float32 over thousands of bounces (the series of float32(0.999) summed
  in float32 comes out 2.1e-5 relative below its exact sum). ``float32_error``
  is twice the sum of the two.

Not expressible: a cap (``half_angle`` < pi): Mitsuba 3 has no spherical-cap
shape, and a tessellated or textured sphere would move the cap's edge.
"""

import math

import numpy as np

from ..mitsuba3 import mean_of_renders, require_mitsuba
from ..spec import SpecError, number

QUANTITIES = ("L", "L_K")
TRUNCATION = 1e-9
"""The relative truncation ``rho^(K+1)`` kept for ``L``."""


class Scene:
    def __init__(self, albedo, emission, half_angle, bounces):
        self.albedo = albedo
        self.emission = emission
        self.half_angle = half_angle
        self.bounces = bounces


def read_scene(scene) -> Scene:
    """The ``scene`` object of a furnace experiment file (its ``radius``,
    ``axis`` and ``point`` do not change the white furnace's values)."""
    if not isinstance(scene, dict):
        raise SpecError("scene", "expected an object")
    albedo = number(scene.get("albedo"), "scene.albedo", 0.0, 1.0)
    if albedo == 1.0:
        raise SpecError("scene.albedo", "expected an albedo in [0, 1), got 1.0: a furnace "
                                        "of albedo 1 has no finite radiance")
    # float32, Mitsuba's, overflows near 3.4e38.
    emission = number(scene.get("emission"), "scene.emission", 0.0, 1e30)
    bounces = scene.get("bounces")
    if bounces is not None and (isinstance(bounces, bool) or not isinstance(bounces, int)
                                or bounces < 0):
        raise SpecError("scene.bounces", f"expected a whole number >= 0, got {bounces!r}")
    half_angle = number(scene.get("half_angle", math.pi), "scene.half_angle", 0.0, math.pi)
    return Scene(albedo, emission, half_angle, bounces)


class Settings:
    """Paths: full accuracy, or ``quick`` for a smoke run. Each quantity gets
    about ``bounces`` bounces in all (about 100 s at full accuracy), in
    renders of ``spp`` paths (fewer for long paths, so that a render stays
    short)."""

    def __init__(self, quick: bool = False):
        self.quick = quick
        self.bounces = 2e5 if quick else 2e8

    def renders(self, reflections):
        """``(passes, spp)`` for paths of ``reflections + 1`` segments."""
        spp = 128 if reflections > 1000 else (256 if self.quick else 4096)
        paths = self.bounces / (reflections + 1)
        return max(8, round(paths / spp)), spp

    def as_dict(self):
        return {"mode": "quick" if self.quick else "full", "bounces": self.bounces,
                "truncation": TRUNCATION}


def require_expressible(exp):
    if exp.scene.half_angle < math.pi:
        raise SpecError(
            "scene.half_angle",
            f"{exp.scene.half_angle} < pi: Mitsuba 3 has no spherical-cap shape (a "
            "tessellated or textured sphere would move the cap's edge); only the white "
            "furnace (half_angle = pi, every wall emitting) is expressible")


def unsupported_reason(exp, quantity):
    if quantity == "L_K" and exp.scene.bounces is None:
        return "the scene gives no `bounces`: L_K is L"
    return None


MAX_REFLECTIONS = 10 ** 6
"""The most reflections a path may take (a path of 1e6 bounces takes about
half a second; an albedo of 1 - 1e-8 would ask for 2e9)."""


def reflections(exp, quantity):
    """``K``: the file's for ``L_K``; for ``L`` the fewest with ``rho^(K+1)`` below
    TRUNCATION. More than MAX_REFLECTIONS is a SpecError naming the field."""
    rho = exp.scene.albedo
    if quantity == "L_K":
        k = exp.scene.bounces
        if k > MAX_REFLECTIONS:
            raise SpecError("scene.bounces", f"{k}: expected at most {MAX_REFLECTIONS} "
                                             "reflections for Mitsuba's paths")
        return k
    if rho == 0.0:
        return 0
    k = max(0, math.ceil(math.log(TRUNCATION) / math.log(rho)) - 1)
    if k > MAX_REFLECTIONS:
        raise SpecError("scene.albedo", f"{rho}: L to a truncation of {TRUNCATION:g} needs {k} "
                                        f"reflections, more than {MAX_REFLECTIONS}: expected an "
                                        "albedo further from 1")
    return k


def float32_series(rho, emission, k):
    """``L_e sum_{j=0}^{k} rho^j`` as a path sums it in float32 (float32 albedo,
    throughput and running sum)."""
    r = np.float32(rho)
    le = np.float32(emission)
    throughput, total = np.float32(1.0), np.float32(0.0)
    for _ in range(k + 1):
        total = np.float32(total + throughput * le)
        throughput = np.float32(throughput * r)
    return float(total)


def compute(exp, quantity, settings):
    mi, _ = require_mitsuba()
    require_expressible(exp)
    s = exp.scene
    k = reflections(exp, quantity)
    depth = k + 1
    passes, spp = settings.renders(k)
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": depth, "rr_depth": depth + 1},
        "walls": {"type": "cube", "flip_normals": True,
                  "emitter": {"type": "area", "radiance": s.emission},
                  "bsdf": {"type": "diffuse", "reflectance": s.albedo}},
        "sensor": {"type": "radiancemeter", "origin": [0.0, 0.0, 0.0],
                   "direction": [0.3, -0.2, -1.0],
                   "film": {"type": "hdrfilm", "width": 1, "height": 1,
                            "rfilter": {"type": "box"}, "pixel_format": "rgb",
                            "component_format": "float32"},
                   "sampler": {"type": "independent", "sample_count": spp}},
    })
    value, std_error = mean_of_renders(scene, passes, spp, exp.seed)
    rho, le = s.albedo, s.emission
    exact_k = le * (1.0 - rho ** (k + 1)) / (1.0 - rho)
    truncation = le * rho ** (k + 1) / (1.0 - rho) if quantity == "L" else 0.0
    f32 = float32_series(rho, le, k)
    rho32 = float(np.float32(rho))
    exact_k32 = float(np.float32(le)) * (1.0 - rho32 ** (k + 1)) / (1.0 - rho32)
    return {
        "value": value,
        "std_error": std_error,
        "samples": int(passes * spp),
        "float32_error": 2.0 * (abs(exact_k32 - exact_k) + abs(f32 - exact_k32)) + truncation,
        "method": f"Mitsuba path integrator in a closed cube (inward normals, every wall "
                  f"emitting {le} with albedo {rho}), max_depth {depth} ({k} reflections), "
                  f"no Russian roulette, 1x1 radiancemeter inside; float64 mean of "
                  f"{passes} renders of {spp} paths, standard error over renders",
        "reflections": k,
        "truncation": truncation,
        "float32_series": f32,
    }
