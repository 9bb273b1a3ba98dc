#!/usr/bin/env python3
"""The compare -> diagnose -> apply -> compare loop through the real rigs (issue 7), end to end.

One case per run (--case):

  rolling_friction  truth mu_r = 0.2 on every pair, baseline 0.05; candidates rolling friction
                    and wall friction (both raise a heap); the heaps on three plates measured;
  cohesion          truth: the baseline (mu_r 0.05) plus a simplified-JKR cohesion of
                    6000 J/m^3; candidates cohesion and rolling friction (both raise the heap;
                    cohesion also opens up the packing, rolling friction barely: the cup tells
                    them apart); the heaps on three plates and the organic-glass cup measured;
  none              truth = baseline (mu_r 0.2): nothing is missing; candidates rolling friction
                    and cohesion; the heaps and the cup measured.
  size_distribution a mixture of pill A and a wider tablet D (8 mm x 4 mm, paper rule) whose lab
                    sample held 70 % A by mass where the model file says 40 %, Table 1's
                    rolling friction; candidates size_distribution (A's
                    mass fraction, and the height spread) and rolling friction; the heaps and
                    the cups of organic glass and galvanized steel, all of sample "mix"
                    (session 45: A's share 0.669 +/- 0.060, chi2/dof 12.90 -> 1.20; before the
                    surrogate weighed its points by their own scatter, 0.667 +/- 0.008, the
                    stated uncertainty 7 times too small: docs/calibrate.md).

A truth model (pill A, 12 spheres; with D for the mixture) makes synthetic lab data with `clumpkit synth` (3 % noise, 2
truth repeats); the baseline is diagnosed against it with `clumpkit diagnose --apply`, then the
baseline and the applied model are compared with `clumpkit compare`. Checked, with an effect
hidden:

  * the hidden effect is ranked first and is the verdict; the fitted strength is within 2 of its
    stated standard deviations of the truth (the stated uncertainty carries the simulation's
    pooled seed-to-seed spread) and inside its physical range;
  * chi2/dof falls from the baseline to the applied model, to within noise (<= 2 for these three
    or four observables: the truth itself scores chi2/dof > 2 about one time in nine);
  * the applied model file holds the effect at the fitted value;

and with nothing hidden: no verdict (the diagnosis calls the model consistent), no model is
written by --apply, and the baseline's chi2/dof is within noise. In every case a second diagnose
run of the same command is served wholly from the cache (nothing is simulated twice).

Scale: every rig run is `tiny` (~185 pills on a plate, ~250 in the cup) with the pill's Young's
modulus lowered from 1.1e8 to 1e7 Pa (a softer pill allows a 3x larger time step: a test-size
reduction; the angle changes little with stiffness at these loads), so a case is 40-80 rig runs
of a few seconds, side by side on the machine's cores. Python 3 standard library only. Exit
status 0 on success, 1 on a failed check, 2 on a run error.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys

PLATES = ["galvanized_steel", "abs_plastic", "organic_glass"]
HEAPS = "".join(f"angle_of_repose,A,plate={p},angle,30,1,3,deg\n" for p in PLATES)
CUP = "bulk_density,A,wall=organic_glass,bulk_density,700,10,3,kg/m^3\n"

# case: truth and baseline (mu_r, cohesion J/m^3 or None[, pill A's mass fraction in a mixture
# with tablet D]), candidates, measurements, the hidden effect and its truth value (None: nothing
# hidden).
CASES = {
    "rolling_friction": dict(truth=(0.2, None), base=(0.05, None),
                             effects="rolling_friction,wall_friction", template=HEAPS,
                             hidden="rolling_friction", value=0.2),
    "cohesion": dict(truth=(0.05, 6000.0), base=(0.05, None), effects="cohesion,rolling_friction",
                     template=HEAPS + CUP, hidden="cohesion", value=6000.0),
    "none": dict(truth=(0.2, None), base=(0.2, None), effects="rolling_friction,cohesion",
                 template=HEAPS + CUP, hidden=None, value=None),
    "size_distribution": dict(truth=(None, None, 0.7), base=(None, None, 0.4),
                              effects="size_distribution,rolling_friction",
                              # sample "mix": a sample named A is pill A alone
                              template=(HEAPS + CUP + CUP.replace("organic_glass",
                                                                  "galvanized_steel")
                                        ).replace(",A,", ",mix,"),
                              hidden="size_distribution", value=0.7,
                              parameter="mass fraction of type A", truth_repeats=4),
}

# Tablet D of the mixture case: wider and flatter than pill A.
TABLET_D = """[shape]
name = "tablet_D"
kind = "cylinder"
diameter = "8.0 mm"
height = "4.0 mm"
[material]
name = "pill"
density = "1380 kg/m^3"
"""


def model_text(name, mu_r, cohesion, source, share_a=None):
    walls = ["pill", "abs_plastic", "organic_glass", "galvanized_steel"]
    lines = [
        "[model]",
        f'name = "{name}"',
        'materials = "materials_soft.toml"',
        'mass_basis = "sphere_union"',
        "[[types]]",
        'name = "A"',
        f'shape = "{os.path.join(source, "shapes", "pill_A.toml")}"',
        "paper_spheres = 12",
    ]
    if share_a is not None:
        lines += [f"mass_fraction = {share_a}", "[[types]]", 'name = "D"',
                  'shape = "tablet_D.toml"', "paper_spheres = 12",
                  f"mass_fraction = {1 - share_a:.10g}"]
    lines += [
        "[effects]",
        "restitution = true",
        "particle_friction = true",
        "wall_friction = true",
    ] + (["size_distribution = true"] if share_a is not None else [])
    # mu_r None: Table 1's values (0.08 pill-pill, 0.05-0.12 pill-wall).
    lines += (["rolling_friction = true"] if mu_r is None else
              ["[effects.rolling_friction]"] + [f"{w} = {mu_r}" for w in walls])
    if cohesion is not None:
        lines += ["[effects.cohesion]", f'energy_density = "{cohesion} J/m^3"']
    return "\n".join(lines) + "\n"


# The value the applied model file holds for the effect (pill-pill where per partner).
APPLIED = {
    "rolling_friction": r"\[effects\.rolling_friction\][^\[]*?pill = ([0-9.eE+-]+)",
    "cohesion": r"\[effects\.cohesion\][^\[]*?energy_density = \"([0-9.eE+-]+) J/m\^3\"",
    "size_distribution": r"name = \"A\"[^\[]*?mass_fraction = ([0-9.eE+-]+)",
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clumpkit", required=True)
    ap.add_argument("--source", required=True, help="the repository (for shapes/)")
    ap.add_argument("--work", required=True, help="scratch folder (emptied first)")
    ap.add_argument("--case", choices=sorted(CASES), default="rolling_friction")
    ap.add_argument("--jobs", default="0", help="rig runs side by side (0 = one per core)")
    ap.add_argument("--all-effects", action="store_true",
                    help="diagnose over the whole effect catalogue, not the case's candidates")
    ap.add_argument("--keep-cache", action="store_true",
                    help="keep WORK/cache from an earlier run (same engine only)")
    a = ap.parse_args()
    a.clumpkit = os.path.abspath(a.clumpkit)
    a.source = os.path.abspath(a.source)
    case = CASES[a.case]

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
    with open(w("tablet_D.toml"), "w") as f:
        f.write(TABLET_D)
    with open(w("truth.toml"), "w") as f:
        f.write(model_text("A12_truth", *case["truth"][:2], a.source, *case["truth"][2:]))
    with open(w("base.toml"), "w") as f:
        f.write(model_text("A12_base", *case["base"][:2], a.source, *case["base"][2:]))
    with open(w("template.csv"), "w") as f:
        f.write("rig,sample,setting,quantity,value,std,n,unit\n" + case["template"])

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
    # seed-to-seed spread pooled over the rig settings).
    # A mixture's cups scatter more from seed to seed (two sizes of tablet: 12-14 kg/m^3 at tiny
    # against ~6 for pill A alone), so its truth takes synth's default of 4 repeats: from 2 the
    # spread that synth's stated std must cover was estimated at 9 kg/m^3 and the lab values
    # drew 1.7 of their stated std low (the fit 3.5 stated sigma from the truth; session 44).
    run("synth", "--model", "truth.toml", "--measurements-template", "template.csv",
        "--noise", "0.03", "--seed", "7", "--repeats", str(case.get("truth_repeats", 2)),
        "-o", "lab.csv", *common)
    narrowed = [] if a.all_effects else ["--effects", case["effects"]]
    diagnose = ["diagnose", "--model", "base.toml", "--measurements", "lab.csv", *narrowed,
                "--no-suggest"]
    run(*diagnose, "--apply", "-o", "v2.toml", "--json", "diag.json", *common)
    again = run(*diagnose, "--json", "diag2.json", *common)
    hidden = case["hidden"]
    models = ["--model", "base.toml"] + (["--model", "v2.toml"] if hidden else [])
    run("compare", *models, "--measurements", "lab.csv", "--json", "cmp.json", *common)

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
    # Two models give a chain; one model, its own comparison.
    chain = ({m["model"]: m["chi2_per_dof"] for m in c["chain"]} if "chain" in c
             else {c["model"]: c["chi2_per_dof"]})
    before = chain["A12_base"]
    if hidden:
        top = d["candidates"][0]
        fit, sd = top["fitted"]["value"], top["fitted"]["std"]
        truth = case["value"]
        check(top["effect"] == hidden, f"the hidden effect ranks first (first: {top['effect']})")
        if "parameter" in case:
            check(case["parameter"] in top["parameter"],
                  f"in its form: {case['parameter']} (first: {top['parameter']})")
        check(d["verdict"]["effect"] == hidden,
              f"the verdict names it (verdict: {d['verdict']['effect']})")
        check(top["plausible"], "its fitted value is inside the physical range")
        check(sd > 0 and abs(fit - truth) <= 2 * sd,
              f"fitted {hidden} {fit:.4g} +/- {sd:.4g} is within 2 sigma of the truth {truth:g}")
        after = chain.get(f"A12_base+{hidden}", float("inf"))
        check(after < before, f"chi2/dof falls: {before:.2f} -> {after:.2f}")
        check(after <= 2.0, f"chi2/dof of the applied model {after:.2f} <= 2 (within noise)")
        with open(w("v2.toml")) as f:
            v2 = f.read()
        held = re.search(APPLIED[hidden], v2)
        check(held is not None and abs(float(held.group(1)) - fit) <= 1e-6 * max(1.0, abs(fit)),
              f"the applied model holds {hidden} at the fitted value "
              f"({held.group(1) if held else 'not found'})")
    else:
        check(d["verdict"]["consistent"] and d["verdict"]["effect"] is None,
              f"no false verdict (verdict: {d['verdict']})")
        check(not os.path.exists(w("v2.toml")), "--apply writes no model when nothing is missing")
        check(before <= 2.0, f"the baseline's chi2/dof {before:.2f} <= 2 (within noise)")
    # The baseline holds Table 1's pill-wall friction per wall: a wall-friction candidate reports
    # the value every wall gets at its fit (galvanized steel's is the parameter); a uniform
    # baseline's candidates (rolling friction here) report none.
    for cand in d["candidates"]:
        partners = cand["fitted"]["partners"]
        if cand["effect"] == "wall_friction":
            check(partners is not None and sorted(partners) == sorted(PLATES)
                  and partners["galvanized_steel"] == cand["fitted"]["value"],
                  f"wall friction reports every wall's value at its fit ({partners})")
        elif cand["effect"] == "rolling_friction" and case["base"][0] is None:
            # Table 1's pill-pill and pill-wall values move together (pill-pill is the parameter).
            check(partners is not None and sorted(partners) == sorted(["pill"] + PLATES)
                  and partners["pill"] == cand["fitted"]["value"],
                  f"rolling friction reports every partner's value at its fit ({partners})")
        elif cand["effect"] in ("rolling_friction", "cohesion"):
            check(partners is None, f"{cand['effect']} has one value for every partner")
    check(d2["simulations"] == 0 and "0 rig runs simulated" in again,
          f"a second diagnose is served from the cache ({d2['simulations']} runs)")
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
