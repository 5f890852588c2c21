"""Command line: ``python -m lqref <experiment files...> [--quick] [--out DIR]``,
or ``python -m lqref --check [experiment files...]``."""

import argparse
import sys
import time

from .mitsuba3 import MitsubaMissing, require_mitsuba
from .runner import DEFAULT_OUT, check, compute
from .spec import SpecError


def main(argv=None):
    ap = argparse.ArgumentParser(
        prog="python -m lqref",
        description="Mitsuba 3 reference values for lightquad experiment files: writes "
                    "<out>/<experiment name>.json per file.")
    ap.add_argument("files", nargs="*", help="experiment files (JSON)")
    ap.add_argument("--quick", action="store_true",
                    help="few samples: a smoke run in seconds, not reference accuracy")
    ap.add_argument("--out", default=str(DEFAULT_OUT),
                    help="directory of the values files (default: reference/values)")
    ap.add_argument("--check", action="store_true",
                    help="only report stale (hash mismatch) or missing values files; "
                         "without files, check every values file in --out")
    args = ap.parse_args(argv)

    if args.check:
        bad = 0
        try:
            report = check(args.files, args.out)
        except (OSError, ValueError) as e:
            print(f"error: --check: {type(e).__name__}: {e}", file=sys.stderr)
            return 2
        for status, name, message in report:
            print(f"{status.upper():8s}{name}: {message}")
            bad += status != "ok"
        return 1 if bad else 0

    if not args.files:
        ap.error("give one or more experiment files (or --check)")

    try:  # the families' dependencies (numpy), before Mitsuba is even tried
        from . import families  # noqa: F401
    except ImportError as e:
        print(f"error: {e} (Python {sys.executable}).\nInstall the pinned versions with:\n"
              "    pip install -r reference/requirements.txt", file=sys.stderr)
        return 3
    try:
        require_mitsuba()
    except MitsubaMissing as e:
        print(f"error: {e}", file=sys.stderr)
        return 3

    failed = 0
    t0 = time.perf_counter()
    for path in args.files:
        print(f"{path}:", flush=True)
        try:
            rec = compute(path, args.quick, args.out)
        except SpecError as e:
            print(f"error: {path}: {e}", file=sys.stderr, flush=True)
            failed += 1
            continue
        except (OSError, ValueError, TypeError, KeyError, AttributeError, IndexError,
                RuntimeError) as e:
            # A file the readers did not foresee (a wrong type deep in the
            # scene, a shape Mitsuba refuses): said, and the next file runs.
            print(f"error: {path}: cannot compute it: {type(e).__name__}: {e}",
                  file=sys.stderr, flush=True)
            failed += 1
            continue
        print(f"  -> {args.out}/{rec['experiment']}.json ({rec['run_seconds']:.1f} s)")
    print(f"{len(args.files) - failed} of {len(args.files)} experiments in "
          f"{time.perf_counter() - t0:.1f} s")
    return 2 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
