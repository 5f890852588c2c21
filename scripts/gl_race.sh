#!/usr/bin/env bash
# Runs examples/gl_race.rs in several processes and prints, for each paired
# ratio, every process's median and the median over processes.
#
#   bash scripts/gl_race.sh [PROCESSES] [ROUNDS] [--serial | --parallel] [--n N] [--calls C]
#
# (defaults 7 processes of 201 rounds, every contender, 1e6 nodes; what
# follows ROUNDS goes to gl_race as it is). One process's
# median is sharp (its 95% interval is some +-0.2%), but the next process's
# can differ by more than that: where the stack and the node tables fall,
# and what the rest of the shared machine does that minute, move a ratio by
# one to two percent from process to process (1.0038 and 1.0184 for
# lightquad / bilby, two runs of 1001 rounds one after the other). So a
# claim about a ratio rests on several processes.
set -euo pipefail
cd "$(dirname "$0")/.."

processes=${1:-7}
rounds=${2:-201}
rest=("${@:3}")
case "$processes$rounds" in
  *[!0-9]* | '') echo "usage: $0 [PROCESSES] [ROUNDS] [--serial | --parallel] [--n N] [--calls C]" >&2; exit 2 ;;
esac
if [ "$processes" -lt 1 ]; then
  echo "PROCESSES $processes: expected at least 1" >&2
  exit 2
fi

cargo build --release --example gl_race >&2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for p in $(seq 1 "$processes"); do
  ./target/release/examples/gl_race "$rounds" "${rest[@]}" > "$out/$p.txt"
  echo "process $p of $processes done" >&2
done

# The ratio rows: `| name / name | median | interval | quartiles |`.
cat "$out"/*.txt | awk -F'|' -v processes="$processes" '
  $2 ~ / \/ / && $3 ~ /[0-9]/ {
    name = $2; gsub(/^ +| +$/, "", name)
    if (!(name in count)) order[++names] = name
    values[name, ++count[name]] = $3 + 0
  }
  END {
    printf "| ratio (%d processes) | median over processes | each process |\n", processes
    print "|---|---:|---|"
    for (i = 1; i <= names; i++) {
      name = order[i]; n = count[name]
      for (j = 1; j <= n; j++) v[j] = values[name, j]
      # Insertion sort: a handful of values.
      for (j = 2; j <= n; j++) {
        x = v[j]
        for (k = j - 1; k >= 1 && v[k] > x; k--) v[k + 1] = v[k]
        v[k + 1] = x
      }
      median = (n % 2) ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2
      each = ""
      for (j = 1; j <= n; j++) each = each sprintf("%s%.4f", (j > 1 ? " " : ""), values[name, j])
      printf "| %s | %.4f | %s |\n", name, median, each
    }
  }'
