#!/usr/bin/env python3
"""Benchmark of the diagnosis loop through the real rigs over the whole effect catalogue (issue 7).

For each hidden effect (and for none), a truth model makes synthetic lab data with
`clumpkit synth`; `clumpkit diagnose --apply` runs over the whole catalogue (no --effects) from
a baseline without the effect; `clumpkit compare` shows the chain baseline -> applied model.
Measurements: the angle of repose on the three plates and the bulk density in the organic-glass
cup (--cups: in cups of other wall materials too; --discharge: the discharger's mass flow at
the given wheel speeds), pill A with 12 spheres (paper rule), Table 1
materials with the pill's Young's modulus lowered to --youngs (default 1e7 Pa; the paper's
1.1e8 Pa with --youngs 1.1e8). --plates, --cups and --discharge choose the measurements,
--effects narrows the diagnosis (default: the whole catalogue).

Cases (truth vs baseline; every other effect as in Table 1):
  rolling_friction   mu_r 0.2 on every pair, baseline 0.05 (with none the small heap spreads flat)
  cohesion           simplified-JKR energy density 2e4 J/m^3 pill-pill, baseline none
  wall_friction      mu_s pill-wall 0.9 on every wall, baseline 0.3
  shape_resolution   4 spheres per pill, baseline 12
  particle_friction  mu_s pill-pill 0.2, baseline Table 1's 0.466
  restitution        e 0.7 on every pair, baseline Table 1's 0.20-0.31
  rolling_model      LIGGGHTS' CDT rolling model, baseline the standard one (eq. 2), both at
                     Table 1's mu_r
  size_distribution  a height spread of 0.15 (mass-weighted relative std), baseline one height
  none               truth = baseline (the diagnosis must not give a verdict)
  rolling_friction+cohesion
                     two effects hidden at once: mu_r 0.2 on every pair and a cohesion of
                     5000 J/m^3, baseline mu_r 0.05 without cohesion (a pair needs at least 5
                     observables: add cups, e.g. --cups abs_plastic,organic_glass,galvanized_steel)

Writes OUT/results.md (a table) and OUT/<case>/ (models, data, JSON, HTML reports); the rig
results are cached in OUT/cache, shared by the cases, so a second run of the script simulates
nothing. Prints the wall time per case. Python 3 standard library only.

  python3 bench/diagnose_bench.py --clumpkit build/apps/clumpkit/clumpkit --out diag_bench \\
      [--scale tiny|mini] [--cases rolling_friction,cohesion] [--jobs 0] [--no-suggest] [--discharge 15]
      [--plates abs_plastic] [--cups ""] [--effects wall_friction,particle_friction]
      [--truth 0.12]     (the hidden strength, instead of the case's own above)
"""
import argparse
import json
import os
import subprocess
import sys
import time

WALLS = ["abs_plastic", "organic_glass", "galvanized_steel"]


def model(name, source, materials, extra):
    """Pill A, 12 spheres, Table 1 effects; `extra` maps effect -> TOML lines replacing it."""
    lines = ["[model]", f'name = "{name}"', f'materials = "{materials}"',
             'mass_basis = "sphere_union"', "[[types]]", 'name = "A"',
             f'shape = "{os.path.join(source, "shapes", "pill_A.toml")}"', "paper_spheres = 12",
             "[effects]"]
    tables = []
    for e in ["restitution", "particle_friction", "wall_friction", "rolling_friction"]:
        if e in extra:
            tables += [f"[effects.{e}]"] + extra[e]
        else:
            lines.append(f"{e} = true")
    for e in ["cohesion", "shape_resolution", "rolling_model", "size_distribution"]:
        if e in extra:
            tables += [f"[effects.{e}]"] + extra[e]
    return "\n".join(lines + tables) + "\n"


def per_partner(value, partners):
    return [f"{p} = {value}" for p in partners]


# case: (truth effects, baseline effects, truth value) for a hidden strength v (None: the
# case's default, the first number in each lambda's signature).
CASES = {
    "rolling_friction": lambda v=0.2: (
        {"rolling_friction": per_partner(v, ["pill"] + WALLS)},
        {"rolling_friction": per_partner(0.05, ["pill"] + WALLS)}, v),
    "cohesion": lambda v=2e4: ({"cohesion": [f'energy_density = "{v:g} J/m^3"']}, {}, v),
    "wall_friction": lambda v=0.9: ({"wall_friction": per_partner(v, WALLS)},
                                    {"wall_friction": per_partner(0.3, WALLS)}, v),
    "shape_resolution": lambda v=4: ({"shape_resolution": [f"spheres = {int(v)}"]}, {}, int(v)),
    "particle_friction": lambda v=0.2: ({"particle_friction": [f"value = {v}"]}, {}, v),
    "restitution": lambda v=0.7: ({"restitution": per_partner(v, ["pill"] + WALLS)}, {}, v),
    "rolling_model": lambda v=None: ({"rolling_model": ['model = "cdt"']}, {}, "cdt"),
    "size_distribution": lambda v=0.15: (
        {"size_distribution": [f"height_spread = {v}"]}, {}, v),
    "none": lambda v=None: ({}, {}, None),
    "rolling_friction+cohesion": lambda v=None: (
        {"rolling_friction": per_partner(0.2, ["pill"] + WALLS),
         "cohesion": ['energy_density = "5000 J/m^3"']},
        {"rolling_friction": per_partner(0.05, ["pill"] + WALLS)}, "0.2 + 5000 J/m^3"),
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clumpkit", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--source", default=os.path.join(os.path.dirname(__file__), ".."))
    ap.add_argument("--scale", default="tiny")
    ap.add_argument("--youngs", default="1.0e7", help="pill Young's modulus, Pa")
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--jobs", default="0")
    ap.add_argument("--noise", default="0.03")
    ap.add_argument("--cups", default="organic_glass",
                    help="wall materials of the bulk-density cups measured (comma-separated; "
                         "all three: abs_plastic,organic_glass,galvanized_steel)")
    ap.add_argument("--plates", default=",".join(WALLS),
                    help="plate materials of the angle-of-repose measurements (comma-separated; "
                         "empty for none)")
    ap.add_argument("--effects", default="",
                    help="narrow the diagnosis to these effects (comma-separated; default: the "
                         "whole catalogue)")
    ap.add_argument("--discharge", default="",
                    help="wheel speeds (rpm, comma-separated) at which the discharger's mass flow "
                         "is measured too (e.g. 15); none by default. Not the pocket mass: "
                         "it is the mass flow times the pocket period, the same measurement")
    ap.add_argument("--truth", type=float, default=None,
                    help="the hidden strength of the case(s) (default: each case's own, in the "
                         "list above); not for rolling_model, none and the pair")
    ap.add_argument("--no-suggest", action="store_true",
                    help="skip the next-measurement suggestion (its trial runs)")
    a = ap.parse_args()
    fixed = {"rolling_model", "none", "rolling_friction+cohesion"}
    if a.truth is not None and fixed & set(a.cases.split(",")):
        ap.error("--truth: the cases " + ", ".join(sorted(fixed)) + " have no strength to set")
    ck, src, out = (os.path.abspath(p) for p in (a.clumpkit, a.source, a.out))
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(src, "shapes", "materials.toml")) as f:
        mats = f.read()
    soft = mats.replace('youngs_modulus = "1.100e8 Pa"', f'youngs_modulus = "{a.youngs} Pa"')
    materials = os.path.join(out, "materials.toml")
    with open(materials, "w") as f:
        f.write(soft)
    common = ["--scale", a.scale, "--cache", os.path.join(out, "cache"), "--jobs", a.jobs]
    rows = []
    for case in a.cases.split(","):
        truth_fx, base_fx, truth_value = (CASES[case]() if a.truth is None
                                          else CASES[case](a.truth))
        d = os.path.join(out, case)
        os.makedirs(d, exist_ok=True)
        for name, fx in (("truth", truth_fx), ("base", base_fx)):
            with open(os.path.join(d, name + ".toml"), "w") as f:
                f.write(model(f"A12_{name}_{case}" if name == "truth" else "A12_base_" + case,
                              src, materials, fx))
        with open(os.path.join(d, "template.csv"), "w") as f:
            f.write("rig,sample,setting,quantity,value,std,n,unit\n" + "".join(
                f"angle_of_repose,A,plate={p},angle,30,1,3,deg\n"
                for p in filter(None, a.plates.split(","))) + "".join(
                f"bulk_density,A,wall={c},bulk_density,700,10,3,kg/m^3\n"
                for c in filter(None, a.cups.split(","))) + "".join(
                f"discharge,A,rpm={r},mass_flow,0.3,0.01,3,kg/s\n"
                for r in filter(None, a.discharge.split(","))))

        def run(*args):
            with open(os.path.join(d, "log.txt"), "a") as log:
                p = subprocess.run([ck, *args], cwd=d, stdout=log, stderr=subprocess.STDOUT)
            if p.returncode != 0:
                sys.exit(f"{case}: clumpkit {args[0]} failed ({p.returncode}); see {d}/log.txt")

        t0 = time.time()
        run("synth", "--model", "truth.toml", "--measurements-template", "template.csv",
            "--noise", a.noise, "--seed", "7", "--repeats", "4", "-o", "lab.csv", *common)
        t1 = time.time()
        run("diagnose", "--model", "base.toml", "--measurements", "lab.csv", "--apply", "-o",
            "v2.toml", "--json", "diag.json", "--report", "report", *common,
            *(["--effects", a.effects] if a.effects else []),
            *(["--no-suggest"] if a.no_suggest else []))
        t2 = time.time()
        # The same diagnosis again: every rig run is served by the cache (issue 7 asks for both
        # times).
        run("diagnose", "--model", "base.toml", "--measurements", "lab.csv", "--json",
            "diag_again.json", *common, *(["--effects", a.effects] if a.effects else []),
            *(["--no-suggest"] if a.no_suggest else []))
        t3 = time.time()
        with open(os.path.join(d, "diag_again.json")) as f:
            again_runs = json.load(f)["simulations"]
        with open(os.path.join(d, "diag.json")) as f:
            dj = json.load(f)
        chain = {}
        if dj["verdict"]["effect"]:
            run("compare", "--model", "base.toml", "--model", "v2.toml", "--measurements",
                "lab.csv", "--json", "cmp.json", *common)
            with open(os.path.join(d, "cmp.json")) as f:
                chain = {m["model"]: m["chi2_per_dof"] for m in json.load(f)["chain"]}
        top = dj["candidates"][0] if dj["candidates"] else None
        rows.append({
            "case": case, "truth": truth_value,
            "verdict": dj["verdict"]["effect"] or "(consistent)",
            "confidence": dj["verdict"]["confidence"],
            "top": top["effect"] if top else "-",
            "fitted": top["fitted"]["value"] if top else None,
            "fitted_std": top["fitted"]["std"] if top else None,
            "with": top.get("with") if top else None,
            "chi2dof_base": dj.get("baseline", {}).get("chi2_per_dof"),
            "chi2dof_after": list(chain.values())[-1] if chain else None,
            "runs": dj["simulations"], "synth_s": t1 - t0, "diagnose_s": t2 - t1,
            "again_s": t3 - t2, "again_runs": again_runs,
            "skipped": dj.get("skipped", [])})
        r = rows[-1]
        with_text = (f" with {r['with']['effect']} {r['with']['fitted']['value']} +/- "
                     f"{r['with']['fitted']['std']}" if r.get("with") else "")
        print(f"{case}: verdict {r['verdict']} (top {r['top']} {r['fitted']} +/- "
              f"{r['fitted_std']}{with_text}, truth {truth_value}), chi2/dof {r['chi2dof_base']} -> "
              f"{r['chi2dof_after']}, {r['runs']} rig runs, synth {r['synth_s']:.0f} s, "
              f"diagnose {r['diagnose_s']:.0f} s, again from the cache {r['again_s']:.1f} s "
              f"({r['again_runs']} runs)", flush=True)
        with open(os.path.join(out, "results.json"), "w") as f:
            json.dump(rows, f, indent=1)
    with open(os.path.join(out, "results.md"), "w") as f:
        f.write(f"scale {a.scale}, pill Young's modulus {a.youngs} Pa, noise {a.noise}, "
                f"diagnose over {a.effects or 'the whole catalogue'}, 2 repeats, synth 4 repeats\n\n"
                "| hidden effect | verdict (confidence) | top candidate: fitted ± std | truth | "
                "χ²/dof baseline → applied | rig runs | diagnose wall time | again (cache) |\n"
                "|---|---|---|---|---|---|---|---|\n")
        for r in rows:
            fit = (f"{r['top']}: {r['fitted']:.4g} ± {r['fitted_std']:.2g}"
                   if r["fitted"] is not None else r["top"])
            if r.get("with"):
                fit += (f" with {r['with']['fitted']['value']:.4g} ± "
                        f"{r['with']['fitted']['std']:.2g}")
            after = f"{r['chi2dof_after']:.2f}" if r["chi2dof_after"] is not None else "-"
            base = f"{r['chi2dof_base']:.2f}" if r["chi2dof_base"] is not None else "-"
            f.write(f"| {r['case']} | {r['verdict']} ({r['confidence']:.2f}) | {fit} | "
                    f"{r['truth'] if r['truth'] is not None else '-'} | {base} → {after} | "
                    f"{r['runs']} | {r['diagnose_s'] / 60:.1f} min | {r['again_s']:.1f} s, "
                    f"{r['again_runs']} runs |\n")
    print(f"wrote {os.path.join(out, 'results.md')}")


if __name__ == "__main__":
    main()
