"""Writes the small hand-made IGES fixtures of tests/cad_import.rs (no CAD library):
plane_surface_190.igs, a 190 plane surface (116 point, 123 normal) trimmed by a square
loop of 110 lines (a 102 as the 142's model-space curve) in a 144;
tabulated_cylinder_122_{line,arc}.igs, a 122 of a 110 line (-10,0,0)-(10,0,0) or a 100
half circle (radius 10 about the z axis, angles 0 to pi), generatrix end L = (.., .., 20)
(so the generatrix is (0, 0, 20)), trimmed in IGES's normalised (u, v) by the square
[0.25, 0.75]^2 (a 102 of 110 lines as the 142's parameter-space curve) in a 144.
Run: python3 make_small_iges.py (in this folder)."""


def iges(entities):
    """entities: list of (type, form, params list). Pointers are 1-based entity indices,
    written as D line numbers (2 k - 1)."""
    d_lines, p_lines = [], []
    for k, (kind, form, params) in enumerate(entities):
        de = 2 * k + 1
        text = ",".join([str(kind)] + [str(x) for x in params]) + ";"
        chunks = [text[i:i + 64] for i in range(0, len(text), 64)]
        start = len(p_lines) + 1
        for c in chunks:
            p_lines.append(f"{c:<64}{de:>8}P{len(p_lines) + 1:>7}")
        d_lines.append(f"{kind:>8}{start:>8}{0:>8}{0:>8}{0:>8}{0:>8}{0:>8}{0:>8}{'00000000':>8}D{len(d_lines) + 1:>7}")
        d_lines.append(f"{kind:>8}{0:>8}{0:>8}{len(chunks):>8}{form:>8}{'':>8}{'':>8}{'':>8}{0:>8}D{len(d_lines) + 1:>7}")
    s = [f"{'tribo hand-made fixture':<72}S{1:>7}"]
    g = [f"{'1H,,1H;,,,,,32,308,15,308,15,,1.,2,2HMM,1,0.01,,1E-07,100.,,,11,0,;':<72}G{1:>7}"]
    t = [f"{'S%7dG%7dD%7dP%7d' % (1, 1, len(d_lines), len(p_lines)):<72}T{1:>7}"]
    return "\n".join(s + g + d_lines + p_lines + t) + "\n"


def de(k):
    return 2 * k + 1


corners = [(-10.0, -10.0), (10.0, -10.0), (10.0, 10.0), (-10.0, 10.0)]
ents = [
    (116, 0, [0.0, 0.0, 5.0, 0]),  # 0 location
    (123, 0, [0.0, 0.0, 2.0]),  # 1 normal (not unit)
    (190, 0, [de(0), de(1)]),  # 2 plane surface
]
for i in range(4):
    a, b = corners[i], corners[(i + 1) % 4]
    ents.append((110, 0, [a[0], a[1], 5.0, b[0], b[1], 5.0]))  # 3..6
ents.append((102, 0, [4] + [de(3 + i) for i in range(4)]))  # 7
ents.append((142, 0, [0, de(2), 0, de(7), 1]))  # 8
ents.append((144, 0, [de(2), 1, 0, de(8)]))  # 9
open("plane_surface_190.igs", "w").write(iges(ents))


for name, directrix in [
    ("line", (110, 0, [-10.0, 0.0, 0.0, 10.0, 0.0, 0.0])),
    ("arc", (100, 0, [0.0, 0.0, 0.0, 10.0, 0.0, -10.0, 0.0])),
]:
    ents = [directrix, (122, 0, [de(0), 10.0, 0.0, 20.0] if name == "arc" else [de(0), -10.0, 0.0, 20.0])]
    square = [(0.25, 0.25), (0.75, 0.25), (0.75, 0.75), (0.25, 0.75)]
    for i in range(4):
        a, b = square[i], square[(i + 1) % 4]
        ents.append((110, 0, [a[0], a[1], 0.0, b[0], b[1], 0.0]))  # 2..5
    ents.append((102, 0, [4] + [de(2 + i) for i in range(4)]))  # 6
    ents.append((142, 0, [1, de(1), de(6), 0, 1]))  # 7
    ents.append((144, 0, [de(1), 1, 0, de(7)]))  # 8
    open(f"tabulated_cylinder_122_{name}.igs", "w").write(iges(ents))
