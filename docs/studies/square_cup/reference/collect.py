"""Collects the stored square-cup mesh runs (run_meshes.sh) into meshes.json on stdout.

usage: python3 collect.py RUN_DIR COMMIT [solid_shell]
Each run RUN_DIR/c{cells}_l{layers}/summary.json with its GNU time -v report
RUN_DIR/c{cells}_l{layers}.time. With `solid_shell`, the runs are the solid-shell sequence
(solid_shell_meshes.json). Standard library only.
"""
import glob
import json
import os
import re
import sys

SEQUENCE = [[50, 2], [25, 1], [12, 1]]
SOLID_SHELL_SEQUENCE = [[50, 1], [25, 1], [12, 1]]

ABOUT_SOLID_SHELL = (
    "NUMISHEET'93 square cup, paper variant, punch to 15 mm in 0.5 mm steps, with the solid-shell element "
    "(one layer, 5 thickness points): the independent check of meshes.json's F-bar reference. "
    "Run with status_prediction: 8 added to scripts/square_cup.rhai's settings (without it the 25x25x1 "
    "solid-shell run stops at 4.25 mm with status cycling at the die radius next to the symmetry planes); "
    "each run alone, nice 10, on a 2-core machine shared with other jobs: CPU seconds are user + system "
    "of GNU time, wall is inflated. DX, DY, DD: draw-in at 15 mm [mm]; punch_force_n: peak punch force so "
    "far, full cup [N]. One layer resolves the thickness by its integration rule, the same along the "
    "sequence, so the cell size is the in-plane one (h = a / cells): 12 -> 25 -> 50 refines by 25/12 and 2. "
    "Rule as for meshes.json."
)


def gnu_time(path):
    text = open(path).read()
    user = float(re.search(r"User time \(seconds\): ([0-9.]+)", text).group(1))
    system = float(re.search(r"System time \(seconds\): ([0-9.]+)", text).group(1))
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([0-9:.]+)", text).group(1)
    seconds = 0.0
    for part in wall.split(":"):
        seconds = seconds * 60 + float(part)
    return user + system, seconds


def main(run_dir, commit, element="hexahedron"):
    shell = element == "solid_shell"
    runs = []
    found = []
    for path in glob.glob(f"{run_dir}/c*_l*.time"):
        cells, layers = re.match(r"c(\d+)_l(\d+)\.time", os.path.basename(path)).groups()
        found.append((int(cells), int(layers)))
    for cells, layers in sorted(found, key=lambda m: -m[0] * m[0] * m[1]):
        name = f"c{cells}_l{layers}"
        s = json.load(open(f"{run_dir}/{name}/summary.json"))
        if s["status"] != "finished":
            raise SystemExit(f"{name} did not finish: {s.get('error')}")
        draw = [d for d in s["draw_in"] if abs(d["punch_travel"] - 15.0) < 1e-9][0]
        cpu, wall = gnu_time(f"{run_dir}/{name}.time")
        runs.append({
            "cells": cells, "layers": layers,
            "command": f"tribo run scripts/square_cup.rhai --quiet --set cells={cells} --set layers={layers} --set travel=15.0 --set step=0.5 "
                       + ("--set 'element=\"solid_shell\"' " if shell else "") + "--set charts=false --out DIR",
            "cpu_s": round(cpu, 2), "wall_s": round(wall, 2),
            "iterations": s["newton_iterations"], "increments": s["increments"], "cutbacks": s["cutbacks"],
            "values": {"draw_in_dx_mm": draw["dx"], "draw_in_dy_mm": draw["dy"], "draw_in_dd_mm": draw["dd"],
                       "punch_force_n": s["punch_force_peak_n"]},
        })
    out = {
        "about": ABOUT_SOLID_SHELL if shell else "NUMISHEET'93 square cup, paper variant (scripts/square_cup.rhai defaults), punch to 15 mm in 0.5 mm steps, "
                 "run by docs/studies/square_cup/reference/run_meshes.sh (each run alone, nice 5, pinned to one core, "
                 "on a 2-core machine shared with other jobs: CPU seconds are user + system of GNU time, wall is inflated). "
                 "DX, DY, DD: draw-in at 15 mm [mm]; punch_force_n: peak punch force so far, full cup [N]. "
                 "The sequence 50x50x2, 25x25x1, 12x12x1: 25 -> 50 refines by 2 in-plane and through the thickness alike, "
                 "12 -> 25 by 25/12 in-plane only (one layer cannot be halved); h = (V/N)^(1/3) after Celik et al. (2008). "
                 "24x24x2 is a check, not extrapolated from: with 12x12x1 it is ratio 2 in every direction, and beside 25x25x1 it shows the effect of the second layer. "
                 "48x48x4 (the similar sequence 12x12x1, 24x24x2, 48x48x4) was not affordable in this session. "
                 "Rule (after Eca and Hoekstra, J. Comput. Phys. 262, 2014): asymptotic when monotone with an observed order in [0.5, 2.1]; "
                 "else the formal order 2 of trilinear hexahedra in the displacements is assumed, with safety factor 3.",
        "commit": commit,
        "element": element,
        "travel_mm": 15.0,
        "step_mm": 0.5,
        "half_side_mm": 75.0,
        "thickness_mm": 0.81,
        "sequence": SOLID_SHELL_SEQUENCE if shell else SEQUENCE,
        "rule": {"min": 0.5, "max": 2.1, "assumed": 2.0},
        "runs": runs,
    }
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main(*sys.argv[1:4])
