#!/bin/bash
# The square-cup study's stored mesh sequence (paper variant, punch to 15 mm, 0.5 mm steps):
# runs each mesh one at a time, niced and on one core, then collects their summaries and CPU
# seconds into meshes.json with collect.py. Usage, from the repository root:
#   bash docs/studies/square_cup/reference/run_meshes.sh [RUN_DIR]
# Then `tribo study square_cup --out docs/studies` measures the study against it.
set -e
RUNS=${1:-/tmp/study_runs}
BIN=${TRIBO:-target/release/tribo}
mkdir -p "$RUNS"
for m in "50 2" "25 1" "24 2" "12 1"; do
  set -- $m; c=$1; l=$2; d=$RUNS/c${c}_l${l}
  rm -rf "$d"
  /usr/bin/time -v -o "$RUNS/c${c}_l${l}.time" nice -n 5 taskset -c 1 "$BIN" run scripts/square_cup.rhai --quiet \
     --set cells=$c --set layers=$l --set travel=15.0 --set step=0.5 --set charts=false --out "$d" > "$RUNS/c${c}_l${l}.log" 2>&1
done
python3 docs/studies/square_cup/reference/collect.py "$RUNS" "$(git rev-parse HEAD)" > docs/studies/square_cup/reference/meshes.json
