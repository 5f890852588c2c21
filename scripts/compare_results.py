#!/usr/bin/env python3
"""Compares two report folders' results.jsonl value for value.

    python3 scripts/compare_results.py OLD_REPORT_DIR NEW_REPORT_DIR [EXPERIMENT ...]

Each folder holds one sub-folder per experiment with a results.jsonl (one
JSON object per job). Both result formats are read: the old one (`values`,
`estimated_errors`, `evaluations` maps of scalars) and the family-generic one
(`quantities: {name: {value: [..], error: [..], evaluations}}`). For every
job (experiment, rule index, budget, repeat) the rule name, seed, failure and,
per quantity, every value, error estimate and evaluation count must agree bit
for bit (non-finite values match each other: the old format wrote them all
as null). Timings, hashes, versions, machines and flags are
not compared. With experiment names given, only those are compared; by
default, the experiments both folders have. Exit status 0 when everything
agrees and both folders hold the same jobs.
"""

import json
import struct
import sys
from pathlib import Path


def bits(x):
    """A float's bit pattern. The old format wrote every non-finite value as
    null; the new one writes "inf", "-inf" or "NaN": a null matches any of them."""
    if x is None:
        return "non-finite"
    x = float(x)
    return "non-finite" if x != x or x in (float("inf"), float("-inf")) else struct.pack("<d", x).hex()


def job(line):
    r = json.loads(line)
    if "quantities" in r:
        qs = {k: (v["value"], v["error"], v["evaluations"]) for k, v in r["quantities"].items()}
    else:
        qs = {
            k: ([v], [r["estimated_errors"][k]], r["evaluations"][k])
            for k, v in r["values"].items()
        }
    key = (r["rule_index"], r["budget"], r["repeat"])
    return key, (r["rule"], r["seed"], r["failure"], qs)


def load(folder):
    out = {}
    for f in sorted(Path(folder).glob("*/results.jsonl")):
        out[f.parent.name] = dict(job(l) for l in f.read_text().splitlines() if l.strip())
    return out


def compare(name, old, new, problems):
    values = 0
    for key in sorted(set(old) | set(new)):
        if key not in old or key not in new:
            problems.append(f"{name} {key}: only in {'new' if key in new else 'old'}")
            continue
        (r0, s0, f0, q0), (r1, s1, f1, q1) = old[key], new[key]
        if (r0, s0, f0) != (r1, s1, f1):
            problems.append(f"{name} {key}: rule/seed/failure {(r0, s0, f0)} vs {(r1, s1, f1)}")
        if set(q0) != set(q1):
            problems.append(f"{name} {key}: quantities {sorted(q0)} vs {sorted(q1)}")
        for q in sorted(set(q0) & set(q1)):
            (v0, e0, n0), (v1, e1, n1) = q0[q], q1[q]
            values += len(v0) + len(e0) + 1
            if [bits(x) for x in v0] != [bits(x) for x in v1]:
                problems.append(f"{name} {key} {q}: value {v0} vs {v1}")
            if [bits(x) for x in e0] != [bits(x) for x in e1]:
                problems.append(f"{name} {key} {q}: error {e0} vs {e1}")
            if n0 != n1:
                problems.append(f"{name} {key} {q}: evaluations {n0} vs {n1}")
    return values


def main(argv):
    if len(argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    old, new = load(argv[1]), load(argv[2])
    names = argv[3:] or sorted(set(old) & set(new))
    problems, jobs, values = [], 0, 0
    for name in names:
        if name not in old or name not in new:
            problems.append(f"{name}: missing in {'old' if name not in old else 'new'}")
            continue
        before = len(problems)
        n = compare(name, old[name], new[name], problems)
        jobs += len(old[name])
        values += n
        print(f"{name}: {len(old[name])} jobs, {n} values, errors and counts compared, "
              f"{len(problems) - before} mismatches")
    for p in problems[:20]:
        print("  " + p)
    only = sorted(set(old) ^ set(new))
    if only:
        print(f"not compared (in one folder only): {', '.join(only)}")
    print(f"TOTAL: {jobs} jobs, {values} values, errors and counts compared, {len(problems)} mismatches")
    return 0 if not problems else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
