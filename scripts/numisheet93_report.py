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
    ("die_radius_minus", "die entry radius 7.5 mm (8 - 0.5: our tolerance)"),
    ("die_radius_plus", "die entry radius 8.5 mm (8 + 0.5)"),
    ("punch_radius_minus", "punch nose radius 7.5 mm (8 - 0.5)"),
    ("punch_radius_plus", "punch nose radius 8.5 mm (8 + 0.5)"),
    ("layers2", "two solid-shell layers instead of one"),
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
        for mesh in [m for m, _ in reversed(MESHES)] + ["hex25"]:
            run = runs.get(f"{key}_{mesh}")
            if run is None:
                continue
            model = MODEL[mesh]
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


def difference_table(runs, measured, finest):
    lines = ["| material | model | DX 15 | DY 15 | DD 15 | DX 40 | DY 40 | DD 40 |",
             "|---|---|---|---|---|---|---|---|"]
    for key, label in MATERIALS:
        for mesh in [m for m, _ in reversed(MESHES)] + ["hex25"]:
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
        seq = finest.get(label)
        if seq is None:
            continue
        row = []
        for q, mm in QUANTITIES:
            mean, _ = measured_value(measured, label, q, mm)
            e = seq["result"][f"{q.upper()} {mm}"]
            row.append("–" if mean is None else
                       f"{100.0 * (e['value'] - mean) / mean:+.1f} % ± {100.0 * e['uncertainty'] / mean:.1f} %")
        if any(c != "–" for c in row):
            meshes = "-".join(MODEL[m].split()[1] for _, m, _ in reversed(seq["members"]))
            lines.append(f"| {label} | **extrapolated** ({meshes}), with its GCI band | " + " | ".join(row) + " |")
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


# The solid-shell meshes of the sequences, finest first: (run suffix, cells per edge of the
# 75 mm quarter blank); h = 75 / cells. Two sequences share 50 x 50: 25, 50, 100 (ratio 2)
# and 35, 50, 71 (ratio about sqrt 2).
MESHES = [("ss100", 100), ("ss71", 71), ("ss50", 50), ("ss35", 35), ("ss25", 25)]
MODEL = {mesh: f"solid-shell {n} x {n} x 1" for mesh, n in MESHES}
MODEL["hex25"] = "F-bar 25 x 25 x 1"
COLOURS = {"ss25": "#1f77b4", "ss35": "#9467bd", "ss50": "#d62728", "ss71": "#ff7f0e",
           "ss100": "#2ca02c", "hex25": "#8c564b"}
TRAVELS = (15, 40)
LINES = (("edge", "edge midline (y = 0)", 1.0), ("diagonal", "diagonal (x = y)", 2 ** 0.5))
STATIONS = 25  # common stations every 3 mm of the reference blank along each line


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


def thickness_at_stations(run, travel, line, scale):
    """ln(t/t0) of a run along a line at a report travel, at the common stations (every 3 mm
    of x along the line): linear interpolation between the run's nodes on the line (exact where
    a station is a node, as on 25, 50 and 100 cells), or None when the run has no profile."""
    for entry in run["summary"].get("thickness_strain_lines", []):
        if round(entry["punch_travel"]) == travel:
            profile = sorted({round(p[0], 9): p[1] for p in entry[line]}.items())
            out = []
            for i in range(STATIONS + 1):
                s = scale * 75.0 * i / STATIONS
                for (s0, v0), (s1, v1) in zip(profile, profile[1:]):
                    if s0 - 1e-6 <= s <= s1 + 1e-6:
                        w = 0.0 if s1 == s0 else min(max((s - s0) / (s1 - s0), 0.0), 1.0)
                        out.append([s, v0 + w * (v1 - v0)])
                        break
                else:
                    return None
            return out
    return None


def sequence_of(runs, key, meshes):
    """Three members of a material's sequence (finest first) and the extrapolation of every
    quantity (draw-ins, punch peak, thickness strain at each station), or None if one is
    missing."""
    members = [(runs.get(f"{key}_{mesh}"), mesh, 75.0 / cells) for mesh, cells in MESHES if mesh in meshes]
    if len(members) != 3 or any(run is None for run, _, _ in members):
        return None
    quantities = {}
    for q, mm in QUANTITIES:
        quantities[f"{q.upper()} {mm}"] = [[h, run["draw"][(q, mm)]] for run, _, h in members]
    quantities["punch peak"] = [[h, run["peak"] / 1000.0] for run, _, h in members]
    for mm in TRAVELS:
        for line, _, scale in LINES:
            profiles = [thickness_at_stations(run, mm, line, scale) for run, _, _ in members]
            if any(p is None for p in profiles):
                continue
            for i in range(STATIONS + 1):
                quantities[f"eps {line} {mm} {i}"] = [[h, p[i][1]] for p, (_, _, h) in zip(profiles, members)]
    return {"members": members, "result": extrapolate(quantities)}


def draw_value(run, name):
    if name == "punch peak":
        return run["peak"] / 1000.0
    q, mm = name.split()
    return run["draw"][(q.lower(), int(mm))]


def sequence_table(seq, measured, label):
    cells = " | ".join(MODEL[mesh].split()[1] + " x " + MODEL[mesh].split()[3] for _, mesh, _ in reversed(seq["members"]))
    lines = [f"| quantity | {cells} | observed order | R | extrapolated | GCI band | band / value | asymptotic | measured |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    res = seq["result"]
    for name in [f"{q.upper()} {mm}" for q, mm in QUANTITIES] + ["punch peak"]:
        e = res[name]
        row = [fmt(draw_value(run, name), 3 if name != "punch peak" else 2) for run, _, _ in reversed(seq["members"])]
        p = e["observed_order"]
        mean = None
        if name != "punch peak":
            q, mm = name.split()
            mean, _ = measured_value(measured, label, q.lower(), int(mm))
        lines.append(f"| {name}{' [kN]' if name == 'punch peak' else ' [mm]'} | " + " | ".join(row)
                     + f" | {'–' if p is None else f'{p:.2f}'} | {e['convergence_ratio']:.3f} | {e['value']:.3f}"
                     + f" | ± {e['uncertainty']:.3f} | {100.0 * e['relative_uncertainty']:.2f} % | {'yes' if e['asymptotic'] else 'no'} | {fmt(mean)} |")
    return "\n".join(lines)


def order_check_table(seqs):
    """The observed order of each draw-in from every sequence that could be formed: where the
    sequences agree, the meshes are in the asymptotic range."""
    lines = ["| material | meshes | " + " | ".join(f"{q.upper()} {mm}" for q, mm in QUANTITIES) + " | punch peak |",
             "|---|---|" + "---|" * (len(QUANTITIES) + 1)]
    n = 0
    for (label, meshes), seq in seqs.items():
        if seq is None:
            continue
        n += 1
        res = seq["result"]
        names = [f"{q.upper()} {mm}" for q, mm in QUANTITIES] + ["punch peak"]
        cells = ", ".join(MODEL[m].split()[1] for m in reversed(meshes))
        lines.append(f"| {label} | {cells} | " + " | ".join(
            "–" if res[k]["observed_order"] is None else f"{res[k]['observed_order']:.2f}" + ("" if res[k]["asymptotic"] else " (not asymptotic)")
            for k in names) + " |")
    return "\n".join(lines) if n else "(no sequence of three meshes finished)"


def thickness_table(seq):
    """The widest GCI band along each line at both travels, where, and how many stations
    show the asymptotic range."""
    res = seq["result"]
    lines = ["| line | travel [mm] | widest GCI band of ln(t/t0) | where (reference distance from the centre) | largest thinning (extrapolated) | stations asymptotic |",
             "|---|---|---|---|---|---|"]
    for mm in TRAVELS:
        for line, label, scale in LINES:
            keys = [k for k in res if k.startswith(f"eps {line} {mm} ")]
            if not keys:
                continue
            widest = max(keys, key=lambda k: res[k]["uncertainty"])
            thinnest = min(keys, key=lambda k: res[k]["value"])
            at = lambda k: scale * 75.0 * int(k.split()[-1]) / STATIONS
            asym = sum(1 for k in keys if res[k]["asymptotic"])
            lines.append(f"| {label} | {mm} | ± {res[widest]['uncertainty']:.4f} | {at(widest):.1f} mm"
                         + f" | {res[thinnest]['value']:.4f} ± {res[thinnest]['uncertainty']:.4f} at {at(thinnest):.1f} mm | {asym} of {len(keys)} |")
    return "\n".join(lines)


def thickness_svg(seqs, path):
    """ln(t/t0) at 40 mm along the edge midline and the diagonal: each mesh of the sequence
    and the extrapolated profile with its GCI band (grey), per material."""
    panels = [(label, line, title, scale, seq) for label, seq in seqs.items() if seq for line, title, scale in LINES]
    if not panels:
        return False
    pw, ph, left, top = 360, 260, 50, 40
    width, height = 20 + pw * 2, top + (ph + 50) * ((len(panels) + 1) // 2) + 30
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="11">',
           f'<text x="{width / 2}" y="20" text-anchor="middle" font-size="14">Thickness strain ln(t/t0) at 40 mm of punch travel: mesh sequence and extrapolation</text>']
    meshes_drawn = []
    for k, (label, line, title, scale, seq) in enumerate(panels):
        x0, y0 = 10 + pw * (k % 2), top + (ph + 50) * (k // 2)
        res = seq["result"]
        profiles = {mesh: thickness_at_stations(run, 40, line, scale) for run, mesh, _ in seq["members"]}
        meshes_drawn += [m for m in profiles if m not in meshes_drawn]
        ext = [(scale * 75.0 * i / STATIONS, res[f"eps {line} 40 {i}"]["value"], res[f"eps {line} 40 {i}"]["uncertainty"])
               for i in range(STATIONS + 1)]
        vals = [v for p in profiles.values() for _, v in p] + [v + u for _, v, u in ext] + [v - u for _, v, u in ext]
        smax = ext[-1][0]
        lo, hi = min(vals), max(vals)
        lo, hi = lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo)
        X = lambda s: x0 + left + (pw - left - 20) * s / smax
        Y = lambda v: y0 + 20 + (ph - 40) * (hi - v) / (hi - lo)
        out.append(f'<text x="{x0 + pw / 2}" y="{y0 + 12}" text-anchor="middle">{label}, {title}</text>')
        out.append(f'<rect x="{X(0):.1f}" y="{Y(hi):.1f}" width="{X(smax) - X(0):.1f}" height="{Y(lo) - Y(hi):.1f}" fill="none" stroke="#999"/>')
        if lo < 0.0 < hi:
            out.append(f'<line x1="{X(0):.1f}" x2="{X(smax):.1f}" y1="{Y(0):.1f}" y2="{Y(0):.1f}" stroke="#bbb" stroke-dasharray="2 2"/>')
        for v in (lo, 0.5 * (lo + hi), hi):
            out.append(f'<text x="{X(0) - 4:.1f}" y="{Y(v) + 4:.1f}" text-anchor="end">{v:.3f}</text>')
        out.append(f'<text x="{X(smax):.1f}" y="{Y(lo) + 14:.1f}" text-anchor="end">{smax:.0f} mm from the centre (reference blank)</text>')
        band = " ".join(f"{X(s):.1f},{Y(v + u):.1f}" for s, v, u in ext) + " " + " ".join(
            f"{X(s):.1f},{Y(v - u):.1f}" for s, v, u in reversed(ext))
        out.append(f'<polygon points="{band}" fill="#ccc"/>')
        for mesh, profile in profiles.items():
            pts = " ".join(f"{X(s):.1f},{Y(v):.1f}" for s, v in profile)
            out.append(f'<polyline points="{pts}" fill="none" stroke="{COLOURS[mesh]}" stroke-width="1.2"/>')
        pts = " ".join(f"{X(s):.1f},{Y(v):.1f}" for s, v, _ in ext)
        out.append(f'<polyline points="{pts}" fill="none" stroke="black" stroke-dasharray="4 3" stroke-width="1.5"/>')
    lx = 20
    for mesh in meshes_drawn:
        n = MODEL[mesh].split()[1]
        out.append(f'<rect x="{lx}" y="{height - 18}" width="10" height="10" fill="{COLOURS[mesh]}"/><text x="{lx + 14}" y="{height - 9}">{n} x {n}</text>')
        lx += 90
    out.append(f'<rect x="{lx}" y="{height - 18}" width="10" height="10" fill="black"/><text x="{lx + 14}" y="{height - 9}">extrapolated (dashed) with its GCI band (grey)</text>')
    out.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")
    return True


def svg_chart(runs, measured, finest, path):
    """Simulated against measured draw-in, one column per quantity and material: the
    measurement as a black bar (with its scatter band, grey, where published), each run a
    coloured marker, the extrapolated value of the finest mesh sequence a black diamond with
    its GCI band."""
    columns = []
    for key, label in MATERIALS:
        for q, mm in QUANTITIES:
            mean, scatter = measured_value(measured, label, q, mm)
            sims = []
            for mesh in [m for m, _ in reversed(MESHES)] + ["hex25"]:
                colour = COLOURS[mesh]
                run = runs.get(f"{key}_{mesh}")
                if run is not None and (q, mm) in run["draw"]:
                    sims.append((mesh, colour, run["draw"][(q, mm)]))
            if mean is None and not sims:
                continue
            seq = finest.get(label)
            ext = seq["result"][f"{q.upper()} {mm}"] if seq else None
            columns.append((f"{label[:2]} {q.upper()} {mm}", mean, scatter, sims, ext))
    width, height, left, top, bottom = max(80 + 60 * len(columns), 820), 450, 60, 40, 100
    vmax = max([c[1] or 0 for c in columns] + [s[2] for c in columns for s in c[3]] + [1.0]) * 1.1
    y = lambda v: top + (height - top - bottom) * (1.0 - v / vmax)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" font-family="sans-serif" font-size="11">',
           f'<text x="{width / 2}" y="20" text-anchor="middle" font-size="14">NUMISHEET\'93 square cup: draw-in [mm], simulated against measured</text>']
    for k in range(0, int(vmax) + 1, 5):
        out.append(f'<line x1="{left}" x2="{width - 20}" y1="{y(k):.1f}" y2="{y(k):.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{left - 6}" y="{y(k) + 4:.1f}" text-anchor="end">{k}</text>')
    for i, (name, mean, scatter, sims, ext) in enumerate(columns):
        cx = left + 30 + 60 * i
        if mean is not None:
            if scatter:
                out.append(f'<rect x="{cx - 18}" y="{y(mean + scatter):.1f}" width="36" height="{y(mean - scatter) - y(mean + scatter):.1f}" fill="#ccc"/>')
            out.append(f'<line x1="{cx - 18}" x2="{cx + 18}" y1="{y(mean):.1f}" y2="{y(mean):.1f}" stroke="black" stroke-width="3"/>')
        for j, (mesh, colour, v) in enumerate(sims):
            out.append(f'<circle cx="{cx - 14 + 5 * j}" cy="{y(v):.1f}" r="3.5" fill="{colour}"><title>{mesh}: {v:.2f}</title></circle>')
        if ext is not None:
            v, u, ex = ext["value"], ext["uncertainty"], cx + 20
            out.append(f'<line x1="{ex}" x2="{ex}" y1="{y(v + u):.1f}" y2="{y(v - u):.1f}" stroke="black"/>')
            out.append(f'<path d="M {ex} {y(v) - 5:.1f} L {ex + 4} {y(v):.1f} L {ex} {y(v) + 5:.1f} L {ex - 4} {y(v):.1f} Z" fill="black"><title>extrapolated: {v:.2f} ± {u:.2f}</title></path>')
        out.append(f'<text x="{cx}" y="{height - bottom + 16}" text-anchor="end" transform="rotate(-40 {cx} {height - bottom + 16})">{name}</text>')
    lx = left
    present = [m for m, _ in reversed(MESHES) if any(f"{k}_{m}" in runs for k, _ in MATERIALS)]
    present += ["hex25"] if any(f"{k}_hex25" in runs for k, _ in MATERIALS) else []
    items = [("measured (mean)", "black")] + [(MODEL[m].replace("solid-shell ", "SS ").replace(" x 1", ""), COLOURS[m]) for m in present]
    items += [("extrapolated ± GCI (diamond)", "black")] if any(c[4] for c in columns) else []
    for k, (label, colour) in enumerate(items):
        lx, ly = left + 190 * (k % 4), height - 34 + 16 * (k // 4)
        out.append(f'<rect x="{lx}" y="{ly}" width="10" height="10" fill="{colour}"/><text x="{lx + 14}" y="{ly + 9}">{label}</text>')
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
    # Every sequence of three meshes that can be formed; the finest one gives the answer.
    candidates = [("ss100", "ss50", "ss25"), ("ss71", "ss50", "ss35"), ("ss50", "ss35", "ss25")]
    all_seqs = {(label, c): sequence_of(runs, key, c) for key, label in MATERIALS for c in candidates}
    finest = {}
    for key, label in MATERIALS:
        done = [(min(75.0 / dict(MESHES)[m] for m in c), all_seqs[(label, c)]) for c in candidates if all_seqs[(label, c)]]
        finest[label] = min(done, key=lambda d: d[0])[1] if done else None
    missing = "(no sequence of three meshes finished: `scripts/numisheet93_runs.sh OUT base35 base50 base71`)"
    for label, seq in finest.items():
        text = text.replace("{{SEQUENCE_%s}}" % label.upper(),
                            sequence_table(seq, measured, label) if seq else missing)
        text = text.replace("{{THICKNESS_%s}}" % label.upper(), thickness_table(seq) if seq else missing)
    text = text.replace("{{ORDERS}}", order_check_table(all_seqs))
    thickness_svg(finest, os.path.join(DOC, "numisheet93_thickness.svg"))
    svg_chart(runs, measured, finest, os.path.join(DOC, "numisheet93.svg"))
    with open(os.path.join(DOC, "numisheet93_sequence.json"), "w") as f:
        json.dump({f"{label} {', '.join(c)}": None if seq is None else {
            "h": [h for _, _, h in seq["members"]], "extrapolations": seq["result"]}
            for (label, c), seq in all_seqs.items()}, f, indent=1)
    text = (text.replace("{{COMMIT}}", git_commit())
            .replace("{{RESULTS}}", results_table(runs, measured))
            .replace("{{DIFFERENCES}}", difference_table(runs, measured, finest))
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
