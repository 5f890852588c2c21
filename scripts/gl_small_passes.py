#!/usr/bin/env python3
"""Paired rounds at a few nodes (`scripts/gl_race.sh`) in passes spread over minutes.

    python3 scripts/gl_small_passes.py [PASSES] [--pause SECONDS] [--n N ...]

(default 6 passes, 40 s apart, n = 5, 10, 20, 50, 100). A pass runs
`bash scripts/gl_race.sh 7 101 --serial --n N --calls 20000/N` at each n:
seven processes of 101 interleaved rounds each. One such run takes about
two seconds, so its seven processes sample where the stack and the code
fall, not the minute the shared machine is having: a whole run can sit 1%
off the next one (n = 10, issue 55's eighth session: 1.0119, then 0.9980,
0.9971 and 0.9967 a minute later). The figure here is the median over the
passes of each run's median, printed with every pass's value; the faster
peer at each n is the one `FixedOrder` is the larger ratio against, in that
median.
"""

import argparse
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CONTENDERS = ("fixed", "rule")
PEERS = ("bilby", "gauss-quad")
ROW = re.compile(r"^\| lightquad (fixed|rule) / (bilby|gauss-quad) \| ([0-9.]+) \|")


def one_run(n):
    """Each `lightquad X / peer` median of one gl_race.sh run at n."""
    run = subprocess.run(
        ["bash", "scripts/gl_race.sh", "7", "101", "--serial", "--n", str(n), "--calls", str(max(1, 20000 // n))],
        cwd=ROOT, capture_output=True, text=True, check=False,
    )
    if run.returncode != 0:
        raise RaceFailed(f"gl_race.sh at n = {n} failed (exit {run.returncode}):\n{run.stderr[-2000:]}")
    found = {}
    for line in run.stdout.splitlines():
        m = ROW.match(line)
        if m:
            found[(m.group(1), m.group(2))] = float(m.group(3))
    want = {(c, p) for c in CONTENDERS for p in PEERS}
    if set(found) != want:
        raise RaceFailed(f"gl_race.sh at n = {n} printed {sorted(found)}, expected {sorted(want)}")
    return found


class RaceFailed(Exception):
    """A gl_race.sh run that failed or printed other rows."""


def table(runs, passes):
    """The median over `passes` whole passes of each ratio, with each pass's value."""
    print(f"Median over {passes} passes of each gl_race.sh run's median (7 processes, 101 rounds):\n")
    print("| n | ratio | median over passes | each pass |")
    print("|---:|---|---:|---|")
    for n, done in runs.items():
        done = done[:passes]
        med = {k: statistics.median(r[k] for r in done) for k in done[0]}
        faster = max(PEERS, key=lambda peer: med[("fixed", peer)])
        for c in CONTENDERS:
            for peer in PEERS:
                mark = " (faster peer)" if peer == faster else ""
                each = " ".join(f"{r[(c, peer)]:.4f}" for r in done)
                print(f"| {n} | {c} / {peer}{mark} | {med[(c, peer)]:.4f} | {each} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("passes", nargs="?", type=int, default=6, help="passes, 1 to 100 (default 6)")
    ap.add_argument("--pause", type=float, default=40.0, help="seconds between passes (default 40)")
    ap.add_argument(
        "--n", type=int, nargs="+", default=[5, 10, 20, 50, 100],
        help="orders, distinct, 1 to 100 (default 5 10 20 50 100)",
    )
    a = ap.parse_args()
    if not 1 <= a.passes <= 100:
        ap.error(f"PASSES {a.passes}: expected 1 to 100")
    if not 0 <= a.pause <= 3600:
        ap.error(f"--pause {a.pause}: expected 0 to 3600 seconds")
    if any(not 1 <= n <= 100 for n in a.n) or len(set(a.n)) != len(a.n):
        ap.error(f"--n {a.n}: expected distinct orders from 1 to 100")
    runs = {n: [] for n in a.n}
    for p in range(a.passes):
        if p:
            time.sleep(a.pause)
        try:
            for n in a.n:
                runs[n].append(one_run(n))
        except RaceFailed as e:
            print(e, file=sys.stderr)
            if p:
                print(f"\nThe {p} whole pass(es) before it:\n")
                table(runs, p)
            sys.exit(1)
        print(f"pass {p + 1} of {a.passes} done", file=sys.stderr)
    table(runs, a.passes)


if __name__ == "__main__":
    main()
