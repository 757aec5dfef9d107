#!/usr/bin/env python3
"""Writes docs/validation/numisheet93.md and numisheet93.svg from the runs of
scripts/numisheet93_runs.sh and the measurements of docs/validation/numisheet93_measured.json.

    scripts/numisheet93_runs.sh out/numisheet93          # the runs (niced; re-entrant)
    python3 scripts/numisheet93_report.py out/numisheet93

Mathematics: each run's summary.json gives the draw-ins DX, DY, DD at 15 and 40 mm of punch
travel (the script's `draw_in`: inward travel of the blank edge midpoints along x and y and
of the corner along the diagonal) and the punch force peak of the full cup. A difference to
the measurement is (simulated - measured) / measured. A factor's effect is its run minus the
base run of the same mesh, material and element, per quantity. Cost: user + system CPU
seconds and the peak resident memory of the run (GNU time -v, cpu.txt). Richardson
extrapolation needs three meshes of one family in the asymptotic range; with fewer the page
says so and gives the command of the missing run.
"""
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DOC = os.path.join(ROOT, "docs", "validation")
QUANTITIES = [("dx", 15), ("dy", 15), ("dd", 15), ("dx", 40), ("dy", 40), ("dd", 40)]
MATERIALS = [("aluminium_1993", "aluminium"), ("steel", "steel")]
FACTORS = [
    ("mu_minus", "friction coefficient - 0.02"),
    ("mu_plus", "friction coefficient + 0.02"),
    ("holder_minus", "blankholder force - 10 % (17.64 kN)"),
    ("holder_plus", "blankholder force + 10 % (21.56 kN)"),
    ("von_mises", "von Mises instead of Hill48"),
]


def load_run(folder):
    """summary.json, CPU seconds and peak memory [MB] of a run folder, or None if unfinished."""
    path = os.path.join(folder, "summary.json")
    if not os.path.isfile(path):
        return None
    with open(path) as f:
        summary = json.load(f)
    cpu, rss = None, None
    try:
        with open(os.path.join(folder, "cpu.txt")) as f:
            user = sys_ = 0.0
            for line in f:
                key, _, value = line.strip().rpartition(": ")
                if key == "User time (seconds)":
                    user = float(value)
                elif key == "System time (seconds)":
                    sys_ = float(value)
                elif key == "Maximum resident set size (kbytes)":
                    rss = float(value) / 1024.0
            cpu = user + sys_
    except OSError:
        pass
    draw = {}
    for entry in summary.get("draw_in", []):
        mm = round(entry["punch_travel"])
        for q in ("dx", "dy", "dd"):
            draw[(q, mm)] = entry[q]
    return {
        "summary": summary,
        "draw": draw,
        "peak": summary.get("punch_force_peak_n"),
        "cpu": cpu,
        "rss": rss,
        "status": summary.get("status"),
    }


def fmt(v, digits=2):
    return "–" if v is None else f"{v:.{digits}f}"


def measured_value(measured, material, q, mm):
    entry = measured.get(material, {}).get(str(mm), {}).get(q)
    if not entry:
        return None, None
    return entry.get("mean"), entry.get("scatter")


def git_commit():
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                              capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "scripts", "std-lib", "src"],
                               cwd=ROOT, capture_output=True, text=True).stdout.strip()
        return head + (" (with uncommitted changes to scripts/std-lib/src)" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def results_table(runs, measured):
    lines = ["| material | model | DX 15 | DY 15 | DD 15 | DX 40 | DY 40 | DD 40 | punch peak [kN] | CPU [s] | peak memory [MB] |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for key, label in MATERIALS:
        for mesh in ("ss25", "ss50", "ss100", "hex25"):
            run = runs.get(f"{key}_{mesh}")
            if run is None:
                continue
            model = {"ss25": "solid-shell 25 x 25 x 1", "ss50": "solid-shell 50 x 50 x 1",
                     "ss100": "solid-shell 100 x 100 x 1", "hex25": "F-bar 25 x 25 x 1"}[mesh]
            cells = [fmt(run["draw"].get(qm)) for qm in QUANTITIES]
            peak = None if run["peak"] is None else run["peak"] / 1000.0
            lines.append(f"| {label} | {model} | " + " | ".join(cells)
                         + f" | {fmt(peak, 1)} | {fmt(run['cpu'], 0)} | {fmt(run['rss'], 0)} |")
        row = []
        for q, mm in QUANTITIES:
            mean, scatter = measured_value(measured, label, q, mm)
            row.append("–" if mean is None else (fmt(mean) + ("" if scatter is None else f" ± {fmt(scatter)}")))
        lines.append(f"| {label} | **measured** | " + " | ".join(row) + " | – | – | – |")
    return "\n".join(lines)


def difference_table(runs, measured):
    lines = ["| material | model | DX 15 | DY 15 | DD 15 | DX 40 | DY 40 | DD 40 |",
             "|---|---|---|---|---|---|---|---|"]
    for key, label in MATERIALS:
        for mesh in ("ss25", "ss50", "hex25"):
            run = runs.get(f"{key}_{mesh}")
            if run is None:
                continue
            row = []
            for q, mm in QUANTITIES:
                mean, _ = measured_value(measured, label, q, mm)
                sim = run["draw"].get((q, mm))
                row.append("–" if mean is None or sim is None else f"{100.0 * (sim - mean) / mean:+.1f} %")
            if all(c == "–" for c in row):
                continue
            lines.append(f"| {label} | {mesh} | " + " | ".join(row) + " |")
    return "\n".join(lines)


def effect_table(runs, base_key, changes):
    base = runs.get(base_key)
    lines = ["| factor (one at a time) | ΔDX 15 | ΔDY 15 | ΔDD 15 | ΔDX 40 | ΔDY 40 | ΔDD 40 | Δ punch peak [kN] |",
             "|---|---|---|---|---|---|---|---|"]
    if base is None:
        return None
    n = 0
    for suffix, label in changes:
        run = runs.get(f"{base_key}_{suffix}") if suffix else runs.get(label[1])
        if run is None:
            lines.append(f"| {label} | not run this session |||||||")
            continue
        n += 1
        row = []
        for qm in QUANTITIES:
            a, b = run["draw"].get(qm), base["draw"].get(qm)
            row.append("–" if a is None or b is None else f"{a - b:+.3f}")
        dp = None if run["peak"] is None or base["peak"] is None else (run["peak"] - base["peak"]) / 1000.0
        lines.append(f"| {label} | " + " | ".join(row) + f" | {fmt(dp, 2)} |")
    return "\n".join(lines)


def pair_table(runs):
    a, b = runs.get("aluminium_1993_ss25"), runs.get("aluminium_ss25")
    if a is None or b is None:
        return None
    lines = ["| Swift constants | DX 15 | DY 15 | DD 15 | DX 40 | DY 40 | DD 40 | punch peak [kN] |",
             "|---|---|---|---|---|---|---|---|"]
    for run, label in ((a, "C = 576.79, n = 0.3593 (benchmark, used)"), (b, "C = 576, n = 0.36 (seed paper's rounding)")):
        lines.append(f"| {label} | " + " | ".join(fmt(run["draw"].get(qm), 3) for qm in QUANTITIES)
                     + f" | {fmt(run['peak'] / 1000.0, 2)} |")
    lines.append("| difference (rounded - benchmark) | " + " | ".join(
        f"{b['draw'][qm] - a['draw'][qm]:+.3f}" if qm in a["draw"] and qm in b["draw"] else "–"
        for qm in QUANTITIES) + f" | {(b['peak'] - a['peak']) / 1000.0:+.2f} |")
    return "\n".join(lines)


def svg_chart(runs, measured, path):
    """Simulated against measured draw-in, one column per quantity and material: the
    measurement as a black bar (with its scatter band, grey, where published), each run a
    coloured marker."""
    columns = []
    for key, label in MATERIALS:
        for q, mm in QUANTITIES:
            mean, scatter = measured_value(measured, label, q, mm)
            sims = []
            for mesh, colour in (("ss25", "#1f77b4"), ("ss50", "#d62728"), ("hex25", "#2ca02c")):
                run = runs.get(f"{key}_{mesh}")
                if run is not None and (q, mm) in run["draw"]:
                    sims.append((mesh, colour, run["draw"][(q, mm)]))
            if mean is None and not sims:
                continue
            columns.append((f"{label[:2]} {q.upper()} {mm}", mean, scatter, sims))
    width, height, left, top, bottom = 80 + 60 * len(columns), 420, 60, 40, 70
    vmax = max([c[1] or 0 for c in columns] + [s[2] for c in columns for s in c[3]] + [1.0]) * 1.1
    y = lambda v: top + (height - top - bottom) * (1.0 - v / vmax)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="11">',
           f'<text x="{width / 2}" y="20" text-anchor="middle" font-size="14">NUMISHEET\'93 square cup: draw-in [mm], simulated against measured</text>']
    for k in range(0, int(vmax) + 1, 5):
        out.append(f'<line x1="{left}" x2="{width - 20}" y1="{y(k):.1f}" y2="{y(k):.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{left - 6}" y="{y(k) + 4:.1f}" text-anchor="end">{k}</text>')
    for i, (name, mean, scatter, sims) in enumerate(columns):
        cx = left + 30 + 60 * i
        if mean is not None:
            if scatter:
                out.append(f'<rect x="{cx - 18}" y="{y(mean + scatter):.1f}" width="36" height="{y(mean - scatter) - y(mean + scatter):.1f}" fill="#ccc"/>')
            out.append(f'<line x1="{cx - 18}" x2="{cx + 18}" y1="{y(mean):.1f}" y2="{y(mean):.1f}" stroke="black" stroke-width="3"/>')
        for j, (mesh, colour, v) in enumerate(sims):
            out.append(f'<circle cx="{cx - 8 + 8 * j}" cy="{y(v):.1f}" r="4" fill="{colour}"><title>{mesh}: {v:.2f}</title></circle>')
        out.append(f'<text x="{cx}" y="{height - bottom + 16}" text-anchor="end" transform="rotate(-40 {cx} {height - bottom + 16})">{name}</text>')
    lx = left
    for label, colour in (("measured (mean)", "black"), ("solid-shell 25x25x1", "#1f77b4"), ("solid-shell 50x50x1", "#d62728"), ("F-bar 25x25x1", "#2ca02c")):
        out.append(f'<rect x="{lx}" y="{height - 18}" width="10" height="10" fill="{colour}"/><text x="{lx + 14}" y="{height - 9}">{label}</text>')
        lx += 150
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "out", "numisheet93")
    runs = {}
    for name in sorted(os.listdir(out)):
        run = load_run(os.path.join(out, name))
        if run is not None:
            runs[name] = run
    with open(os.path.join(DOC, "numisheet93_measured.json")) as f:
        measured = json.load(f)
    svg_chart(runs, measured, os.path.join(DOC, "numisheet93.svg"))
    template_path = os.path.join(DOC, "numisheet93.template.md")
    with open(template_path) as f:
        text = f.read()
    sens = {}
    for key, label in MATERIALS:
        sens[label] = effect_table(runs, f"{key}_ss25", FACTORS) or "(base run missing)"
    element = {}
    for key, label in MATERIALS:
        base, hexa = runs.get(f"{key}_ss25"), runs.get(f"{key}_hex25")
        if base and hexa:
            element[label] = " | ".join(
                f"{hexa['draw'][qm] - base['draw'][qm]:+.3f}" if qm in hexa["draw"] and qm in base["draw"] else "–"
                for qm in QUANTITIES)
    element_rows = "\n".join(f"| {label}: F-bar 25 x 25 x 1 instead of solid-shell | {row} |" for label, row in element.items()) or "| (F-bar runs not finished this session) | |"
    text = (text.replace("{{COMMIT}}", git_commit())
            .replace("{{RESULTS}}", results_table(runs, measured))
            .replace("{{DIFFERENCES}}", difference_table(runs, measured))
            .replace("{{PAIR}}", pair_table(runs) or "(one of the pair's runs did not finish this session)")
            .replace("{{SENS_ALUMINIUM}}", sens["aluminium"])
            .replace("{{SENS_STEEL}}", sens["steel"])
            .replace("{{ELEMENT}}", element_rows)
            .replace("{{RUNS}}", ", ".join(f"`{k}`" for k in runs)))
    with open(os.path.join(DOC, "numisheet93.md"), "w") as f:
        f.write(text)
    print(f"wrote {DOC}/numisheet93.md and numisheet93.svg from {len(runs)} runs in {out}")


if __name__ == "__main__":
    main()
