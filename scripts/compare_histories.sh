#!/usr/bin/env bash
# Runs the four main jobs with two tribo binaries and compares their histories byte for byte:
# the paper and benchmark square cups, both U-channel variants (punch touching the strip and
# 0.1 mm above it, one run each: the scene writes both into one folder) and the cylindrical
# cup. A change that reshapes code without changing what it computes must leave every
# history.csv identical (history.csv holds no wall time).
#
#   scripts/compare_histories.sh BEFORE_BIN AFTER_BIN [WORK_DIR]
#
# To compare against a commit: `git worktree add /tmp/before <commit>`, build it with
# `cargo build --release` there, and pass /tmp/before/target/release/tribo as BEFORE_BIN.
# Exit status 0 when every history is identical, 1 otherwise (the differing files named).
# With REUSE_BEFORE=1, the BEFORE side's outputs already in WORK_DIR/before are reused.
set -euo pipefail
before=$(realpath "$1"); after=$(realpath "$2")
work=${3:-$(mktemp -d)}
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work"
# The cups on F-bar hexahedra as these jobs always were (the script's default for one layer
# became the solid-shell, docs/solid-shell.md "Default").
cases=(
  "paper|scripts/square_cup.rhai|--set charts=false --set element=\"hexahedron\""
  "benchmark|scripts/square_cup.rhai|--set charts=false --set variant=\"benchmark\" --set element=\"hexahedron\""
  "u_channel_touching|tests/scenes/u_channel.rhai|--set only=0.0"
  "u_channel_lifted|tests/scenes/u_channel.rhai|--set only=0.1"
  "cylindrical_cup|scripts/cylindrical_cup.rhai|"
)
status=0
for case in "${cases[@]}"; do
  IFS='|' read -r name script sets <<<"$case"
  for side in before after; do
    bin=$before; [ "$side" = after ] && bin=$after
    if [ "$side" = before ] && [ "${REUSE_BEFORE:-0}" = 1 ] && [ -d "$work/before/$name" ]; then
      continue
    fi
    out="$work/$side/$name"; rm -rf "$out"
    eval "\"$bin\" run \"$root/$script\" $sets --quiet --out \"$out\"" > "$work/$side-$name.log" 2>&1 \
      || { echo "$name: the $side run failed (log: $work/$side-$name.log)"; status=1; }
  done
  n=0
  while IFS= read -r f; do
    rel=${f#"$work/before/$name/"}
    n=$((n + 1))
    if cmp -s "$f" "$work/after/$name/$rel"; then
      echo "$name: $rel identical ($(wc -l <"$f") lines)"
    else
      echo "$name: $rel DIFFERS"; status=1
    fi
  done < <(find "$work/before/$name" -name history.csv | sort)
  [ "$n" -gt 0 ] || { echo "$name: no history.csv written"; status=1; }
done
exit $status
