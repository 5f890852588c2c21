#!/usr/bin/env python3
"""Write scipy's unscrambled Sobol' and Halton points, the independent
references for lightquad's Joe-Kuo direction numbers (src/quadrature/sobol.rs)
and radical inverses (src/quadrature/halton.rs).

Run from the repository root:

    python3 -m venv /tmp/sv && /tmp/sv/bin/pip install -r scripts/requirements-reference.txt
    /tmp/sv/bin/python scripts/gen_sobol_reference.py

Writes tests/data/sobol_joe_kuo.json: the first 1024 points of
scipy.stats.qmc.Sobol(DIMS, scramble=False, bits=32), each coordinate as the
32-bit integer x * 2^32 (exact: with bits = 32 every coordinate is a multiple
of 2^-32). scipy's direction numbers are Joe and Kuo's new-joe-kuo-6.21201
(its first coordinate is van der Corput's), and its points come in Gray-code
order: row i is the point of natural index i ^ (i >> 1), the first (row 0)
being the origin. The rows are written in scipy's order; the Rust test
(tests/it/sobol_dims.rs) maps them. The first 1024 points in Gray-code order
are the first 1024 in natural order, permuted.

Those points use only the first 10 direction numbers of each dimension. The
`high` section adds the points of natural index 2^k (k = 0..31: point 2^k is
the k-th direction number itself) and three others with many bits set, each
drawn at its Gray-code row (the inverse Gray code of its index) after
fast_forward; about a minute, most of it stepping to row 2^32 - 1.

Writes tests/data/halton_scipy.json: the first 512 points of
scipy.stats.qmc.Halton(DIMS, scramble=False) (row i is point i, row 0 the
origin; coordinate j the radical inverse of i in the j-th prime), as floats
(shortest round-trip form). scipy sums the digits in floating point, so they
may differ from the correctly rounded radical inverse in the last bits.
"""

import json
from pathlib import Path

import numpy as np
import scipy
from scipy.stats import qmc

DIMS = 21
POINTS = 1024
HALTON_POINTS = 512
HIGH = [1 << k for k in range(32)] + [0xFFFF_FFFF, 0xDEAD_BEEF, 0x1234_5678]


def inverse_gray(n: int) -> int:
    """The Gray-code row r with r ^ (r >> 1) == n: r = n ^ (n >> 1) ^ (n >> 2) ^ ..."""
    r, shift = n, 1
    while n >> shift:
        r ^= n >> shift
        shift += 1
    return r


def high_points() -> list:
    """Points of natural index HIGH, stepping one sampler forward through their rows."""
    sampler = qmc.Sobol(DIMS, scramble=False, bits=32)
    rows = sorted((inverse_gray(n), n) for n in HIGH)
    at, out = 0, []
    for row, n in rows:
        assert row ^ (row >> 1) == n
        sampler.fast_forward(row - at)
        x = sampler.random(1)[0] * 2.0**32
        at = row + 1
        assert np.all(x == np.floor(x)) and np.all(x < 2.0**32)
        out.append({"natural_index": n, "gray_row": row, "u32": [int(v) for v in x]})
    return out


def main() -> None:
    sampler = qmc.Sobol(DIMS, scramble=False, bits=32)
    x = sampler.random(POINTS)
    ints = x * 2.0**32
    # Every coordinate a whole number below 2^32: nothing was rounded.
    assert np.all(ints == np.floor(ints)) and np.all(ints < 2.0**32)
    ints = ints.astype(np.uint64)
    # Gray-code order, checked on van der Corput: row i is bit-reversed i ^ (i >> 1).
    for i in range(POINTS):
        g = i ^ (i >> 1)
        assert int(ints[i, 0]) == int(f"{g:032b}"[::-1], 2), i
    out = {
        "source": (
            f"scripts/gen_sobol_reference.py (scipy {scipy.__version__}, numpy {np.__version__}): "
            f"scipy.stats.qmc.Sobol({DIMS}, scramble=False, bits=32).random({POINTS}); "
            "Joe and Kuo's new-joe-kuo-6.21201 direction numbers, first coordinate van der Corput"
        ),
        "scipy_version": scipy.__version__,
        "order": "gray: row i is the point of natural index i ^ (i >> 1); row 0 is the origin",
        "dimensions": DIMS,
        "points": POINTS,
        "rows_u32": [[int(v) for v in row] for row in ints],
        "high": high_points(),
    }
    path = Path("tests/data/sobol_joe_kuo.json")
    text = json.dumps(out, indent=None, separators=(",", ":"))
    # One row a line, so a diff shows which points changed.
    text = text.replace("],[", "],\n[").replace("},{", "},\n{")
    path.write_text(text + "\n")
    print(f"wrote {path}: {POINTS} points x {DIMS} dimensions")
    halton()


def halton() -> None:
    """tests/data/halton_scipy.json: scipy's unscrambled Halton points."""
    x = qmc.Halton(DIMS, scramble=False).random(HALTON_POINTS)
    out = {
        "source": (
            f"scripts/gen_sobol_reference.py (scipy {scipy.__version__}, numpy {np.__version__}): "
            f"scipy.stats.qmc.Halton({DIMS}, scramble=False).random({HALTON_POINTS}); "
            "row i is point i, coordinate j the radical inverse of i in the j-th prime"
        ),
        "scipy_version": scipy.__version__,
        "dimensions": DIMS,
        "points": HALTON_POINTS,
        "rows": [[float(v) for v in row] for row in x],
    }
    path = Path("tests/data/halton_scipy.json")
    text = json.dumps(out, indent=None, separators=(",", ":")).replace("],[", "],\n[")
    path.write_text(text + "\n")
    print(f"wrote {path}: {HALTON_POINTS} points x {DIMS} dimensions")


if __name__ == "__main__":
    main()
