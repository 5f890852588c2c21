#!/usr/bin/env python3
"""An external estimator for lightquad (protocol lightquad-estimator/1,
docs/external-estimators.md): plain Monte Carlo irradiance at a receiver
point from rectangle lights, standard library only.

Each request names a rendering scene, an irradiance quantity (E_area,
E_hemisphere, ...: one value, whatever lightquad's form) and a budget n. The
estimate samples each rectangle uniformly by area, n points:

    E = sum over lights of  A L_e (1/n) sum_i cos(theta_r) cos(theta_e) / r^2

(R-A of docs/EQUATIONS.md), with the sample standard error. A scene with
occluders, another kind of light, RGB radiance or another quantity gets an
`error` answer.

Two planted faults, for the report's verdicts to catch:
    --no-cos     forgets the light's cosine (the pdf of directions missing
                 its cos factor): biased;
    --half-se    reports half its standard error: error bars too small.
"""

import json
import math
import random
import sys
import time


class Unsupported(Exception):
    """A request this estimator cannot answer."""


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit(a):
    length = math.sqrt(dot(a, a))
    return [a[0] / length, a[1] / length, a[2] / length]


def rectangles(scene):
    """The scene's lights as (origin, edge_u, edge_v, radiance), or Unsupported."""
    if scene.get("occluders"):
        raise Unsupported("occluders: this example has no visibility test")
    lights = []
    for k, e in enumerate(scene.get("emitters", [])):
        if e.get("type") != "rectangle":
            raise Unsupported(f"emitters[{k}] is a {e.get('type')}: only rectangles")
        if not isinstance(e.get("radiance"), (int, float)):
            raise Unsupported(f"emitters[{k}]: only a scalar radiance")
        lights.append((e["origin"], e["edge_u"], e["edge_v"], float(e["radiance"])))
    return lights


def irradiance(scene, n, rng, with_cos=True):
    """The estimate and its standard error from n samples per light."""
    x = scene["receiver"]["point"]
    normal = unit(scene["receiver"]["normal"])
    lights = rectangles(scene)
    samples = []
    for _ in range(n):
        f = 0.0
        for origin, eu, ev, radiance in lights:
            facing = cross(eu, ev)  # the emitting side (e_u x e_v)
            area = math.sqrt(dot(facing, facing))
            u, v = rng.random(), rng.random()
            y = [origin[i] + u * eu[i] + v * ev[i] for i in range(3)]
            d = sub(y, x)
            r2 = dot(d, d)
            cos_r = dot(normal, d) / math.sqrt(r2)
            cos_e = -dot(facing, d) / (area * math.sqrt(r2))
            if cos_r <= 0.0 or cos_e <= 0.0:
                continue
            f += radiance * area * cos_r * (cos_e if with_cos else 1.0) / r2
        samples.append(f)
    mean = math.fsum(samples) / n
    m2 = math.fsum((f - mean) ** 2 for f in samples)
    m4 = math.fsum((f - mean) ** 4 for f in samples)
    variance = m2 / (n - 1) if n > 1 else math.inf
    return mean, math.sqrt(variance / n), doubted(n, m2, m4)


def doubted(n, m2, m4):
    """Whether the standard error is in doubt, by lightquad's Monte Carlo
    test: every sample alike, or a sample variance whose own relative error
    sqrt((b2 - 1)/n) (b2 the kurtosis) exceeds max(0.5 (16/n)^(1/4), 0.3),
    as where a few samples carry the spread."""
    if n < 2 or m2 == 0.0:
        return True
    b2 = n * m4 / (m2 * m2)
    return math.sqrt(max(b2 - 1.0, 0.0) / n) > max(0.5 * (16.0 / n) ** 0.25, 0.3)


def answer(request, with_cos, se_scale):
    """One response for one request."""
    if request.get("family") != "rendering" or not request.get("quantity", "").startswith("E_"):
        raise Unsupported(f"{request.get('family')} {request.get('quantity')}: "
                          "only the rendering family's irradiance E_*")
    rng = random.Random(request["seed"])
    start = time.perf_counter()
    value, se, in_doubt = irradiance(request["scene"], request["budget"], rng, with_cos)
    seconds = time.perf_counter() - start
    std_error = [se * se_scale] if math.isfinite(se) else None
    response = {"id": request["id"], "value": [value], "evaluations": request["budget"],
                "seconds": seconds}
    if std_error is not None:
        response["std_error"] = std_error
    if in_doubt:
        response["doubted"] = True
    return response


def main():
    with_cos = "--no-cos" not in sys.argv[1:]
    se_scale = 0.5 if "--half-se" in sys.argv[1:] else 1.0
    print(json.dumps({"protocol": "lightquad-estimator", "version": 1}), flush=True)  # ready
    for line in sys.stdin:  # one request per line, until lightquad closes stdin
        request = json.loads(line)
        try:
            response = answer(request, with_cos, se_scale)
        except Unsupported as e:
            response = {"id": request["id"], "error": str(e)}
        print(json.dumps(response, allow_nan=False), flush=True)


if __name__ == "__main__":
    main()
