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


# The mesh sequence: the solid-shell 25 x 25, 50 x 50 and 100 x 100 x 1 sheets, h the in-plane
# cell of the 75 mm quarter blank, finest first.
SEQUENCE = [("ss100", 0.75), ("ss50", 1.5), ("ss25", 3.0)]
TRAVELS = (15, 40)
LINES = (("edge", "edge midline (y = 0)"), ("diagonal", "diagonal (x = y)"))


def tribo_binary():
    return os.environ.get("TRIBO", os.path.join(ROOT, "target", "release", "tribo"))


def extrapolate(quantities):
    """The engine's Richardson extrapolation (`tribo extrapolate`, src/study/richardson.rs) of
    {name: [[h, value] x 3]}: observed order, asymptotic verdict, GCI band."""
    doc = json.dumps({"quantities": quantities})
    done = subprocess.run([tribo_binary(), "extrapolate", "-"], input=doc,
                          capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"tribo extrapolate failed: {done.stderr.strip()}")
    return json.loads(done.stdout)["quantities"]


def thickness_profile(run, travel, line):
    """[[s, ln(t/t0)], ...] of a run along a line at a report travel, or None."""
    for entry in run["summary"].get("thickness_strain_lines", []):
        if round(entry["punch_travel"]) == travel:
            return entry[line]
    return None


def sequence_of(runs, key):
    """The three members of a material's sequence and the extrapolation of every quantity
    (draw-ins, punch peak, thickness strain at each station), or None if one is missing."""
    members = [(runs.get(f"{key}_{mesh}"), h) for mesh, h in SEQUENCE]
    if any(run is None for run, _ in members):
        return None
    quantities = {}
    for q, mm in QUANTITIES:
        quantities[f"{q.upper()} {mm}"] = [[h, run["draw"][(q, mm)]] for run, h in members]
    quantities["punch peak"] = [[h, run["peak"] / 1000.0] for run, h in members]
    for mm in TRAVELS:
        for line, _ in LINES:
            profiles = [thickness_profile(run, mm, line) for run, _ in members]
            if any(p is None for p in profiles):
                continue
            for i in range(len(profiles[0])):
                quantities[f"eps {line} {mm} {i}"] = [[h, p[i][1]] for p, (_, h) in zip(profiles, members)]
    return {"members": members, "result": extrapolate(quantities)}


def sequence_table(seq, measured, label):
    lines = ["| quantity | 25 x 25 | 50 x 50 | 100 x 100 | observed order | R | extrapolated | GCI band | band / value | asymptotic | measured |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    res = seq["result"]
    names = [f"{q.upper()} {mm}" for q, mm in QUANTITIES] + ["punch peak"]
    for name in names:
        e = res[name]
        row = [fmt(run["draw"][(name.split()[0].lower(), int(name.split()[1]))], 3) if name != "punch peak"
               else fmt(run["peak"] / 1000.0, 2) for run, _ in reversed(seq["members"])]
        p = e["observed_order"]
        mean = None
        if name != "punch peak":
            q, mm = name.split()
            mean, _ = measured_value(measured, label, q.lower(), int(mm))
        lines.append(f"| {name}{' [kN]' if name == 'punch peak' else ' [mm]'} | " + " | ".join(row)
                     + f" | {'–' if p is None else f'{p:.2f}'} | {e['convergence_ratio']:.3f} | {e['value']:.3f}"
                     + f" | ± {e['uncertainty']:.3f} | {100.0 * e['relative_uncertainty']:.2f} % | {'yes' if e['asymptotic'] else 'no'} | {fmt(mean)} |")
    return "\n".join(lines)


def thickness_table(seq):
    """Thickness strain at every fifth station at 40 mm: the three meshes, the extrapolated
    value and its band; and the widest band along each line at both travels."""
    res = seq["result"]
    lines = ["| line | travel [mm] | widest GCI band of ln(t/t0) | where (reference distance from the centre) | stations asymptotic |",
             "|---|---|---|---|---|"]
    for mm in TRAVELS:
        for line, label in LINES:
            keys = [k for k in res if k.startswith(f"eps {line} {mm} ")]
            if not keys:
                continue
            profile = thickness_profile(seq["members"][0][0], mm, line)
            widest = max(keys, key=lambda k: res[k]["uncertainty"])
            at = profile[int(widest.split()[-1])][0]
            asym = sum(1 for k in keys if res[k]["asymptotic"])
            lines.append(f"| {label} | {mm} | ± {res[widest]['uncertainty']:.4f} | {at:.1f} mm | {asym} of {len(keys)} |")
    return "\n".join(lines)


def thickness_svg(seqs, path):
    """ln(t/t0) at 40 mm along the edge midline and the diagonal: each mesh of the sequence
    and the extrapolated profile with its GCI band (grey), per material."""
    panels = [(label, line, title, seq) for label, seq in seqs.items() if seq for line, title in LINES]
    if not panels:
        return False
    pw, ph, left, top = 360, 260, 50, 40
    width, height = 20 + pw * 2, top + (ph + 50) * ((len(panels) + 1) // 2) + 30
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="11">',
           f'<text x="{width / 2}" y="20" text-anchor="middle" font-size="14">Thickness strain ln(t/t0) at 40 mm of punch travel: mesh sequence and extrapolation</text>']
    colours = {"ss25": "#1f77b4", "ss50": "#d62728", "ss100": "#2ca02c"}
    for k, (label, line, title, seq) in enumerate(panels):
        x0, y0 = 10 + pw * (k % 2), top + (ph + 50) * (k // 2)
        res = seq["result"]
        profiles = {mesh: thickness_profile(run, 40, line) for (run, _), (mesh, _) in zip(seq["members"], SEQUENCE)}
        keys = sorted((int(key.split()[-1]), key) for key in res if key.startswith(f"eps {line} 40 "))
        ext = [(profiles["ss100"][i][0], res[key]["value"], res[key]["uncertainty"]) for i, key in keys]
        vals = [v for p in profiles.values() for _, v in p] + [v + u for _, v, u in ext] + [v - u for _, v, u in ext]
        smax = max(s for s, _, _ in ext)
        lo, hi = min(vals), max(vals)
        lo, hi = lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo)
        X = lambda s: x0 + left + (pw - left - 20) * s / smax
        Y = lambda v: y0 + 20 + (ph - 40) * (hi - v) / (hi - lo)
        out.append(f'<text x="{x0 + pw / 2}" y="{y0 + 12}" text-anchor="middle">{label}, {title}</text>')
        out.append(f'<rect x="{X(0):.1f}" y="{Y(hi):.1f}" width="{X(smax) - X(0):.1f}" height="{Y(lo) - Y(hi):.1f}" fill="none" stroke="#999"/>')
        for v in (lo, 0.5 * (lo + hi), hi):
            out.append(f'<text x="{X(0) - 4:.1f}" y="{Y(v) + 4:.1f}" text-anchor="end">{v:.3f}</text>')
        out.append(f'<text x="{X(smax):.1f}" y="{Y(lo) + 14:.1f}" text-anchor="end">{smax:.0f} mm from the centre</text>')
        band = " ".join(f"{X(s):.1f},{Y(v + u):.1f}" for s, v, u in ext) + " " + " ".join(
            f"{X(s):.1f},{Y(v - u):.1f}" for s, v, u in reversed(ext))
        out.append(f'<polygon points="{band}" fill="#ccc"/>')
        for mesh, profile in profiles.items():
            pts = " ".join(f"{X(s):.1f},{Y(v):.1f}" for s, v in profile)
            out.append(f'<polyline points="{pts}" fill="none" stroke="{colours[mesh]}" stroke-width="1.2"/>')
        pts = " ".join(f"{X(s):.1f},{Y(v):.1f}" for s, v, _ in ext)
        out.append(f'<polyline points="{pts}" fill="none" stroke="black" stroke-dasharray="4 3" stroke-width="1.5"/>')
    lx = 20
    for label, colour in (("25 x 25", colours["ss25"]), ("50 x 50", colours["ss50"]), ("100 x 100", colours["ss100"]),
                          ("extrapolated (dashed) with its GCI band (grey)", "black")):
        out.append(f'<rect x="{lx}" y="{height - 18}" width="10" height="10" fill="{colour}"/><text x="{lx + 14}" y="{height - 9}">{label}</text>')
        lx += 110
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")
    return True


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
    seqs = {label: sequence_of(runs, key) for key, label in MATERIALS}
    missing = "(a member of the sequence did not finish: `scripts/numisheet93_runs.sh OUT base25 base50 base100`)"
    for label, seq in seqs.items():
        text = text.replace("{{SEQUENCE_%s}}" % label.upper(),
                            sequence_table(seq, measured, label) if seq else missing)
        text = text.replace("{{THICKNESS_%s}}" % label.upper(), thickness_table(seq) if seq else missing)
    thickness_svg(seqs, os.path.join(DOC, "numisheet93_thickness.svg"))
    with open(os.path.join(DOC, "numisheet93_sequence.json"), "w") as f:
        json.dump({label: None if seq is None else {
            "h": [h for _, h in SEQUENCE], "extrapolations": seq["result"]} for label, seq in seqs.items()},
            f, indent=1)
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
