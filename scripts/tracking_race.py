#!/usr/bin/env python3
"""Races lightquad's stochastic volume estimators against Mitsuba 3's on one
32^3 voxel grid and one ray: the wall time each needs to reach a relative
standard error of 1e-3 (the tracking-race target in benches/README.md).

    scripts/tracking_race.py [--target 1e-3] [--threads 2] [--repeats 5] [--quick]
                             [--only ratio|delta|light] ... [--json FILE]

Run it from anywhere with reference/.venv's Python, or with plain python3:
it re-executes itself under reference/.venv/bin/python when Mitsuba is not
importable (``python3 -m venv reference/.venv &&
reference/.venv/bin/pip install -r reference/requirements.txt`` makes it).
Needs Debian's libllvm19 (``apt-get install libllvm19``) for the
``llvm_ad_rgb`` variant; DRJIT_LIBLLVM_PATH defaults to its library. Builds
the example ``tracking_race`` (lightquad's side) with cargo.

The races, each lightquad's estimator against Mitsuba's own counterpart:

- ratio tracking of V-tau: lightquad's ``ratio-tracking`` (16 spans over the
  medium's chord, each with its own bound, tentative collisions at
  k = max(1, min(2D, 256/D)) times it) against Mitsuba's ``heterogeneous`` medium walked
  the way ``volpath`` walks a shadow ray: ``sample_interaction`` (free flights
  against the medium's one global majorant) and the weight
  ``sigma_n / combined_extinction`` at each tentative collision;
- delta tracking of V-tau: lightquad's ``delta-tracking`` (32 spans, each
  with its own bound) against the same
  Mitsuba walk that stops at the first real collision (probability
  ``sigma_t / combined_extinction``), as ``volpath`` does on camera paths;
- V-L with single scattering: lightquad's free-flight estimator
  (``tracking::radiance``) against Mitsuba's ``volpath`` (max_depth 2) with a
  directional emitter, read by a 1x1 radiancemeter (the harness's scene for
  ``v-l-single-scattering``).

For each side: a pilot run gives the variance of one walk, ``n`` walks
reach the target (``n = var / (target * mean)^2``), and the median of
``--repeats`` timed runs of ``n`` walks is its time (Mitsuba's kernels are
compiled by the pilot run; compilation is not timed). The ratio printed is
lightquad's time over Mitsuba's: below 1, lightquad is faster.

Both sides get the same number of threads (Dr.Jit's pool is set to it);
Mitsuba computes in float32 and SIMD lanes (16 with AVX-512, as on the
machine the figures in benches/README.md come from), lightquad in float64,
one walk at a time per thread.
"""

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
VENV_PYTHON = ROOT / "reference" / ".venv" / "bin" / "python"
LIBLLVM = "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"
mi = dr = None  # Mitsuba and Dr.Jit, imported by mitsuba_setup


def reexec_in_venv():
    """Runs this script again under reference/.venv's Python when Mitsuba is not
    importable here (the venv is made by scripts/reference.sh)."""
    try:
        import mitsuba  # noqa: F401
        import numpy  # noqa: F401
    except ImportError:
        in_venv = Path(sys.prefix).resolve() == VENV_PYTHON.parent.parent.resolve()
        if VENV_PYTHON.exists() and not in_venv:
            os.execv(str(VENV_PYTHON), [str(VENV_PYTHON), __file__, *sys.argv[1:]])
        sys.exit("tracking_race.py: Mitsuba 3 is not installed; make reference/.venv first:\n"
                 "    python3 -m venv reference/.venv && "
                 "reference/.venv/bin/pip install -r reference/requirements.txt")


# ----------------------------------------------------------------------------
# The grid and the ray


def grid_experiment(resolution=32):
    """A volume experiment file (a dict) with a ``resolution``^3 cloud: five
    Gaussian lumps and a band-limited ripple over [-1, 1]^3, density 0 to about
    6, crossed by a ray whose optical depth is about 2.5; a directional light
    with albedo 0.8 for V-L. Deterministic: the same grid on every machine."""
    import numpy as np

    n = resolution
    c = (np.arange(n) + 0.5) / n * 2.0 - 1.0  # voxel centres
    z, y, x = np.meshgrid(c, c, c, indexing="ij")  # x fastest once flattened
    lumps = [  # centre, width, height
        ((-0.45, 0.10, 0.05), 0.22, 5.0),
        ((0.05, -0.05, 0.10), 0.30, 3.0),
        ((0.50, 0.20, -0.10), 0.15, 6.0),
        ((0.20, 0.45, 0.40), 0.25, 2.0),
        ((-0.10, -0.50, -0.35), 0.20, 2.5),
    ]
    density = np.zeros_like(x)
    for (cx, cy, cz), w, h in lumps:
        density += h * np.exp(-((x - cx) ** 2 + (y - cy) ** 2 + (z - cz) ** 2) / (2 * w * w))
    ripple = 0.25 * (1 + np.sin(7 * x + 1) * np.sin(5 * y + 2) * np.sin(6 * z + 0.5))
    density = np.round(density + ripple, 6)  # short decimals: the file round-trips exactly
    return {
        "name": "race-grid-32",
        "family": "volume",
        "description": "scripts/tracking_race.py: a 32^3 cloud for timing the "
                       "stochastic estimators against Mitsuba 3.",
        "equations": ["V-tau", "V-L"],
        "scene": {
            "ray": {"origin": [-2.0, 0.08, 0.04], "direction": [1.0, 0.02, 0.01]},
            "medium": {"type": "voxel-grid", "min": [-1.0, -1.0, -1.0],
                       "max": [1.0, 1.0, 1.0], "resolution": [n, n, n],
                       "data": density.ravel().tolist()},
            "lambda": 0.4,
            "light": {"toward_light": [0.3, 1.0, 0.2], "intensity": 1.0, "albedo": 0.8},
        },
        "quantities": ["tau", "I_L"],
        "rules": [{"rule": "ratio-tracking"}, {"rule": "delta-tracking"}],
        "budgets": [1024],
        "reference": {"type": "converged", "n": 64},
    }


# ----------------------------------------------------------------------------
# lightquad


def lightquad_binary():
    """Builds the example ``tracking_race`` in release mode; returns its path."""
    subprocess.run(["cargo", "build", "--release", "--quiet", "--example", "tracking_race"],
                   cwd=ROOT, check=True)
    return ROOT / "target" / "release" / "examples" / "tracking_race"


def lightquad_run(binary, path, estimator, walks, seed, threads):
    out = subprocess.run([str(binary), str(path), estimator, str(walks), str(seed),
                          str(threads)], check=True, capture_output=True, text=True)
    r = json.loads(out.stdout)
    return r["value"], r["std_error"], r["seconds"], r["lookups"] / r["walks"]


# ----------------------------------------------------------------------------
# Mitsuba


def mitsuba_setup(threads):
    """Mitsuba in ``llvm_ad_rgb`` with Dr.Jit's pool at ``threads`` threads;
    returns the harness's volume module (its scene builders)."""
    os.environ.setdefault("DRJIT_LIBLLVM_PATH", LIBLLVM)
    sys.path.insert(0, str(ROOT / "reference"))
    from lqref import mitsuba3

    global mi, dr
    mitsuba3.VARIANT = "llvm_ad_rgb"
    mi, dr = mitsuba3.require_mitsuba()
    dr.set_thread_count(threads)
    from lqref.families import volume

    return volume


def _walks(medium, o, d, delta: bool, walks, seed):
    """Dr.Jit code (``dr.syntax`` makes the loop symbolic: one kernel): ``walks``
    walks along ``o + t d`` through ``medium``, Mitsuba's free-flight sampling
    (``sample_interaction``, the medium's global majorant) with the
    ratio-tracking weight ``sigma_n / combined_extinction`` at each tentative
    collision, or, for delta tracking, stopping with weight 0 at the first
    real one (probability ``sigma_t / combined_extinction``). Returns the
    weights and the tentative collisions of each walk."""
    rng = mi.PCG32(size=walks, initstate=seed)
    ray = dr.zeros(mi.Ray3f, walks)
    ray.o = mi.Point3f(*o)
    ray.d = mi.Vector3f(*d)
    ray.maxt = dr.inf
    weight = dr.full(mi.Float, 1.0, walks)
    steps = dr.zeros(mi.UInt32, walks)
    active = dr.full(mi.Bool, True, walks)
    channel = dr.zeros(mi.UInt32, walks)
    while active:
        mei = medium.sample_interaction(ray, rng.next_float32(), channel, active)
        active &= mei.is_valid()
        majorant = mei.combined_extinction[0]
        if active:
            steps += 1
            if delta:
                if rng.next_float32() * majorant < mei.sigma_t[0]:
                    weight = mi.Float(0.0)
                    active = mi.Bool(False)
            else:
                weight *= mei.sigma_n[0] / majorant
            ray.o = mei.p
    return weight, steps


def mitsuba_tracker(medium, o, d, delta):
    """A function of ``(walks, seed)`` running :func:`_walks` as one kernel;
    returns the per-walk scores as float64 and the mean tentative collisions
    per walk."""
    import numpy as np

    kernel = dr.syntax(_walks)

    def run(walks, seed):
        weight, steps = kernel(medium, o, d, delta, walks, dr.opaque(mi.UInt64, seed))
        dr.eval(weight, steps)
        return np.asarray(weight, dtype=np.float64), float(np.mean(np.asarray(steps)))

    return run


def mitsuba_light(volume, exp):
    """A function of ``(walks, seed, passes)`` rendering V-L with ``walks``
    samples in ``passes`` renders (the harness's scene: volpath, max_depth 2,
    radiancemeter); returns the renders' means (float64) and the samples of
    each. Timed runs are one render; the pilot's 64 give the variance."""
    import numpy as np

    scene = volume.single_scattering_scene(exp, 1)[0]

    def run(walks, seed, passes=1):
        spp = max(1, math.ceil(walks / passes))
        values = np.empty(passes)
        for k in range(passes):
            img = mi.render(scene, spp=spp, seed=(seed * 7919 + k) % 2 ** 32)
            values[k] = float(np.mean(np.asarray(img, dtype=np.float64)[0, 0, :3]))
        return values, spp

    return run


# ----------------------------------------------------------------------------
# The race


def walks_for(mean, var_one, target):
    """Walks for a relative standard error ``target``: var / (target mean)^2."""
    return max(2, math.ceil(var_one / (target * mean) ** 2))


def race(name, lq, mts, target, repeats, pilot, small=2 ** 12):
    """Times both sides to ``target``; returns a result row (a dict).

    Each side is also timed the same way on ``small`` walks: that time is
    mostly its fixed cost per call (lightquad: the spans' majorants; Mitsuba:
    tracing the Dr.Jit loop or setting up a render, and launching it), and
    the ratio of the differences compares the walks alone."""
    # lightquad: pilot for the variance of one walk, then timed runs.
    v, se, _, _ = lq(pilot, 1)
    var_lq = se * se * pilot
    n_lq = walks_for(v, var_lq, target)
    lq_runs = [lq(n_lq, 100 + k) for k in range(repeats)]
    lq_small = statistics.median(lq(small, 200 + k)[2] for k in range(repeats))
    # Mitsuba: the pilot also compiles the kernel.
    m = mts(pilot, 1, pilot=True)
    v_m, var_m = m["mean"], m["var_one"]
    n_m = walks_for(v_m, var_m, target)

    def timed(walks, seed):
        t0 = time.perf_counter()
        r = mts(walks, seed)
        return time.perf_counter() - t0, r

    m_timed = [timed(n_m, 100 + k) for k in range(repeats)]
    m_small = statistics.median(timed(small, 200 + k)[0] for k in range(repeats))
    t_lq = statistics.median(r[2] for r in lq_runs)
    t_m = statistics.median(t for t, _ in m_timed)
    m_first = m_timed[0][1]
    # A single render has no spread of its own: its standard error is the
    # pilot's variance over its samples.
    m_se = m_first["se"] if math.isfinite(m_first["se"]) else math.sqrt(var_m / n_m)
    return {
        "race": name,
        "lightquad": {"walks": n_lq, "seconds": t_lq, "small_seconds": lq_small,
                      "value": lq_runs[0][0], "rel_se": lq_runs[0][1] / lq_runs[0][0],
                      "lookups_per_walk": lq_runs[0][3], "var_one": var_lq},
        "mitsuba": {"walks": n_m, "seconds": t_m, "small_seconds": m_small,
                    "value": m_first["mean"], "rel_se": m_se / m_first["mean"],
                    "lookups_per_walk": m_first.get("steps"), "var_one": var_m},
        "small_walks": small,
        "ratio": t_lq / t_m,
        # Only where both runs are many times the small one.
        "ratio_without_fixed": ((t_lq - lq_small) / (t_m - m_small)
                                if min(n_lq, n_m) >= 8 * small else None),
    }


def table(rows, args):
    """The rows as a Markdown table, with the agreement of the two estimates
    (their difference over its standard error)."""
    lines = [
        f"Time to a relative standard error of {args.target:g}, {args.threads} thread(s) "
        f"each, median of {args.repeats} runs; ratio = lightquad / Mitsuba (< 1: lightquad "
        "faster). 'Fixed': the time of a run of 4096 walks on the same side, mostly its "
        "cost per call; the last ratio compares the times less it.",
        "",
        "| estimator | lightquad walks | look-ups a walk | lightquad | fixed "
        "| Mitsuba walks | look-ups a walk | Mitsuba | fixed | ratio | ratio less fixed "
        "| estimates differ by |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        lq, m = r["lightquad"], r["mitsuba"]
        se = math.hypot(lq["rel_se"] * lq["value"], m["rel_se"] * m["value"])
        z = (lq["value"] - m["value"]) / se
        m_lookups = "-" if m["lookups_per_walk"] is None else f"{m['lookups_per_walk']:.2f}"
        lines.append(
            f"| {r['race']} | {lq['walks']:,} | {lq['lookups_per_walk']:.2f} | "
            f"{lq['seconds'] * 1e3:.1f} ms | {lq['small_seconds'] * 1e3:.1f} ms | "
            f"{m['walks']:,} | {m_lookups} | {m['seconds'] * 1e3:.1f} ms | "
            f"{m['small_seconds'] * 1e3:.1f} ms | {r['ratio']:.2f} | "
            f"{'-' if r['ratio_without_fixed'] is None else format(r['ratio_without_fixed'], '.2f')}"
            f" | {z:+.1f} SE |")
    lines += [
        "",
        "Look-ups: density evaluations at tentative collisions (lightquad's V-L "
        "also reads its shadow rays' majorants, 1 a shadow ray, which are not counted). "
        "Mitsuba's medium has one global majorant (k = 1 for ratio tracking); "
        "lightquad's spans (16; 32 for delta tracking of V-tau; one on a shadow ray) each have "
        "their own, and "
        "ratio tracking draws at "
        "k = min(2D, 256/D) times it (src/volume/tracking/span.rs). Mitsuba computes in "
        "float32 (an independent check put its ratio tracking 0.1%, 2.3 SE, below "
        "the exact tau at 2e7 walks; within the noise at a 1e-3 target); with "
        "--quick the fixed costs dominate and the plain ratio says little.",
    ]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--target", type=float, default=1e-3, help="relative standard error")
    ap.add_argument("--threads", type=int, default=2, help="threads on both sides")
    ap.add_argument("--repeats", type=int, default=5, help="timed runs, median")
    ap.add_argument("--quick", action="store_true", help="target 1e-2, 2 repeats: a smoke run")
    ap.add_argument("--json", type=Path, help="also write the rows to this file")
    ap.add_argument("--only", choices=["ratio", "delta", "light"], action="append",
                    help="race only this estimator (repeatable; default all three)")
    args = ap.parse_args()
    if args.quick:
        args.target, args.repeats = 1e-2, 2
    reexec_in_venv()
    import numpy as np

    volume = mitsuba_setup(args.threads)
    binary = lightquad_binary()
    tmp = Path(tempfile.mkdtemp(prefix="lq-race-"))
    exp_dict = grid_experiment()
    path = tmp / "race-grid-32.json"
    path.write_text(json.dumps(exp_dict))
    sys.path.insert(0, str(ROOT / "reference"))
    from lqref import spec

    exp = spec.load(path)
    scene, medium = volume.build_scene(exp)
    o = [float(x) for x in exp.scene.origin]
    d = [float(x) for x in exp.scene.direction]

    def lq_side(estimator):
        return lambda walks, seed: lightquad_run(binary, path, estimator, walks, seed,
                                                  args.threads)

    def tracker_side(delta):
        run = mitsuba_tracker(medium, o, d, delta)

        def side(walks, seed, pilot=False):
            w, steps = run(walks, seed)
            mean = float(np.mean(w))
            var = float(np.var(w, ddof=1))
            return {"mean": mean, "var_one": var, "se": math.sqrt(var / w.size),
                    "steps": steps}

        return side

    def light_side():
        run = mitsuba_light(volume, exp)

        def side(walks, seed, pilot=False):
            # The pilot's 64 renders pin the variance down; a timed run is
            # one render (each render has a fixed cost).
            values, spp = run(walks, seed, 64 if pilot else 1)
            # A render's variance times its samples: the variance of one sample.
            var = float(np.var(values, ddof=1)) * spp if values.size > 1 else math.nan
            return {"mean": float(np.mean(values)), "var_one": var,
                    "se": math.sqrt(var / (spp * values.size))}

        return side

    pilot = 2 ** 16
    races = {
        "ratio": lambda: race("V-tau, ratio tracking", lq_side("ratio-tracking"),
                              tracker_side(False), args.target, args.repeats, pilot),
        "delta": lambda: race("V-tau, delta tracking", lq_side("delta-tracking"),
                              tracker_side(True), args.target, args.repeats, pilot),
        "light": lambda: race("V-L, free-flight single scattering",
                              lq_side("free-flight-light"), light_side(), args.target,
                              args.repeats, pilot),
    }
    rows = [run() for name, run in races.items() if not args.only or name in args.only]
    print(table(rows, args))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
