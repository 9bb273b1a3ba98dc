#!/usr/bin/env python3
"""The rigs on LIGGGHTS against the bundled runner (`clumpkit rig ... --engine liggghts`).

For the bulk density, the angle of repose and the discharger, the same command runs with both
engines: the same model (the production model with the CDT rolling model, which both codes
have), scale, seeds and repeats. clumpkit writes the rig as a LIGGGHTS deck, runs it (the
bulk density under `mpirun -np N` with --np N > 1, the others on one rank) and measures the
result with the same code as its own runs (the cup weighed by clump centres; the heap's
silhouette fit; the pockets weighed as they close). Checked:

  * each LIGGGHTS repeat ran there: engine "liggghts", the MPI ranks asked, the deck kept,
    pills in the cup / on the plate / in the rig, and only the expected difference noted (no
    implicit damping in LIGGGHTS); every counted pocket carried pills and the discharged mass
    grows;
  * the calibration commands reach LIGGGHTS too: the --compare-rig (the bulk density) runs on
    LIGGGHTS through `clumpkit compare --engine liggghts --np N` (the rig run the compare caches
    is the LIGGGHTS side of the comparison), its simulated value is the cached run's, and a second
    compare is served from the cache;
  * the means of the two engines agree: |difference| <= max(K x combined standard error,
    floor), the floor a stated fraction of the mean (the seed-to-seed scatter of a tiny rig,
    measured: docs/rigs.md).

Exit status: 0 when all agree, 1 when not, 2 on a run error, 77 when LIGGGHTS (or mpirun for
--np > 1) is not installed (ctest SKIP_RETURN_CODE). Python 3 standard library only.
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import time

SKIP = 77
# rig -> (quantity, unit factor for printing, floor of the tolerance as a fraction of the mean)
RIGS = {
    "bulk_density": ("bulk_density", 1.0, "kg/m^3", 0.05),
    "angle_of_repose": ("angle", 180.0 / math.pi, "deg", 0.15),
    # tiny's three counted pockets at 30 rpm (its pocket fills scatter ~10 % from seed to seed;
    # with two pockets the run ends before the first pocket has emptied).
    "discharge": ("pocket_mass", 1.0, "kg", 0.25),
}
# Per rig: extra settings.
EXTRA = {"discharge": ["--set", "rpm=30"]}


def log(msg):
    print(msg, flush=True)


def run(cmd, out):
    log("$ " + " ".join(cmd))
    t0 = time.time()
    # CTest runs another test beside this one on the 2 cores: OpenMPI's ranks then yield their
    # core while they wait instead of spinning (one LIGGGHTS repeat took 223 s instead of 46 s).
    env = dict(os.environ, OMPI_MCA_mpi_yield_when_idle="1")
    with open(out, "w") as f:
        p = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT, env=env)
    if p.returncode != 0:
        with open(out) as f:
            tail = f.read()[-3000:]
        raise RuntimeError("%s exited with %d:\n%s" % (cmd[0], p.returncode, tail))
    return time.time() - t0


def model_file(work):
    """The production model with the CDT rolling model, as a file (`compare` takes no --set)."""
    shapes = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shapes")
    with open(os.path.join(shapes, "models", "production.toml")) as f:
        text = f.read()
    text = text.replace('"../', '"%s/' % os.path.abspath(shapes))
    text = text.replace('name = "production"', 'name = "production_cdt"')
    path = os.path.join(work, "production_cdt.toml")
    with open(path, "w") as f:
        f.write(text + '\n[effects.rolling_model]\nmodel = "cdt"\n')
    return path


def liggghts_through_compare(a, rig, quantity, np, work):
    """The LIGGGHTS side of `rig` made by `clumpkit compare --engine liggghts`: returns the rig
    result the compare cached, and the checks on the compare itself."""
    cache = os.path.join(work, "compare_cache")
    lab = os.path.join(work, "lab_%s.csv" % rig)
    with open(lab, "w") as f:
        f.write("rig,sample,setting,quantity,value,std,n,unit\n")
        f.write({"bulk_density": "bulk_density,mix,,bulk_density,730,10,3,kg/m^3\n",
                 "angle_of_repose": "angle_of_repose,mix,,angle,25,1,3,deg\n",
                 # the speed of EXTRA's --set rpm=30
                 "discharge": "discharge,mix,rpm=30,pocket_mass,0.17,0.01,3,kg\n"}[rig])
    cmd = [a.clumpkit, "compare", "--model", model_file(work), "--measurements", lab,
           "--engine", "liggghts", "--np", str(np), "--scale", a.scale, "--repeats",
           str(a.repeats), "--seed", str(a.seed), "--cache", cache]
    cmp_json = os.path.join(work, "compare_%s.json" % rig)
    t = run(cmd + ["--json", cmp_json], os.path.join(work, "liggghts_%s.log" % rig))
    again = os.path.join(work, "compare_again_%s.log" % rig)
    run(cmd + ["--quiet"], again)
    cached = [f for f in os.listdir(cache) if f.startswith(rig + "_") and f.endswith(".json")]
    if len(cached) != 1:
        raise RuntimeError("expected one cached %s run in %s, found %s" % (rig, cache, cached))
    with open(os.path.join(cache, cached[0])) as f:
        entry = json.load(f)
    with open(cmp_json) as f:
        cmp = json.load(f)
    with open(again) as f:
        again_text = f.read()
    result = entry["result"]
    mean = result["quantities"][quantity]["mean"]  # the quantity's unit, as compare's
    simulated = cmp["observables"][0]["simulated"]
    checks = {
        "compare reports engine liggghts on %d rank(s)" % np:
            cmp.get("engine") == "liggghts" and cmp.get("mpi_ranks") == np,
        "compare's simulated value is the cached LIGGGHTS run's (%.10g)" % simulated:
            abs(simulated - mean) <= 1e-9 * abs(simulated),
        "the cached run has the seeds asked": [r["seed"] for r in result["repeats"]]
            == list(range(a.seed, a.seed + a.repeats)),
        "a second compare simulates nothing": "0 rig runs simulated, 1 served" in again_text,
    }
    return result, checks, t


def values(result, quantity):
    return [r["values"][quantity] for r in result["repeats"]]


def mean_sd(xs):
    m = sum(xs) / len(xs)
    sd = math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1)) if len(xs) > 1 else 0.0
    return m, sd


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clumpkit", required=True)
    ap.add_argument("--work", required=True, help="scratch folder (emptied)")
    ap.add_argument("--scale", default="tiny")
    ap.add_argument("--repeats", type=int, default=1,
                    help="seeds per rig and engine (1: the tolerance is the floor alone)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--np", type=int, default=2,
                    help="LIGGGHTS MPI ranks of the --mpi-rig run (the others run on one)")
    ap.add_argument("--mpi-rig", default="bulk_density",
                    help="the rig run on --np ranks (at tiny, two ranks only cost CPU)")
    ap.add_argument("--rigs", default="bulk_density,angle_of_repose,discharge")
    ap.add_argument("--compare-rig", default="bulk_density",
                    help="the rig whose LIGGGHTS side runs through `clumpkit compare` ('' none)")
    ap.add_argument("--k", type=float, default=3.0, help="tolerance in combined standard errors")
    ap.add_argument("--json", help="write the comparison here")
    a = ap.parse_args()

    if not shutil.which("liggghts"):
        log("SKIP: liggghts is not installed (apt-get install liggghts)")
        return SKIP
    if a.np > 1 and not shutil.which("mpirun"):
        log("SKIP: mpirun is not installed (apt-get install openmpi-bin)")
        return SKIP
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)

    report, ok = [], True
    for rig in a.rigs.split(","):
        quantity, factor, unit, floor = RIGS[rig]
        common = ["--scale", a.scale, "--repeats", str(a.repeats), "--seed", str(a.seed),
                  "--set", "effects.rolling_model=cdt"] + EXTRA.get(rig, [])
        ck_json = os.path.join(a.work, "clumpkit_%s.json" % rig)
        lg_json = os.path.join(a.work, "liggghts_%s.json" % rig)
        lg_out = os.path.join(a.work, "liggghts_%s" % rig)
        try:
            t_ck = run([a.clumpkit, "rig", rig, "--threads", "1", "--json", ck_json] + common,
                       os.path.join(a.work, "clumpkit_%s.log" % rig))
            np = a.np if rig == a.mpi_rig else 1
            compare_checks = {}
            if rig == a.compare_rig:
                lg, compare_checks, t_lg = liggghts_through_compare(a, rig, quantity, np, a.work)
            else:
                t_lg = run([a.clumpkit, "rig", rig, "--engine", "liggghts", "--np", str(np),
                            "--out", lg_out, "--json", lg_json] + common,
                           os.path.join(a.work, "liggghts_%s.log" % rig))
                lg = json.load(open(lg_json))
        except RuntimeError as e:
            log("ERROR: %s" % e)
            return 2
        ck = json.load(open(ck_json))
        for name, passed in compare_checks.items():
            log(("ok   " if passed else "FAIL ") + "%s compare: %s" % (rig, name))
            ok = ok and passed
        for k, rep in enumerate(lg["repeats"]):
            d = rep["details"]
            checks = {
                "engine is liggghts": d.get("engine") == "liggghts",
                "ran on %d MPI ranks" % np: d.get("mpi_ranks") == np,
                "deck kept": os.path.isfile(d.get("deck", "")),
                "pills measured": d.get("pills", 0) > 0,
                "only the implicit damping noted": len(d.get("differences", [])) == 1
                and "implicit damping" in d["differences"][0],
            }
            if rig == "discharge":
                fills = d.get("pocket_fills_slice_kg", [])
                curve = d.get("curve_mass_kg", [])
                checks["every counted pocket carried pills"] = bool(fills) and min(fills) > 0
                checks["the discharged mass grows and ends above 0"] = (
                    len(curve) > 2 and all(b >= a - 1e-12 for a, b in zip(curve, curve[1:]))
                    and curve[-1] > 0)
            for name, passed in checks.items():
                if not passed:
                    ok = False
                    log("FAIL: %s repeat %d: %s (details: %s)" % (rig, k + 1, name,
                                                                   json.dumps(d)[:800]))
        x_ck, x_lg = values(ck, quantity), values(lg, quantity)
        m_ck, s_ck = mean_sd(x_ck)
        m_lg, s_lg = mean_sd(x_lg)
        se = math.sqrt(s_ck ** 2 / len(x_ck) + s_lg ** 2 / len(x_lg))
        tol = max(a.k * se, floor * abs(m_ck))
        diff = m_lg - m_ck
        passed = abs(diff) <= tol
        ok = ok and passed
        line = ("%-16s clumpkit %9.4g +/- %-8.3g LIGGGHTS %9.4g +/- %-8.3g %s  diff %+.3g "
                "(tolerance %.3g) %s; wall %.0f s / %.0f s"
                % (rig, m_ck * factor, s_ck * factor, m_lg * factor, s_lg * factor, unit,
                   diff * factor, tol * factor, "ok" if passed else "FAIL", t_ck, t_lg))
        log(line)
        report.append(dict(rig=rig, quantity=quantity, unit=unit,
                           clumpkit=[x * factor for x in x_ck], liggghts=[x * factor for x in x_lg],
                           difference=diff * factor, tolerance=tol * factor, passed=passed,
                           clumpkit_wall_s=t_ck, liggghts_wall_s=t_lg))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(dict(settings=vars(a), rigs=report), f, indent=1)
    log("PASS" if ok else "FAIL")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
