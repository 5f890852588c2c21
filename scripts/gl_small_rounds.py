#!/usr/bin/env python3
"""Criterion's `gl_small` bench in rounds, the contenders side by side.

    python3 scripts/gl_small_rounds.py [ROUNDS] [--n N ...] [--raw FILE]
    python3 scripts/gl_small_rounds.py --from FILE [FILE ...] [--n N ...]

(default 7 rounds, n = 5, 10, 20, 50, 100; `--raw` writes every round's
medians as JSON, again after each round, to a file that must not exist yet;
`--from` runs nothing and reports the rounds of such files together).

Criterion times the contenders of a group one after another, so that a
minute in which the shared machine is busy falls on one contender and not
its peers: one run of the bench moved a contender's median by a third from
one run to the next (`benches/README.md`, `gl_small`, sixth session). Here
each round runs the bench binary once for each n and contender, filtered to
that one benchmark (criterion's own sampling, warm-up and median,
unchanged), the contenders in an order rotated from round to round. Each
round's ratios are taken between medians measured within seconds of each
other; the figure for a ratio is their median over the rounds, printed with
an interval of that median and every round's value.

The bench binary is built first (`cargo bench --no-run`) and copied, so that
a rebuild during the run changes nothing measured; its criterion output goes
to a temporary directory (`CRITERION_HOME`), so that no saved baseline under
`target/criterion` is read or changed. One run at a time: a second waits
for nothing and stops with an error, since two would time each other.
"""

import argparse
import fcntl
import json
import math
import os
import re
import shutil
import signal
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
LABELS = tuple(CONTENDERS.values())
PEERS = ("bilby", "gauss-quad")
# The orders the bench times.
BENCH_NS = (5, 10, 20, 50, 100)
MAX_ROUNDS = 1000


def sources():
    """What the bench binary is built from: build.rs's own list of the
    crate's sources (its `SOURCES`, read from build.rs, so that the two
    cannot drift apart), and the bench; None where build.rs has no such
    list."""
    try:
        text = (ROOT / "build.rs").read_text()
    except OSError:
        return None
    found = re.search(r"const SOURCES: \[&str; \d+\] = \[(.*?)\];", text, re.S)
    if not found:
        return None
    return re.findall(r'"([^"]+)"', found.group(1)) + ["benches/quadrature.rs"]


STOPPING = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


class Stop(Exception):
    """A run stopped by a signal (SIGINT, SIGTERM, SIGHUP)."""

    def __init__(self, signum):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


def stop_on_signal(signum, _frame):
    raise Stop(signum)


def child(command, **options):
    """`subprocess.run` in a process group of its own, the whole group
    killed if this one stops (cargo's rustc with cargo)."""
    try:
        process = subprocess.Popen(command, start_new_session=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **options)
    except OSError as e:
        raise SystemExit(f"could not run {command[0]}: {e.strerror}")
    try:
        out, err = process.communicate()
    except BaseException:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
        raise
    return subprocess.CompletedProcess(command, process.returncode, out, err)


def git(*args):
    """git's output, or None where git or the command fails."""
    try:
        done = subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True)
    except OSError:
        return None
    return done.stdout if done.returncode == 0 else None


def source_stamp():
    """The commit measured, `+` where the sources differ from it (untracked
    files included); `unknown` outside a checkout of this repository (as
    build.rs tells it: build.rs tracked by the repository around it)."""
    if git("ls-files", "--error-unmatch", "build.rs") is None:
        return "unknown (not a git checkout of lightquad)"
    head = git("rev-parse", "--short", "HEAD")
    paths = sources()
    if head is None:
        return "unknown (no commit)"
    if paths is None:
        return head.strip() + " (whether the sources differ from it is unknown: build.rs lists no SOURCES)"
    changes = git("--no-optional-locks", "status", "--porcelain", "--", *paths)
    return head.strip() + ("" if changes == "" else "+")


def bench_binary(folder):
    """Builds the `quadrature` bench, copies its executable into `folder`
    and returns the copy."""
    built = child(["cargo", "bench", "--bench", "quadrature", "--no-run", "--message-format=json"], cwd=ROOT)
    sys.stderr.write(built.stderr)
    executables = []
    for line in built.stdout.splitlines():
        try:
            message = json.loads(line)
        except ValueError:
            continue
        if message.get("reason") == "compiler-artifact" and message.get("target", {}).get("name") == "quadrature":
            executables.append(message.get("executable"))
    executables = [e for e in executables if e]
    if built.returncode != 0 or not executables:
        raise SystemExit("could not build the quadrature bench (cargo bench --bench quadrature --no-run)")
    copy = Path(folder) / Path(executables[-1]).name
    shutil.copy2(executables[-1], copy)
    return copy


def median_ns(binary, home, name, n):
    """Criterion's median for `gl_small/<name>/<n>`, in ns, from one run."""
    estimates = Path(home) / "gl_small" / name.replace("/", "_") / str(n) / "new" / "estimates.json"
    estimates.unlink(missing_ok=True)
    filter_ = "^" + re.escape(f"gl_small/{name}/{n}") + "$"
    run = child([str(binary), "--bench", "--noplot", filter_], cwd=ROOT, env=dict(os.environ, CRITERION_HOME=str(home)))
    if run.returncode != 0:
        raise SystemExit(f"gl_small/{name}/{n} failed:\n{run.stderr}")
    try:
        with open(estimates) as f:
            return json.load(f)["median"]["point_estimate"]
    except (OSError, ValueError, KeyError) as e:
        raise SystemExit(f"gl_small/{name}/{n}: no median from criterion ({e}): is the benchmark still named so in benches/quadrature.rs?")


def one_round(binary, home, ns, r):
    """Every contender at every n; the order rotated by the round `r`."""
    names = list(CONTENDERS)
    times = {}
    for i, n in enumerate(ns):
        k = (r + i) % len(names)
        for name in names[k:] + names[:k]:
            times[(CONTENDERS[name], n)] = median_ns(binary, home, name, n)
    return times


def faster_peer(rounds, n):
    """The peer whose median over the rounds is the lower at `n`. Taken
    round by round, the lower of two noisy medians would favour the peers."""
    return min(PEERS, key=lambda p: statistics.median(t[(p, n)] for t in rounds))


def ratio_rows(rounds, ns):
    """Per n, each ratio's values over the rounds."""
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


def write_raw(path, rounds, stamp, binary):
    """Every round's medians so far, written whole or not at all."""
    raw = {
        "commit": stamp,
        "binary": binary.name,
        "rounds": [[{"contender": c, "n": n, "median_ns": t} for (c, n), t in r.items()] for r in rounds],
    }
    partial = path.with_name(path.name + ".partial")
    try:
        partial.write_text(json.dumps(raw, indent=1) + "\n")
        partial.replace(path)
    except OSError as e:
        partial.unlink(missing_ok=True)
        raise SystemExit(f"--raw {path}: could not write it ({e.strerror})")


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
    """The rounds of `--raw` files, each checked, and what they hold."""
    rounds, sources = [], []
    for path in paths:
        try:
            with open(path) as f:
                raw = json.load(f)
        except (OSError, ValueError) as e:
            raise SystemExit(f"--from {path}: not a readable JSON file ({e})")
        if not isinstance(raw, dict) or not isinstance(raw.get("rounds"), list) or not raw["rounds"]:
            raise SystemExit(f"--from {path}: expected a file written by --raw, an object with a list of rounds")
        for i, r in enumerate(raw["rounds"]):
            rounds.append(checked_round(path, i, r))
        sources.append(f"{path} ({raw.get('commit', 'unknown')}, {plural(len(raw['rounds']), 'round')})")
    return rounds, "; ".join(sources)


def checked_round(path, i, entries):
    """One round of a `--raw` file: each (contender, n) once, its median a
    finite positive number of ns."""
    where = f"--from {path}: rounds[{i}]"
    if not isinstance(entries, list):
        raise SystemExit(f"{where}: expected a list of medians")
    times = {}
    for e in entries:
        if not isinstance(e, dict):
            raise SystemExit(f"{where}: {e!r}: expected {{contender, n, median_ns}}")
        key, t = (e.get("contender"), e.get("n")), e.get("median_ns")
        if key[0] not in LABELS or key[1] not in BENCH_NS:
            raise SystemExit(f"{where}: contender {key[0]!r} at n = {key[1]!r}: expected one of {', '.join(LABELS)} at n in {BENCH_NS}")
        if key in times:
            raise SystemExit(f"{where}: {key[0]} at n = {key[1]} twice")
        try:
            t = float(t) if isinstance(t, (int, float)) and not isinstance(t, bool) else math.nan
        except OverflowError:
            t = math.inf
        if not math.isfinite(t) or t <= 0:
            raise SystemExit(f"{where}: {key[0]} at n = {key[1]}: median_ns = {e.get('median_ns')!r:.40}; expected a finite number above 0")
        times[key] = t
    return times


def plural(k, word):
    return f"{k} {word}" + ("" if k == 1 else "s")


def print_report(rounds, ns, source):
    print(f"{source}. Criterion medians in ns, median over {plural(len(rounds), 'round')}:\n")
    print("| n | " + " | ".join(LABELS) + " |")
    print("|---:|" + "---:|" * len(LABELS))
    for n in ns:
        cells = [statistics.median(t[(c, n)] for t in rounds) for c in LABELS]
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
            print(f"| {n} | {name} | {statistics.median(values):.4f} | {within} | {below} of {len(values)} | {each} |")


def arguments():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[1])
    parser.add_argument("rounds", nargs="?", type=int, help=f"rounds to run, 1 to {MAX_ROUNDS} (default 7)")
    parser.add_argument("--n", type=int, nargs="+", help="the orders, of 5 10 20 50 100 (default all)")
    parser.add_argument("--raw", help="write every round's medians here, as JSON (a new file)")
    parser.add_argument("--from", dest="sources", nargs="+", help="report these --raw files' rounds, run nothing")
    args = parser.parse_args()
    if args.n is not None:
        bad = [n for n in args.n if n not in BENCH_NS]
        if bad:
            parser.error(f"--n {' '.join(map(str, bad))}: the bench times n = 5, 10, 20, 50 and 100")
        if len(set(args.n)) != len(args.n):
            parser.error(f"--n {' '.join(map(str, args.n))}: each n once")
    if args.sources:
        if args.rounds is not None or args.raw is not None:
            parser.error("--from runs nothing: ROUNDS and --raw are for a run")
        same = {Path(p).resolve() for p in args.sources}
        if len(same) != len(args.sources):
            parser.error(f"--from {' '.join(args.sources)}: a file named twice")
        return args
    args.rounds = 7 if args.rounds is None else args.rounds
    if not 1 <= args.rounds <= MAX_ROUNDS:
        parser.error(f"ROUNDS {args.rounds}: expected 1 to {MAX_ROUNDS}")
    if args.raw is not None:
        raw = Path(args.raw)
        if args.raw == "" or raw.exists() or not raw.resolve().parent.is_dir():
            parser.error(f"--raw {args.raw!r}: expected a new file's path in a folder that exists")
        try:
            raw.with_name(raw.name + ".partial").open("x").close()
            raw.with_name(raw.name + ".partial").unlink()
        except OSError as e:
            parser.error(f"--raw {args.raw}: a file cannot be made there ({e.strerror})")
    return args


def report_saved(args):
    rounds, source = read_raw(args.sources)
    ns = list(args.n or BENCH_NS)
    missing = [n for n in ns if any((c, n) not in t for t in rounds for c in LABELS)]
    if args.n and missing:
        raise SystemExit(f"--n {' '.join(map(str, missing))}: not every round of the files holds every contender there")
    ns = [n for n in ns if n not in missing]
    if not ns:
        raise SystemExit("--from: no n at which every round holds every contender")
    if missing:
        print(f"left out n = {', '.join(map(str, missing))}: not in every round", file=sys.stderr)
    print_report(rounds, ns, source)


def run(args):
    stamp = source_stamp()
    raw = Path(args.raw) if args.raw else None
    ns = list(args.n or BENCH_NS)
    lock = take_lock()
    rounds = []
    with tempfile.TemporaryDirectory(prefix="gl_small_rounds.") as home:
        try:
            binary = bench_binary(home)
            for r in range(args.rounds):
                times = one_round(binary, home, ns, r)
                # The file and the count agree where a signal comes.
                signal.pthread_sigmask(signal.SIG_BLOCK, STOPPING)
                if raw:
                    write_raw(raw, rounds + [times], stamp, binary)
                rounds.append(times)
                signal.pthread_sigmask(signal.SIG_UNBLOCK, STOPPING)
                print(f"round {r + 1} of {args.rounds} done", file=sys.stderr)
        except Stop as e:
            saved = f"; {plural(len(rounds), 'round')} in {raw}" if raw and rounds else ""
            print(f"stopped by {e} after {plural(len(rounds), 'round')}{saved}", file=sys.stderr)
            raise SystemExit(128 + e.signum)
    lock.close()
    print_report(rounds, ns, f"Commit {stamp}")


def take_lock():
    """This checkout's lock on runs, held while the file stays open."""
    (ROOT / "target").mkdir(exist_ok=True)
    try:
        lock = open(ROOT / "target" / "gl_small_rounds.lock", "w")
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        raise SystemExit("another gl_small_rounds run is under way here: two at once would time each other")
    except OSError as e:
        raise SystemExit(f"target/gl_small_rounds.lock: cannot take the lock ({e.strerror})")
    return lock


def main():
    for signum in STOPPING:
        signal.signal(signum, stop_on_signal)
    try:
        args = arguments()
        if args.sources:
            report_saved(args)
        else:
            run(args)
    except Stop as e:
        raise SystemExit(128 + e.signum)
    except BrokenPipeError:
        # The reader went away (`| head`); the temporary folder is gone by now.
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        raise SystemExit(141)


if __name__ == "__main__":
    main()
