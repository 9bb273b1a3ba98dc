#!/usr/bin/env python3
"""One table from the JSON files of examples/rig_study.sh: study.md (markdown) and study.csv."""
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
for rpm in (10, 15, 30):
    d = load(f"dis_{rpm}")
    m_, cv, mf = q(d, "pocket_mass"), q(d, "pocket_mass_cv"), q(d, "mass_flow")
    if m_:
        md.append(f"| production | {rpm} | {pm(m_, 3)} (n={m_[2]}) | {pm(cv, 3)} | {pm(mf, 3)} |")
        for k, v in (("pocket_mass", m_), ("pocket_mass_cv", cv), ("mass_flow", mf)):
            rows.append(["discharge", "mix", f"rpm={rpm};scale={d['scale']}", k, *v, "production"])
    else:
        md.append(f"| production | {rpm} | {(d or {}).get('error', 'not run')[:60]} | | |")
md.insert(0, f"Scale: {scale}; mean ± standard deviation over the repeats (n).\n")
(out / "study.md").write_text("\n".join(md) + "\n")
with open(out / "study.csv", "w", newline="") as f:
    w = csv.writer(f)
    # SPEC §8 measurement columns (clumpkit compare reads them) plus the model.
    w.writerow(["rig", "sample", "setting", "quantity", "value", "std", "n", "unit", "model"])
    w.writerows(rows)
print("\n".join(md))
