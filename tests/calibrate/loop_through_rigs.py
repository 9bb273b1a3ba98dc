#!/usr/bin/env python3
"""The compare -> diagnose -> apply -> compare loop through the real rigs (issue 7), end to end.

A truth model (pill A, 12 spheres, rolling friction mu_r = 0.2 on every pair) makes synthetic
lab data with `clumpkit synth` (3 % noise, 3 lab repeats, angle of repose on three plates). A
baseline with the effect held at a low value (mu_r = 0.05: with none at all this small heap
spreads flat and has no angle) is diagnosed against it with `clumpkit diagnose --apply` over two
candidates that both raise a heap (rolling friction and wall friction), then the baseline and the
applied model are compared with `clumpkit compare`. Checked:

  * the hidden effect is ranked first and is the verdict; the fitted mu_r is within 2 of its
    stated standard deviations of the truth (the stated uncertainty carries the simulation's
    pooled seed-to-seed spread) and inside its physical range;
  * chi2/dof falls from the baseline to the applied model, to within noise (<= 2 for these three
    observables: the truth itself scores chi2/dof > 2 one time in nine);
  * the applied model file names the effect at the fitted value, and a second diagnose run of
    the same command is served wholly from the cache (nothing is simulated twice).

Scale: every rig run is the `tiny` angle of repose (~185 pills) with the pill's Young's modulus
lowered from 1.1e8 to 1e7 Pa (a softer pill allows a 3x larger time step: a test-size reduction;
the angle changes little with stiffness at these loads), so the whole loop is ~70 rig runs of a
few seconds, side by side on the machine's cores. Python 3 standard library only. Exit status 0
on success, 1 on a failed check, 2 on a run error.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys

TRUTH_MU_R = 0.2
BASE_MU_R = 0.05


def model_text(name, mu_r, source):
    walls = ["pill", "abs_plastic", "organic_glass", "galvanized_steel"]
    return "\n".join([
        "[model]",
        f'name = "{name}"',
        'materials = "materials_soft.toml"',
        'mass_basis = "sphere_union"',
        "[[types]]",
        'name = "A"',
        f'shape = "{os.path.join(source, "shapes", "pill_A.toml")}"',
        "paper_spheres = 12",
        "[effects]",
        "restitution = true",
        "particle_friction = true",
        "wall_friction = true",
        "[effects.rolling_friction]",
    ] + [f"{w} = {mu_r}" for w in walls]) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clumpkit", required=True)
    ap.add_argument("--source", required=True, help="the repository (for shapes/)")
    ap.add_argument("--work", required=True, help="scratch folder (emptied first)")
    ap.add_argument("--jobs", default="0", help="rig runs side by side (0 = one per core)")
    ap.add_argument("--keep-cache", action="store_true",
                    help="keep WORK/cache from an earlier run (same engine only)")
    a = ap.parse_args()
    a.clumpkit = os.path.abspath(a.clumpkit)
    a.source = os.path.abspath(a.source)

    if a.keep_cache and os.path.isdir(os.path.join(a.work, "cache")):
        for entry in os.listdir(a.work):
            if entry != "cache":
                p = os.path.join(a.work, entry)
                shutil.rmtree(p) if os.path.isdir(p) else os.remove(p)
    else:
        shutil.rmtree(a.work, ignore_errors=True)
        os.makedirs(a.work)
    w = lambda *p: os.path.join(a.work, *p)
    with open(os.path.join(a.source, "shapes", "materials.toml")) as f:
        materials = f.read()
    soft = materials.replace('youngs_modulus = "1.100e8 Pa"', 'youngs_modulus = "1.0e7 Pa"')
    if soft == materials:
        print("FAIL: the pill's Young's modulus line was not found in shapes/materials.toml")
        return 2
    with open(w("materials_soft.toml"), "w") as f:
        f.write(soft)
    with open(w("truth.toml"), "w") as f:
        f.write(model_text("A12_truth", TRUTH_MU_R, a.source))
    with open(w("base.toml"), "w") as f:
        f.write(model_text("A12_base", BASE_MU_R, a.source))
    with open(w("template.csv"), "w") as f:
        f.write("rig,sample,setting,quantity,value,std,n,unit\n"
                "angle_of_repose,A,plate=galvanized_steel,angle,30,1,3,deg\n"
                "angle_of_repose,A,plate=abs_plastic,angle,30,1,3,deg\n"
                "angle_of_repose,A,plate=organic_glass,angle,30,1,3,deg\n")

    common = ["--scale", "tiny", "--cache", w("cache"), "--jobs", a.jobs, "--quiet"]

    def run(*args):
        cmd = [a.clumpkit, *args]
        print("$ " + " ".join(cmd), flush=True)
        p = subprocess.run(cmd, cwd=a.work, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           text=True)
        print(p.stdout, flush=True)
        if p.returncode != 0:
            print(f"FAIL: exit status {p.returncode}")
            sys.exit(2)
        return p.stdout

    # The truth's mean from 2 repeats; synth states an std that covers their standard error (the
    # seed-to-seed spread pooled over the three plates).
    run("synth", "--model", "truth.toml", "--measurements-template", "template.csv",
        "--noise", "0.03", "--seed", "7", "--repeats", "2", "-o", "lab.csv", *common)
    run("diagnose", "--model", "base.toml", "--measurements", "lab.csv", "--effects",
        "rolling_friction,wall_friction", "--no-suggest", "--apply", "-o", "v2.toml", "--json",
        "diag.json", *common)
    again = run("diagnose", "--model", "base.toml", "--measurements", "lab.csv", "--effects",
                "rolling_friction,wall_friction", "--no-suggest", "--json", "diag2.json", *common)
    run("compare", "--model", "base.toml", "--model", "v2.toml", "--measurements", "lab.csv",
        "--json", "cmp.json", *common)

    failures = []

    def check(ok, what):
        print(("ok   " if ok else "FAIL ") + what)
        if not ok:
            failures.append(what)

    with open(w("diag.json")) as f:
        d = json.load(f)
    with open(w("diag2.json")) as f:
        d2 = json.load(f)
    with open(w("cmp.json")) as f:
        c = json.load(f)
    top = d["candidates"][0]
    fit, sd = top["fitted"]["value"], top["fitted"]["std"]
    check(top["effect"] == "rolling_friction",
          f"the hidden effect ranks first (first: {top['effect']})")
    check(d["verdict"]["effect"] == "rolling_friction",
          f"the verdict names it (verdict: {d['verdict']['effect']})")
    check(top["plausible"], "its fitted value is inside the physical range")
    check(sd > 0 and abs(fit - TRUTH_MU_R) <= 2 * sd,
          f"fitted mu_r {fit:.4f} +/- {sd:.4f} is within 2 sigma of the truth {TRUTH_MU_R}")
    chain = {m["model"]: m["chi2_per_dof"] for m in c["chain"]}
    before, after = chain["A12_base"], chain["A12_base+rolling_friction"]
    check(after < before, f"chi2/dof falls: {before:.2f} -> {after:.2f}")
    check(after <= 2.0, f"chi2/dof of the applied model {after:.2f} <= 2 (within noise)")
    check(d2["simulations"] == 0 and "0 rig runs simulated" in again,
          f"a second diagnose is served from the cache ({d2['simulations']} runs)")
    with open(w("v2.toml")) as f:
        v2 = f.read()
    held = re.search(r"\[effects\.rolling_friction\][^\[]*?pill = ([0-9.eE+-]+)", v2)
    check(held is not None and abs(float(held.group(1)) - fit) <= 1e-6 * max(1.0, abs(fit)),
          f"the applied model holds pill-pill rolling friction at the fitted value "
          f"({held.group(1) if held else 'not found'})")
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
