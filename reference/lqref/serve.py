"""Mitsuba 3 as a lightquad external estimator: ``python reference/serve.py``
answers lightquad's requests (protocol lightquad-estimator/1,
docs/external-estimators.md) on stdin and stdout, one JSON line each, until
stdin ends.

Each request is computed as the harness computes a values file (the same
Mitsuba scenes: transmittance through a homogeneous sphere or a voxel grid,
single scattering by volpath, irradiance and reflected radiance by the
direct integrator, the furnace by the path integrator, pixel coverage by the
perspective sensor), with the request's budget as Mitsuba's sample count:
``min(8, budget)`` renders of ``budget // renders`` samples each (ratio-
tracking walks and ray-march steps = budget for the volume family's own
loops), the standard error over the renders. The variant is ``llvm_ad_rgb``
where ``DRJIT_LIBLLVM_PATH`` names libLLVM, ``scalar_rgb`` otherwise; both
compute in float32.
"""

import json
import sys
import time

from . import spec
from .mitsuba3 import MitsubaMissing, require_mitsuba, use_llvm_if_present

RENDERS = 8
"""The most renders a budget is split into (the standard error is their spread)."""


def settings_for(family_name, family, budget):
    """The family's Settings with ``budget`` samples in all."""
    settings = family.Settings(quick=True)
    passes = max(1, min(RENDERS, budget))
    spp = max(1, budget // passes)
    if family_name == "furnace":
        settings.renders = lambda reflections: (passes, spp)
    else:
        settings.passes, settings.spp = passes, spp
    if family_name == "volume":
        settings.walks = budget
        settings.march_steps = budget
    return settings, passes * spp


def answer(request):
    """The response to one request (an ``error`` one for a scene or quantity
    the harness cannot compute)."""
    from .families import FAMILIES

    rid = request.get("id")
    name = request.get("family")
    quantity = request.get("quantity")
    if name not in FAMILIES:
        return {"id": rid, "error": f"family {name!r}: the harness knows {sorted(FAMILIES)}"}
    if request.get("channels") != 1:
        return {"id": rid, "error": f"{request.get('channels')} channels: the harness "
                                    "computes one value per quantity (RGB averaged)"}
    family = FAMILIES[name]
    raw = {"name": request.get("experiment", "request"), "family": name,
           "scene": request.get("scene"), "quantities": [quantity],
           "seed": int(request.get("seed", 0)) % 2 ** 32}
    try:
        exp = spec.from_dict(raw, "<request>")
        family.require_expressible(exp)
        why = family.unsupported_reason(exp, quantity)
        if why is not None:
            return {"id": rid, "error": why}
        settings, samples = settings_for(name, family, int(request["budget"]))
        start = time.perf_counter()
        result = family.compute(exp, quantity, settings)
        seconds = time.perf_counter() - start
    except (spec.SpecError, KeyError, TypeError, ValueError, RuntimeError,
            AssertionError) as e:
        return {"id": rid, "error": f"{type(e).__name__}: {e}"}
    response = {"id": rid, "value": [float(result["value"])], "evaluations": samples,
                "seconds": seconds}
    se = float(result["std_error"])
    if se == se and se != float("inf"):  # finite: one render has no spread
        response["std_error"] = [se]
    return response


def main():
    variant = use_llvm_if_present()
    try:
        require_mitsuba()
        from . import families  # noqa: F401  (loaded before the hello: start-up)
    except (MitsubaMissing, ImportError) as e:
        print(f"error: {e}", file=sys.stderr, flush=True)
        return 3
    print(f"lqref.serve: Mitsuba 3 variant {variant}", file=sys.stderr, flush=True)
    print(json.dumps({"protocol": "lightquad-estimator", "version": 1}), flush=True)  # ready
    for line in sys.stdin:
        request = json.loads(line)
        response = answer(request)
        print(json.dumps(response, allow_nan=False), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
