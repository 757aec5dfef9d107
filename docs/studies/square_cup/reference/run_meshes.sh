#!/bin/bash
# The square-cup study's stored mesh sequences (paper variant, punch to 15 mm, 0.5 mm steps):
# runs each mesh one at a time, niced and on one core, then collects their summaries and CPU
# seconds with collect.py. Usage, from the repository root:
#   bash docs/studies/square_cup/reference/run_meshes.sh [RUN_DIR]          # meshes.json (F-bar)
#   ELEMENT=solid_shell bash docs/studies/square_cup/reference/run_meshes.sh [RUN_DIR]
#                                                                       # solid_shell_meshes.json
# (Until status prediction is the engine's default, the solid-shell 25x25x1 run needs
# `status_prediction: 8` added to scripts/square_cup.rhai's settings: see the about field.)
# Then `tribo study square_cup --out docs/studies` measures the study against them.
set -e
RUNS=${1:-/tmp/study_runs}
BIN=${TRIBO:-target/release/tribo}
ELEMENT=${ELEMENT:-hexahedron}
mkdir -p "$RUNS"
if [ "$ELEMENT" = solid_shell ]; then
  MESHES=("50 1" "25 1" "12 1"); EXTRA=(--set 'element="solid_shell"'); OUT=solid_shell_meshes.json
else
  MESHES=("50 2" "25 1" "24 2" "12 1"); EXTRA=(); OUT=meshes.json
fi
for m in "${MESHES[@]}"; do
  set -- $m; c=$1; l=$2; d=$RUNS/c${c}_l${l}
  rm -rf "$d"
  /usr/bin/time -v -o "$RUNS/c${c}_l${l}.time" nice -n 5 taskset -c 1 "$BIN" run scripts/square_cup.rhai --quiet \
     --set cells=$c --set layers=$l --set travel=15.0 --set step=0.5 "${EXTRA[@]}" --set charts=false --out "$d" > "$RUNS/c${c}_l${l}.log" 2>&1
done
python3 docs/studies/square_cup/reference/collect.py "$RUNS" "$(git rev-parse HEAD)" "$ELEMENT" > "docs/studies/square_cup/reference/$OUT"
