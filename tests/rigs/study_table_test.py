#!/usr/bin/env python3
"""examples/rig_study_table.py on hand-made run JSON (the fields `clumpkit rig --json` writes):
the table's rows and their mean ± std, the SPEC §8 CSV, and the discharge curves' SVG (one line
per repeat and speed, scaled to the paper's pocket). Exit status 0 on success, 1 on a failed
check. Python 3 standard library only."""
import csv
import json
import pathlib
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

script = pathlib.Path(sys.argv[1])
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def quantity(mean, std, n, unit):
    return {"mean": mean, "std": std, "n": n, "unit": unit}


with tempfile.TemporaryDirectory() as tmp:
    out = pathlib.Path(tmp)
    (out / "bd_paper_A12.json").write_text(json.dumps(
        {"scale": "mini", "quantities": {"bulk_density": quantity(724.4, 5.2, 3, "kg/m^3")}}))
    for rpm, (pocket, reps) in {10: (0.2, 2), 30: (0.17, 1)}.items():
        repeats = [{"seed": k + 1, "details": {
            "curve_time_s": [0.0, 0.5, 1.0], "curve_mass_kg": [0.0, 0.01 * rpm, 0.02 * rpm],
            "slice_to_paper_factor": 5.0}} for k in range(reps)]
        (out / f"dis_{rpm}.json").write_text(json.dumps({"scale": "mini", "repeats": repeats, "quantities": {
            "pocket_mass": quantity(pocket, 0.004 if reps > 1 else 0.0, reps, "kg"),
            "pocket_mass_cv": quantity(0.03, 0.01 if reps > 1 else 0.0, reps, "1"),
            "mass_flow": quantity(pocket * 8 * rpm / 60, 0.005 if reps > 1 else 0.0, reps, "kg/s")}}))
    p = subprocess.run([sys.executable, str(script), str(out)], capture_output=True, text=True)
    check(p.returncode == 0, f"the script exits 0 ({p.returncode}: {p.stderr.strip()[:200]})")
    md = (out / "study.md").read_text()
    check("| paper_A12 | 12 | 724 ± 5 (n=3) | not run |" in md, "bulk density row, mean ± std (n)")
    check("| production | 10 | 0.200 ± 0.004 (n=2) | 0.030 ± 0.010 | 0.267 ± 0.005 |" in md,
          "discharge at 10 rpm: two repeats give mean ± std")
    check("| production | 15 | not run | | |" in md, "a speed not run says so")
    check("| production | 30 | 0.170 (n=1) | 0.030 | 0.680 |" in md,
          "one repeat: the bare value, no spread")
    with open(out / "study.csv") as f:
        rows = list(csv.DictReader(f))
    check(len(rows) == 1 + 3 + 3, f"CSV: 1 bulk density + 2 × 3 discharge rows ({len(rows)})")
    check(any(r["setting"] == "rpm=10;scale=mini" and r["quantity"] == "pocket_mass" for r in rows),
          "CSV: SPEC §8 setting of a discharge row")
    svg = ET.parse(out / "discharge_curves.svg").getroot()
    ns = "{http://www.w3.org/2000/svg}"
    lines = svg.findall(f"{ns}polyline")
    check(len(lines) == 3, f"SVG: one line per repeat and speed ({len(lines)})")
    labels = [t.text for t in svg.findall(f"{ns}text")]
    check("10 rpm, seed 2" in labels and "30 rpm" in labels, "SVG: the legend names them")
    # The 30 rpm line ends at the top of the plot: 0.6 kg in the slice × 5 = the largest mass.
    top = [float(t.text) for t in svg.findall(f"{ns}text") if t.get("text-anchor") == "end"]
    check(abs(max(top) - 3.0) < 1e-9, f"SVG: masses scaled to the paper's pocket (top {max(top)})")
    check("discharge_curves.svg" in md, "the table names the picture")
print(f"{len(failures)} check(s) failed" if failures else "all checks passed")
sys.exit(1 if failures else 0)
