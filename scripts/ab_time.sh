#!/usr/bin/env bash
# Times two commands side by side, as BENCHMARKS.md's before/after figures are measured: after
# WARMUP uncounted runs of each, A and B run in turn (A B A B ...), each pinned to the
# processors CPUS (taskset), each run's user, system and wall seconds and peak memory from
# GNU time; the ratio A/B is taken pair by pair (pairing keeps it meaningful when the
# machine's speed drifts), and min / median / max are printed: quote the median.
#
#   scripts/ab_time.sh [-n PAIRS] [--warmup WARMUP] [--cpu CPUS] --baseline 'B COMMAND' -- A COMMAND...
#
# Defaults: 3 pairs, 1 warm-up, processor 1. Needs taskset (util-linux) and /usr/bin/time.
set -euo pipefail
pairs=3; warmup=1; cpus=1; baseline=""
while [ $# -gt 0 ]; do
  case "$1" in
    -n) pairs=$2; shift 2 ;;
    --warmup) warmup=$2; shift 2 ;;
    --cpu) cpus=$2; shift 2 ;;
    --baseline) baseline=$2; shift 2 ;;
    --) shift; break ;;
    *) echo "ab_time.sh: unknown argument '$1' (usage at the top of $0)" >&2; exit 2 ;;
  esac
done
if [ $# -eq 0 ] || [ -z "$baseline" ]; then
  echo "ab_time.sh: give --baseline 'B COMMAND' and, after --, the A command" >&2; exit 2
fi
read -r -a b_cmd <<< "$baseline"
a_cmd=("$@")
log=$(mktemp); trap 'rm -f "$log" "$log.t"' EXIT
run() { # label, command...: appends "label user sys wall peak_kib"
  local label=$1; shift
  taskset -c "$cpus" /usr/bin/time -f "%U %S %e %M" -o "$log.t" "$@" > /dev/null 2>&1 \
    || echo "ab_time.sh: $label exited with status $? (figures kept)" >&2
  echo "$label $(tail -n 1 "$log.t")" >> "$log"
}
for ((i = 0; i < warmup; i++)); do run warmA "${a_cmd[@]}"; run warmB "${b_cmd[@]}"; done
for ((i = 0; i < pairs; i++)); do run A "${a_cmd[@]}"; run B "${b_cmd[@]}"; done
awk '
  function stats(name, v, n,    i, j, t) {
    for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++) if (v[j] < v[i]) { t = v[i]; v[i] = v[j]; v[j] = t }
    printf "%-12s %10.3f %10.3f %10.3f\n", name, v[1], (n % 2 ? v[(n + 1) / 2] : (v[n / 2] + v[n / 2 + 1]) / 2), v[n]
  }
  $1 == "A" { na++; au[na] = $2; ac[na] = $2 + $3; aw[na] = $4; am[na] = $5 / 1024 }
  $1 == "B" { nb++; bu[nb] = $2; bc[nb] = $2 + $3; bw[nb] = $4; bm[nb] = $5 / 1024
              rc[nb] = ac[nb] / bc[nb]; rw[nb] = aw[nb] / bw[nb] }
  END {
    printf "%-12s %10s %10s %10s   (%d pairs, whole process)\n", "", "min", "median", "max", nb
    stats("A cpu s", ac, na); stats("A wall s", aw, na); stats("A peak MiB", am, na)
    stats("B cpu s", bc, nb); stats("B wall s", bw, nb); stats("B peak MiB", bm, nb)
    stats("A/B cpu", rc, nb); stats("A/B wall", rw, nb)
  }' "$log"
