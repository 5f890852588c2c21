"""Computing an experiment's values with Mitsuba 3 (its family computes each
quantity), writing them, and checking values files against their experiment
files (stale when the hash differs)."""

import json
import math
import os
import platform
import time
from pathlib import Path

from . import spec
from .fnv import file_hash
from .mitsuba3 import versions

REFERENCE_DIR = Path(__file__).resolve().parent.parent  # reference/
REPO_ROOT = REFERENCE_DIR.parent
DEFAULT_OUT = REFERENCE_DIR / "values"


def _log(message):
    print(message, flush=True)


def compute(path, quick=False, out_dir=DEFAULT_OUT, log=_log):
    """Computes the supported quantities of the experiment at ``path`` with its
    family's sample counts (``quick``: a smoke run's) and writes
    ``out_dir/<name>.json``; returns the record. Raises SpecError for a fault in
    the file or a scene element Mitsuba cannot express."""
    from .families import FAMILIES  # here, not above: they need numpy, --check does not

    exp = spec.load(path)
    family = FAMILIES[exp.family]
    family.require_expressible(exp)
    settings = family.Settings(quick)
    digest = file_hash(path)
    start = time.perf_counter()
    values, unsupported = {}, {}
    for q in dict.fromkeys(exp.quantities):
        reason = family.unsupported_reason(exp, q)
        if reason is not None:
            unsupported[q] = reason
            continue
        t0 = time.perf_counter()
        result = family.compute(exp, q, settings)
        if not all(math.isfinite(result[key]) for key in ("value", "std_error")):
            raise spec.SpecError(
                "scene", f"Mitsuba's {q} came out {result['value']} +- {result['std_error']}: "
                         "not finite (float32 overflow?); no values file written")
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
        **versions(),
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
