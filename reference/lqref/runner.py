"""Computing an experiment's values with Mitsuba 3, writing them, and checking
values files against their experiment files (stale when the hash differs)."""

import json
import os
import platform
import time
from pathlib import Path

from . import spec as spec_mod
from .fnv import file_hash
from .spec import SpecError

REFERENCE_DIR = Path(__file__).resolve().parent.parent  # reference/
REPO_ROOT = REFERENCE_DIR.parent
DEFAULT_OUT = REFERENCE_DIR / "values"
EXPRESSIBLE_MEDIA = ("constant-sphere", "voxel-grid")

NO_EMISSION = ("Mitsuba 3 media have no volumetric emission (homogeneous and heterogeneous "
               "media take no radiance): no counterpart of V-E")


def unsupported_reason(exp, quantity):
    """Why ``quantity`` is not computed for ``exp``, or None if it is."""
    if quantity == "I_E":
        return NO_EMISSION
    if quantity == "I_B":
        return ("not computed by this harness: I_B = I_b * tau, use the tau value "
                "(or add a function for it)")
    if quantity == "I":
        if exp.emission is not None:
            return "I = I_E + I_B + I_L needs I_E: " + NO_EMISSION
        return "not computed by this harness: I = I_B + I_L here, I_B is not computed"
    if quantity == "I_L" and exp.light is None:
        return "the scene has no light"
    return None


def _log(message):
    print(message, flush=True)


def compute(path, settings, out_dir=DEFAULT_OUT, log=_log):
    """Computes the supported quantities of the experiment at ``path`` and
    writes ``out_dir/<name>.json``; returns the record. Raises SpecError for a
    scene element Mitsuba cannot express."""
    from . import mitsuba_scene as ms
    from . import quantities as qt

    exp = spec_mod.load(path)
    if exp.medium is not None and exp.medium["type"] not in EXPRESSIBLE_MEDIA:
        raise SpecError(
            "scene.medium.type",
            f"Mitsuba 3 cannot express a `{exp.medium['type']}` medium: its media are "
            "homogeneous or voxel grids (gridvolume), and a voxelised copy would be a "
            "different field")
    digest = file_hash(path)
    start = time.perf_counter()
    values, unsupported = {}, {}
    for q in dict.fromkeys(exp.quantities):
        reason = unsupported_reason(exp, q)
        if reason is not None:
            unsupported[q] = reason
            continue
        t0 = time.perf_counter()
        if q == "tau":
            if exp.medium is None:
                result = {"value": 1.0, "std_error": 0.0, "samples": 0,
                          "method": "no medium: tau = 1"}
            elif exp.medium["type"] == "constant-sphere":
                result = qt.tau_constant_sphere(exp, settings)
            else:
                result = qt.tau_voxel_grid(exp, settings)
        elif q == "I_L":
            if exp.medium is None:
                result = {"value": 0.0, "std_error": 0.0, "samples": 0,
                          "method": "no medium: nothing scatters, I_L = 0"}
            else:
                result = qt.light_single_scattering(exp, settings)
        else:  # unreachable: every quantity has a reason or a function
            raise AssertionError(q)
        result["seconds"] = round(time.perf_counter() - t0, 3)
        values[q] = result
        log(f"  {q:4s} = {result['value']:.10g} +- {result['std_error']:.3g}"
            f"  ({result['seconds']:.1f} s)")
    for q, why in unsupported.items():
        log(f"  {q:4s}   unsupported: {why}")

    record = {
        "experiment": exp.name,
        "experiment_file": _display_path(path),
        "experiment_hash": digest,
        **ms.versions(),
        "settings": settings.as_dict(),
        "seed": exp.seed,
        "machine": f"{platform.machine()} {platform.system()}, {os.cpu_count()} cpus, "
                   f"Python {platform.python_version()}",
        "run_seconds": round(time.perf_counter() - start, 3),
        "quantities": values,
        "unsupported": unsupported,
    }
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    target = out_dir / f"{exp.name}.json"
    tmp = target.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(record, indent=2) + "\n")
    tmp.replace(target)
    return record


def _display_path(path):
    p = Path(path).resolve()
    try:
        return str(p.relative_to(REPO_ROOT))
    except ValueError:
        return str(p)


def check(paths, out_dir=DEFAULT_OUT):
    """Compares values files with their experiment files. With ``paths``: the
    values file of each experiment file; without: every values file against the
    experiment file it records. Returns ``[(status, name, message)]`` with
    status ``ok``, ``stale`` or ``missing``."""
    out_dir = Path(out_dir)
    report = []
    if paths:
        pairs = []
        for p in paths:
            name = json.loads(Path(p).read_text())["name"]
            pairs.append((Path(p), out_dir / f"{name}.json", name))
    else:
        pairs = []
        for v in sorted(out_dir.glob("*.json")):
            rec = json.loads(v.read_text())
            exp_file = Path(rec.get("experiment_file", ""))
            if not exp_file.is_absolute():
                exp_file = REPO_ROOT / exp_file
            pairs.append((exp_file, v, rec.get("experiment", v.stem)))
    for exp_file, values_file, name in pairs:
        if not exp_file.is_file():
            report.append(("missing", name, f"experiment file {exp_file} not found "
                                             f"(recorded in {values_file})"))
            continue
        if not values_file.is_file():
            report.append(("missing", name, f"no values file {values_file}"))
            continue
        recorded = json.loads(values_file.read_text()).get("experiment_hash")
        now = file_hash(exp_file)
        if recorded == now:
            report.append(("ok", name, f"{values_file} matches {exp_file} ({now})"))
        else:
            report.append(("stale", name,
                           f"{values_file} was computed from hash {recorded}, "
                           f"{exp_file} now hashes to {now}: "
                           f"rerun python -m lqref {exp_file}"))
    return report
