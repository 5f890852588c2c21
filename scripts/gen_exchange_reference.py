#!/usr/bin/env python3
"""Form factors between two surfaces at 30 digits, for tests/it/exchange_exact.rs.

Independent of the Rust code: Howell's printed closed forms (C-11, C-14,
C-41) evaluated in mpmath, and for a pair with no catalogue formula the
2-D integral over the first polygon of Lambert's point-to-polygon formula
(mpmath's tanh-sinh quadrature).

    python3 scripts/gen_exchange_reference.py > tests/data/exchange_form_factors.json
"""
import json

from mpmath import atan, ln, mp, mpf, pi, quad, sqrt, acos

mp.dps = 30


def c11(a, b, c):
    x, y = mpf(a) / c, mpf(b) / c
    return 2 / (pi * x * y) * (
        ln(sqrt((1 + x**2) * (1 + y**2) / (1 + x**2 + y**2)))
        + x * sqrt(1 + y**2) * atan(x / sqrt(1 + y**2))
        + y * sqrt(1 + x**2) * atan(y / sqrt(1 + x**2))
        - x * atan(x) - y * atan(y))


def c14(l, w, h):
    hh, ww = mpf(h) / l, mpf(w) / l
    s2 = hh**2 + ww**2
    term = ln((1 + ww**2) * (1 + hh**2) / (1 + s2)
              * (ww**2 * (1 + s2) / ((1 + ww**2) * s2)) ** (ww**2)
              * (hh**2 * (1 + s2) / ((1 + hh**2) * s2)) ** (hh**2))
    return (ww * atan(1 / ww) + hh * atan(1 / hh) - sqrt(s2) * atan(1 / sqrt(s2))
            + term / 4) / (pi * ww)


def c41(r1, r2, h):
    big1, big2 = mpf(r1) / h, mpf(r2) / h
    x = 1 + (1 + big2**2) / big1**2
    return (x - sqrt(x**2 - 4 * (big2 / big1) ** 2)) / 2


def sub(a, b):
    return [a[i] - b[i] for i in range(3)]


def dot(a, b):
    return sum(a[i] * b[i] for i in range(3))


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    return sqrt(dot(a, a))


def lambert(p, n, corners):
    """Point-to-polygon form factor, the polygon wholly above p's horizon."""
    total = mpf(0)
    k = len(corners)
    for i in range(k):
        a, b = sub(corners[i], p), sub(corners[(i + 1) % k], p)
        c = cross(a, b)
        angle = acos(dot(a, b) / (norm(a) * norm(b)))
        total += angle * dot(n, c) / norm(c)
    return abs(total) / (2 * pi)


def general_pair():
    """A parallelogram receiver (z = 0, normal +z) and a tilted triangle above."""
    o, eu, ev = [0, 0, 0], [1, 0, 0], [mpf('0.3'), mpf('0.8'), 0]
    tri = [[mpf('0.2'), mpf('0.1'), mpf('0.7')], [mpf('1.1'), mpf('0.4'), mpf('1.3')],
           [mpf('0.4'), mpf('1.2'), mpf('0.9')]]
    n = [0, 0, 1]
    area = norm(cross(eu, ev))

    def f(u, v):
        p = [o[i] + u * eu[i] + v * ev[i] for i in range(3)]
        return lambert(p, n, tri)

    value = quad(f, [0, 1], [0, 1]) * area / area  # mean of F_dA over A_1 = F_12
    return {"receiver": {"origin": [0, 0, 0], "edge_u": [1, 0, 0], "edge_v": [0.3, 0.8, 0]},
            "triangle": [[float(x) for x in c] for c in tri],
            "F": str(value)}


def main():
    out = {
        "about": "scripts/gen_exchange_reference.py, mpmath at 30 digits",
        "parallel_rectangles": [{"a": a, "b": b, "c": c, "F": str(c11(a, b, c))}
                                for a, b, c in [(1, 1, 1), (1, 1, 0.1), (1, 1, 0.01),
                                                (1, 1, 10), (2, 0.5, 0.3)]],
        "perpendicular_rectangles": [{"l": l, "w": w, "h": h, "F": str(c14(l, w, h))}
                                     for l, w, h in [(1, 1, 1), (1, 2, 0.5), (3, 0.2, 1),
                                                     (1, 0.01, 1)]],
        "coaxial_disks": [{"r1": a, "r2": b, "h": h, "F": str(c41(a, b, h))}
                          for a, b, h in [(1, 1, 1), (0.5, 2, 0.1), (1, 1, 100),
                                          (1, 1, 0.1), (2, 0.5, 1)]],
        "general_pair": general_pair(),
    }
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
