#!/usr/bin/env bash
# The Mitsuba 3 reference harness (reference/): creates reference/.venv with the
# pinned requirements, then
#   scripts/reference.sh          regenerates every committed values file at full
#                                 accuracy (each file records its seconds in
#                                 `run_seconds`; README.md gives their sum);
#   scripts/reference.sh --ci     runs the harness's pytest suite, checks that no
#                                 committed values file is stale, and regenerates
#                                 one transmittance and one single-scattering value
#                                 with few samples into a scratch folder, which the
#                                 Rust test tests/it/mitsuba.rs then checks against
#                                 lightquad (so the harness cannot rot), and runs
#                                 one bundled experiment with Mitsuba as an
#                                 external estimator (reference/serve.py).
set -euo pipefail
cd "$(dirname "$0")/.."

venv=reference/.venv
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
# The package registry can hiccup: three tries.
for attempt in 1 2 3; do
  if "$venv/bin/pip" install --quiet --disable-pip-version-check -r reference/requirements.txt; then
    break
  fi
  if [ "$attempt" = 3 ]; then
    echo "reference.sh: pip install -r reference/requirements.txt failed three times" >&2
    exit 1
  fi
  sleep 10
done

if [ "${1:-}" = "--ci" ]; then
  (cd reference && .venv/bin/python -m pytest -q -p no:cacheprovider)
  (cd reference && .venv/bin/python -m lqref --check)
  scratch=$(mktemp -d)
  trap 'rm -rf "$scratch"' EXIT
  (cd reference && .venv/bin/python -m lqref --quick --out "$scratch" \
    ../experiments/mitsuba-tau-constant-sphere.json ../experiments/v-l-single-scattering.json \
    ../experiments/r-h-vs-a-tilted-rectangle.json ../experiments/mitsuba-r-furnace-bounces.json \
    ../experiments/w-ss-edge-coverage.json ../experiments/exchange-perpendicular-squares.json)
  LIGHTQUAD_REFERENCE_VALUES="$scratch" cargo test --release --test it mitsuba::
  # Mitsuba as an external estimator (reference/serve.py): one small bundled
  # experiment run through it; every one of its jobs must have answered.
  cargo run --release --quiet -- run experiments/mitsuba-r-furnace-bounces.json --out "$scratch/external"
  python3 - "$scratch/external/mitsuba-r-furnace-bounces/results.jsonl" <<'PY'
import json, sys
rows = [json.loads(l) for l in open(sys.argv[1])]
mitsuba = [r for r in rows if r["rule"] == "mitsuba"]
failed = [r["failure"] for r in mitsuba if r["failure"]]
if not mitsuba or failed:
    sys.exit(f"reference.sh: Mitsuba as an external estimator: {len(mitsuba)} jobs, failures {failed[:3]}")
print(f"reference.sh: Mitsuba answered all {len(mitsuba)} of its jobs as an external estimator")
PY
else
  # Every experiment that has a committed values file (Mitsuba cannot express
  # every scene: Gaussian blobs, linear gradients and volumetric emission have
  # no counterpart there).
  mapfile -t files < <(cd reference && .venv/bin/python -c '
import json, pathlib
for p in sorted(pathlib.Path("values").glob("*.json")):
    print("../" + json.loads(p.read_text())["experiment_file"])')
  (cd reference && .venv/bin/python -m lqref "${files[@]}")
fi
