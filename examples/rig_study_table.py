#!/usr/bin/env python3
"""One table from the JSON files of examples/rig_study.sh: study.md (markdown) and study.csv,
and the discharge curves of every speed in one picture (discharge_curves.svg)."""
import csv, json, pathlib, sys

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "study")
rows = []  # SPEC §8 rows: rig, sample, setting, quantity, value, std, n, unit, model

def load(name):
    p = out / f"{name}.json"
    return json.loads(p.read_text()) if p.exists() else None

def pm(v, digits):
    """mean ± std, or the bare value when there was one repeat (no spread to report)."""
    return f"{v[0]:.{digits}f} ± {v[1]:.{digits}f}" if v[2] > 1 else f"{v[0]:.{digits}f}"

def q(j, k):
    s = j["quantities"].get(k) if j else None
    return (s["mean"], s["std"], s["n"], s["unit"]) if s else None

models = [f"paper_{t}{n}" for t, ns in (("A", (4, 12, 20)), ("B", (4, 12, 20)), ("C", (2, 12, 18))) for n in ns]
md = ["| model | spheres | bulk density kg/m³ | angle of repose ° (left / right) |",
      "|---|---|---|---|"]
scale = None
for m in models:
    bd, aor = load(f"bd_{m}"), load(f"aor_{m}")
    scale = scale or (bd or aor or {}).get("scale")
    cells = []
    b = q(bd, "bulk_density")
    cells.append(f"{pm(b, 0)} (n={b[2]})" if b else (bd or {}).get("error", "not run")[:60])
    a, al, ar = q(aor, "angle"), q(aor, "angle_left"), q(aor, "angle_right")
    cells.append(f"{pm(a, 1)} ({al[0]:.1f} / {ar[0]:.1f}, n={a[2]})" if a else
                 (aor or {}).get("error", "not run")[:60])
    md.append(f"| {m} | {m.split('_')[1][1:]} | " + " | ".join(cells) + " |")
    for rig, j, ks in (("bulk_density", bd, ["bulk_density"]), ("angle_of_repose", aor, ["angle", "angle_left", "angle_right"])):
        for k in ks:
            v = q(j, k)
            if v: rows.append([rig, m.split("_")[1][0], f"scale={j['scale']}", k, *v, m])
md += ["", "| model | rpm | pocket mass kg (paper pocket) | CV | mass flow kg/s |", "|---|---|---|---|---|"]
discharges = []  # (rpm, run JSON) of the speeds run, for the curves below
for rpm in (10, 15, 30):
    d = load(f"dis_{rpm}")
    if d:
        discharges.append((rpm, d))
        scale = scale or d.get("scale")  # a study of the discharger alone (--rigs discharge)
    m_, cv, mf = q(d, "pocket_mass"), q(d, "pocket_mass_cv"), q(d, "mass_flow")
    if m_:
        md.append(f"| production | {rpm} | {pm(m_, 3)} (n={m_[2]}) | {pm(cv, 3)} | {pm(mf, 3)} |")
        for k, v in (("pocket_mass", m_), ("pocket_mass_cv", cv), ("mass_flow", mf)):
            rows.append(["discharge", "mix", f"rpm={rpm};scale={d['scale']}", k, *v, "production"])
    else:
        md.append(f"| production | {rpm} | {(d or {}).get('error', 'not run')[:60]} | | |")
md.insert(0, f"Scale: {scale}; mean ± standard deviation over the repeats (n).\n")
with open(out / "study.csv", "w", newline="") as f:
    w = csv.writer(f)
    # SPEC §8 measurement columns (clumpkit compare reads them) plus the model.
    w.writerow(["rig", "sample", "setting", "quantity", "value", "std", "n", "unit", "model"])
    w.writerows(rows)


def curves_svg(runs, path):
    """Discharged mass against time since the wheel started, every repeat of every speed, scaled
    to the paper's 100 mm pocket (the runs' slice_to_paper_factor). A self-contained SVG."""
    lines = []  # (label, colour, [(t, m)])
    colours = {10: "#1f77b4", 15: "#2ca02c", 30: "#d62728"}
    for rpm, d in runs:
        for r in d.get("repeats", []):
            det = r.get("details", {})
            t, m = det.get("curve_time_s"), det.get("curve_mass_kg")
            if not t or not m:
                continue
            f = det.get("slice_to_paper_factor", 1.0)
            lines.append((f"{rpm} rpm" + (f", seed {r['seed']}" if len(d["repeats"]) > 1 else ""),
                          colours.get(rpm, "#555"), [(a, b * f) for a, b in zip(t, m)]))
    if not lines:
        return False
    tmax = max(p[0] for _, _, pts in lines for p in pts) or 1.0
    mmax = max(p[1] for _, _, pts in lines for p in pts) or 1.0
    W, H, L, B, R, T = 720, 440, 80, 60, 30, 30
    X = lambda t: L + (W - L - R) * max(t, 0.0) / tmax
    Y = lambda m: H - B - (H - B - T) * m / mmax
    o = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="13">',
         f'<rect width="{W}" height="{H}" fill="white"/>',
         f'<line x1="{L}" y1="{H - B}" x2="{W - R}" y2="{H - B}" stroke="black"/>',
         f'<line x1="{L}" y1="{T}" x2="{L}" y2="{H - B}" stroke="black"/>']
    for i in range(6):
        t, m = tmax * i / 5, mmax * i / 5
        o.append(f'<text x="{X(t):.1f}" y="{H - B + 18}" text-anchor="middle">{t:.2g}</text>')
        o.append(f'<text x="{L - 6}" y="{Y(m) + 4:.1f}" text-anchor="end">{m:.3g}</text>')
        o.append(f'<line x1="{L}" y1="{Y(m):.1f}" x2="{W - R}" y2="{Y(m):.1f}" stroke="#ddd"/>')
    o.append(f'<text x="{(L + W - R) / 2}" y="{H - 15}" text-anchor="middle">time since the wheel started, s</text>')
    o.append(f'<text transform="translate(18,{(T + H - B) / 2}) rotate(-90)" text-anchor="middle">'
             'discharged mass per 100 mm of wheel, kg</text>')
    for k, (label, colour, pts) in enumerate(lines):
        xy = " ".join(f"{X(a):.1f},{Y(b):.1f}" for a, b in pts)
        o.append(f'<polyline fill="none" stroke="{colour}" stroke-width="2" points="{xy}"/>')
        o.append(f'<text x="{L + 12}" y="{T + 16 + 16 * k}" fill="{colour}">{label}</text>')
    o.append("</svg>")
    path.write_text("\n".join(o) + "\n")
    return True


if curves_svg(discharges, out / "discharge_curves.svg"):
    md.append("\nThe discharge curves of every speed: discharge_curves.svg")
(out / "study.md").write_text("\n".join(md) + "\n")
print("\n".join(md))
