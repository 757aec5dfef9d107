#!/usr/bin/env bash
# The runs behind docs/validation/numisheet93.md: NUMISHEET'93 benchmark variant to 40 mm,
# one-layer solid-shell sheets, Hill48, both benchmark sheets, and the sensitivity runs.
# Each run writes its own folder under OUT (default out/numisheet93) with summary.json and
# cpu.txt (/usr/bin/time -v: CPU seconds and peak memory); a run whose folder exists is
# skipped, so the script can be re-entered, and run twice at once on the same OUT to use both
# cores. Runs niced (the machine is shared): NICE=0 gives a runner its core back.
#
#   scripts/numisheet93_runs.sh [OUT] [GROUP...]      GROUP: base25 pair25 sens25 tools25 layers25 base35 base50 base71 base100 fbar25
#   python3 scripts/numisheet93_report.py OUT         # writes docs/validation/numisheet93.md + SVG
set -euo pipefail
out=${1:-out/numisheet93}
shift || true
groups=${*:-base25 pair25 sens25 base50}
tribo=${TRIBO:-target/release/tribo}
niceness=${NICE:-19}
mkdir -p "$out"

run() { # name, then --set arguments
    local name=$1; shift
    local dir="$out/$name"
    # A folder that exists is a run done or under way (two runners may share OUT); delete a
    # failed run's folder to run it again.
    if [[ -d "$dir" ]]; then echo "skip $name (done or under way)"; return; fi
    mkdir -p "$dir"
    echo "run  $name: $*"
    local sets=() defaults=(variant='"benchmark"' charts=false)
    # One solid-shell layer unless the run names its element or layers (a --set may name
    # a variable once).
    [[ " $* " == *" element="* ]] || defaults+=(element='"solid_shell"')
    [[ " $* " == *" layers="* ]] || defaults+=(layers=1)
    for s in "${defaults[@]}" "$@"; do
        sets+=(--set "$s")
    done
    nice -n "$niceness" /usr/bin/time -v -o "$dir/cpu.txt" "$tribo" run scripts/square_cup.rhai --quiet \
        --out "$dir" "${sets[@]}" > "$dir/log.txt" 2>&1 || echo "FAILED $name (see $dir/log.txt)"
}

for g in $groups; do
    case $g in
    base25)  for m in aluminium_1993 steel; do
                 run "${m}_ss25" material="\"$m\"" yield_kind='"hill48"' cells=25; done ;;
    pair25)  run aluminium_ss25 material='"aluminium"' yield_kind='"hill48"' cells=25 ;;
    sens25)  for m in aluminium_1993 steel; do
                 mu0=$([[ $m == steel ]] && echo 0.144 || echo 0.162)
                 run "${m}_ss25_mu_minus" material="\"$m\"" yield_kind='"hill48"' cells=25 \
                     mu=$(python3 -c "print($mu0 - 0.02)")
                 run "${m}_ss25_mu_plus" material="\"$m\"" yield_kind='"hill48"' cells=25 \
                     mu=$(python3 -c "print($mu0 + 0.02)")
                 run "${m}_ss25_holder_minus" material="\"$m\"" yield_kind='"hill48"' cells=25 holder_force=17640.0
                 run "${m}_ss25_holder_plus" material="\"$m\"" yield_kind='"hill48"' cells=25 holder_force=21560.0
                 run "${m}_ss25_von_mises" material="\"$m\"" yield_kind='"isotropic"' cells=25
             done ;;
    base50)  for m in aluminium_1993 steel; do
                 run "${m}_ss50" material="\"$m\"" yield_kind='"hill48"' cells=50; done ;;
    base35)  for m in aluminium_1993 steel; do
                 run "${m}_ss35" material="\"$m\"" yield_kind='"hill48"' cells=35; done ;;
    base71)  for m in aluminium_1993 steel; do
                 run "${m}_ss71" material="\"$m\"" yield_kind='"hill48"' cells=71; done ;;
    base100) for m in aluminium_1993 steel; do
                 run "${m}_ss100" material="\"$m\"" yield_kind='"hill48"' cells=100; done ;;
    tools25) for m in aluminium_1993 steel; do   # tool radii by +-0.5 mm (our tolerance)
                 for side in minus:7.5 plus:8.5; do
                     run "${m}_ss25_die_radius_${side%%:*}" material="\"$m\"" yield_kind='"hill48"' cells=25 die_radius=${side##*:}
                     run "${m}_ss25_punch_radius_${side%%:*}" material="\"$m\"" yield_kind='"hill48"' cells=25 punch_radius=${side##*:}
                 done; done ;;
    layers25) for m in aluminium_1993 steel; do
                 run "${m}_ss25_layers2" material="\"$m\"" yield_kind='"hill48"' cells=25 layers=2; done ;;
    fbar25)  for m in aluminium_1993 steel; do
                 run "${m}_hex25" material="\"$m\"" yield_kind='"hill48"' cells=25 element='"hexahedron"'; done ;;
    *) echo "unknown group $g" >&2; exit 2 ;;
    esac
done
