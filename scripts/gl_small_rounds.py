#!/usr/bin/env python3
"""Criterion's `gl_small` bench in rounds, the contenders side by side.

    python3 scripts/gl_small_rounds.py [ROUNDS] [--n N ...] [--raw FILE]
    python3 scripts/gl_small_rounds.py --from FILE [FILE ...]

(default 7 rounds, n = 5, 10, 20, 50, 100; `--raw` writes every round's
medians as JSON; `--from` runs nothing and reports the rounds of such
files together). Criterion times the contenders
of a group one after another, so that a minute in which the shared machine
is busy falls on one contender and not its peers: one run of the bench
moved a contender's median by a third from one run to the next
(`benches/README.md`, `gl_small`, sixth session). Here each round runs the
bench binary once for each n and contender, filtered to that one benchmark
(criterion's own sampling, warm-up and median, unchanged), the contenders
in an order rotated from round to round. Each round's ratios are taken
between medians measured within seconds of each other; the figure for a
ratio is their median over the rounds, printed with every round's value.

The bench binary is built first (`cargo bench --no-run`); its criterion
output goes to a temporary directory (`CRITERION_HOME`), so that no saved
baseline under `target/criterion` is read or changed.
"""

import argparse
import json
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# The bench's names (benches/quadrature.rs, `gl_small`) and their short
# labels here.
CONTENDERS = {
    "lightquad/fixed": "fixed",
    "lightquad": "rule",
    "lightquad/estimate": "estimate",
    "bilby": "bilby",
    "gauss-quad": "gauss-quad",
}
PEERS = ("bilby", "gauss-quad")
# The orders the bench times.
BENCH_NS = (5, 10, 20, 50, 100)


def bench_binary():
    """Builds the `quadrature` bench and returns its executable."""
    built = subprocess.run(
        ["cargo", "bench", "--bench", "quadrature", "--no-run"],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    sys.stderr.write(built.stderr)
    found = re.search(r"\((target/release/deps/quadrature-[0-9a-f]+)\)", built.stderr)
    if built.returncode != 0 or not found:
        sys.exit("could not build the quadrature bench (cargo bench --no-run)")
    return ROOT / found.group(1)


def median_ns(binary, home, name, n):
    """Criterion's median for `gl_small/<name>/<n>`, in ns, from one run."""
    filter_ = "^" + re.escape(f"gl_small/{name}/{n}") + "$"
    env = dict(os.environ, CRITERION_HOME=str(home))
    run = subprocess.run(
        [str(binary), "--bench", "--noplot", filter_],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
    )
    if run.returncode != 0:
        sys.exit(f"gl_small/{name}/{n} failed:\n{run.stderr}")
    path = Path(home) / "gl_small" / name.replace("/", "_") / str(n) / "new" / "estimates.json"
    with open(path) as f:
        return json.load(f)["median"]["point_estimate"]


def one_round(binary, home, ns, r):
    """Every contender at every n; the order rotated by the round `r`."""
    names = list(CONTENDERS)
    times = {}
    for n in ns:
        k = (r + ns.index(n)) % len(names)
        for name in names[k:] + names[:k]:
            times[(CONTENDERS[name], n)] = median_ns(binary, home, name, n)
    return times


def faster_peer(rounds, n):
    """The peer whose median over the rounds is the lower at `n`. Taken
    round by round, the lower of two noisy medians would favour the peers."""
    return min(PEERS, key=lambda p: statistics.median(t[(p, n)] for t in rounds))


def ratio_rows(rounds, ns):
    """Per n, each ratio's median over the rounds and every round's value."""
    rows = []
    for n in ns:
        peer = faster_peer(rounds, n)
        pairs = {
            f"fixed / {peer}": ("fixed", peer),
            f"rule / {peer}": ("rule", peer),
            "estimate / rule": ("estimate", "rule"),
        }
        per = {name: [t[(x, n)] / t[(y, n)] for t in rounds] for name, (x, y) in pairs.items()}
        rows.append((n, per))
    return rows


def write_raw(path, rounds, binary):
    """Every round's medians, written whole or not at all."""
    raw = {
        "commit": git_head(),
        "binary": binary.name,
        "rounds": [
            [{"contender": c, "n": n, "median_ns": t} for (c, n), t in r.items()]
            for r in rounds
        ],
    }
    path = Path(path)
    partial = path.with_name(path.name + ".partial")
    partial.write_text(json.dumps(raw, indent=1) + "\n")
    partial.replace(path)


def git_head():
    """The commit measured, with `+` where the work tree differs from it."""
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True)
    dirty = subprocess.run(["git", "diff", "--quiet", "HEAD", "--", "src", "benches/*.rs", "Cargo.toml", "Cargo.lock"], cwd=ROOT)
    return head.stdout.strip() + ("+" if dirty.returncode else "")


def median_interval(values):
    """An interval holding the median with at least 95% confidence, from
    the order statistics, free of any distribution: the `j`-th lowest and
    highest of `k` values, `j` the largest with `P(B < j) <= 0.025`, `B`
    binomial (k, 1/2). It covers more than 95% where no `j` gives 95%
    exactly (98.8% at 11 rounds, 96.5% at 33); `None` below 6 values,
    where even the least and the largest cover less."""
    k = len(values)
    ordered = sorted(values)
    below, j = 0.0, 0
    while below + math.comb(k, j) / 2**k <= 0.025:
        below += math.comb(k, j) / 2**k
        j += 1
    if j == 0:
        return None
    return ordered[j - 1], ordered[k - j]


def read_raw(paths):
    """The rounds of `--raw` files, and what they were measured on."""
    rounds, sources = [], []
    for path in paths:
        with open(path) as f:
            raw = json.load(f)
        sources.append(f"{Path(path).name} ({raw['commit']}, {len(raw['rounds'])} rounds)")
        for r in raw["rounds"]:
            rounds.append({(e["contender"], e["n"]): e["median_ns"] for e in r})
    return rounds, ", ".join(sources)


def print_report(rounds, ns, source):
    print(f"{source}. Criterion medians in ns, median over {len(rounds)} rounds:\n")
    labels = list(CONTENDERS.values())
    print("| n | " + " | ".join(labels) + " |")
    print("|---:|" + "---:|" * len(labels))
    for n in ns:
        cells = [statistics.median(t[(c, n)] for t in rounds) for c in labels]
        print(f"| {n} | " + " | ".join(f"{c:.1f}" for c in cells) + " |")
    print("\nRatios within each round against the faster peer (the lower median over rounds), median over rounds:\n")
    print("| n | ratio | median | interval of the median (95% or more) | rounds below 1 | each round |")
    print("|---:|---|---:|---|---:|---|")
    for n, per in ratio_rows(rounds, ns):
        for name, values in per.items():
            below = sum(v < 1 for v in values)
            interval = median_interval(values)
            within = "– (under 6 rounds)" if interval is None else "{:.3f} to {:.3f}".format(*interval)
            each = " ".join(f"{v:.3f}" for v in values)
            print(
                f"| {n} | {name} | {statistics.median(values):.4f} | {within} "
                f"| {below} of {len(values)} | {each} |"
            )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("rounds", nargs="?", type=int, default=7)
    parser.add_argument("--n", type=int, nargs="+", default=list(BENCH_NS))
    parser.add_argument("--raw", help="write every round's medians here, as JSON")
    parser.add_argument("--from", dest="sources", nargs="+", help="report these --raw files' rounds, run nothing")
    args = parser.parse_args()
    if args.sources:
        try:
            rounds, source = read_raw(args.sources)
            ns = [n for n in args.n if all((c, n) in t for t in rounds for c in CONTENDERS.values())]
        except (OSError, ValueError, KeyError, TypeError) as e:
            parser.error(f"--from: {e!r}: expected files written by --raw")
        if not rounds or not ns:
            parser.error("--from: no round holds every contender at any of the n asked for")
        print_report(rounds, ns, source)
        return
    if args.rounds < 1:
        parser.error(f"ROUNDS {args.rounds}: expected at least 1")
    bad = [n for n in args.n if n not in BENCH_NS]
    if bad:
        parser.error(f"--n {bad}: the bench times n = 5, 10, 20, 50 and 100")
    if args.raw and not Path(args.raw).resolve().parent.is_dir():
        parser.error(f"--raw {args.raw}: its folder does not exist")
    binary = bench_binary()
    rounds = []
    with tempfile.TemporaryDirectory() as home:
        for r in range(args.rounds):
            rounds.append(one_round(binary, home, args.n, r))
            print(f"round {r + 1} of {args.rounds} done", file=sys.stderr)
    if args.raw:
        write_raw(args.raw, rounds, binary)
    print_report(rounds, args.n, f"Commit {git_head()}")


if __name__ == "__main__":
    main()
