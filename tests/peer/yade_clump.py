#!/usr/bin/env python3
"""clumpkit's Yade export run in a real Yade (Debian's `yade`), against clumpkit's own figures.

Templates: the paper's nine pills (`clumpkit paper --out`) and an asymmetric clump (the bundled
rock, 10 spheres by the optimiser), each exported with `clumpkit export --format yade`. One Yade
run (`yade -n -x`) loads every exported file and checks, per template:

  * the file runs in this Yade (imports, TEMPLATE, helpers);
  * add_clump: one clump of len(RADII) member spheres, each at centre + POSITIONS[i] with radius
    RADII[i]; Yade's reference point (its centre of mass, from its grid integration of the union at
    DISCRETIZATION) within 0.02 of the smallest radius of the centre asked for, which is
    clumpkit's union centre of mass; mass and sorted principal moments exactly clumpkit's; the
    same with an orientation (each sphere at centre + q POSITIONS[i]);
  * independent of clumpkit's numbers: Yade's own grid integration of the union (appendClumped
    with discretization=40) gives the centre of mass within 0.005 r_min, the mass within 0.5 % and
    the sorted principal moments within 1 % of clumpkit's ray-sampled union values; Yade's sum
    over the spheres (discretization=0) exceeds the union's mass wherever the spheres overlap;
  * replaceByClumps with TEMPLATE on a sphere of radius R_REF: the clump's member radii within
    1.5 % of RADII (Yade sizes by its own coarse grid estimate of the template's volume; the
    ratio is reported); on a sphere of radius R_REPLACE, which replays that estimate, within
    1e-9; then set_union_mass gives clumpkit's mass;
  * free fall for 200 steps: the clump moves as one rigid body, its centre of mass falling as
    Yade's leapfrog predicts from rest (g dt^2 n (n + 1) / 2, 1e-9 relative), without turning (no
    contact, no torque).

Exit 0 when every check holds, 1 when one fails, 2 on a run error, 77 (skipped) when Yade is not
installed. Python 3 standard library only; writes WORK/result.json.
"""
import argparse
import glob
import json
import os
import shutil
import subprocess
import sys

# Runs inside Yade: O, utils, Vector3 and the engines are in its globals.
DRIVER = r'''
import json, sys
files = json.load(open(sys.argv[1]))
out = []
for path in files:
    O.reset()
    ns = dict(globals())
    exec(open(path).read(), ns)
    R, P, MASS, PM = ns["RADII"], ns["POSITIONS"], ns["MASS"], ns["PRINCIPAL_MOMENTS"]
    rmin = min(R)
    mat = O.materials.append(FrictMat(density=ns["DENSITY"], young=1e7, poisson=0.3,
                                      frictionAngle=0.5))
    r = {"file": path, "spheres": len(R), "mass": MASS, "moments": sorted(PM)}
    # add_clump at true size.
    c = Vector3(0.01, -0.02, 0.03)
    cid = ns["add_clump"](c, material=mat)
    b = O.bodies[cid]
    mids = sorted(b.shape.members.keys())
    r["members"] = len(mids)
    r["member_pos_err"] = max((O.bodies[m].state.pos - c - Vector3(*p)).norm()
                              for m, p in zip(mids, P)) / rmin
    r["member_radius_err"] = max(abs(O.bodies[m].shape.radius - q) / q for m, q in zip(mids, R))
    r["com_offset"] = (b.state.pos - c).norm() / rmin
    r["add_mass"] = b.state.mass
    r["add_moments"] = sorted(b.state.inertia[k] for k in range(3))
    # Turned: each sphere at centre + q p, the same union mass and moments.
    q = Quaternion(Vector3(0.3, -0.5, 0.8).normalized(), 1.1)
    c2 = Vector3(0.05, 0.0, 0.03)
    cid2 = ns["add_clump"](c2, material=mat, orientation=q)
    b2 = O.bodies[cid2]
    m2 = sorted(b2.shape.members.keys())
    r["turned_pos_err"] = max((O.bodies[m].state.pos - c2 - q * Vector3(*p)).norm()
                              for m, p in zip(m2, P)) / rmin
    r["turned_com_offset"] = (b2.state.pos - c2).norm() / rmin
    r["turned_moments"] = sorted(b2.state.inertia[k] for k in range(3))
    O.bodies.erase(cid2, True)
    # Free fall: no contact, so no torque.
    O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb()]),
                 InteractionLoop([Ig2_Sphere_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()],
                                 [Law2_ScGeom_FrictPhys_CundallStrack()]),
                 NewtonIntegrator(gravity=(0, 0, -9.81), damping=0.0)]
    O.dt = 1e-5
    z0, q0 = b.state.pos[2], b.state.ori
    O.run(200, True)
    # Yade's leapfrog from rest: v = k g dt after k steps, so n steps fall g dt^2 n (n + 1) / 2.
    n = round(O.time / O.dt)
    r["fall"] = z0 - b.state.pos[2]
    r["fall_expected"] = 0.5 * 9.81 * O.dt * O.dt * n * (n + 1)
    r["turn"] = b.state.ori.angularDistance(q0)
    # Yade's own estimates of the union: grid (discretization 40) and the sum over spheres.
    O.reset()
    mat = O.materials.append(FrictMat(density=ns["DENSITY"], young=1e7, poisson=0.3,
                                      frictionAngle=0.5))
    for disc, key in ((40, "grid"), (0, "sum")):
        cid, _ = O.bodies.appendClumped(
            [utils.sphere(c + Vector3(*p), q, material=mat) for p, q in zip(P, R)],
            discretization=disc)
        s = O.bodies[cid].state
        r[key + "_mass"] = s.mass
        r[key + "_moments"] = sorted(s.inertia[k] for k in range(3))
        r[key + "_com_offset"] = (s.pos - c).norm() / rmin
        O.bodies.erase(cid, True)
    # replaceByClumps with TEMPLATE on a sphere of radius R_REF.
    O.reset()
    mat = O.materials.append(FrictMat(density=ns["DENSITY"], young=1e7, poisson=0.3,
                                      frictionAngle=0.5))
    for key in ("R_REF", "R_REPLACE"):
        O.bodies.clear()
        O.bodies.append(utils.sphere(c, ns[key], material=mat))
        (cid, mids), = O.bodies.replaceByClumps([ns["TEMPLATE"]], [1.0],
                                                discretization=ns["DISCRETIZATION"])
        ratios = sorted(x / q for x, q in zip(sorted(O.bodies[m].shape.radius for m in mids),
                                               sorted(R)))
        r[key + "_size_ratio"] = sum(ratios) / len(ratios)
        r[key + "_ratio_spread"] = ratios[-1] - ratios[0]
        ns["set_union_mass"](cid)
        r[key + "_mass"] = O.bodies[cid].state.mass
    out.append(r)
json.dump(out, open(sys.argv[2], "w"), indent=1)
'''


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--clumpkit", required=True)
    ap.add_argument("--work", required=True, help="scratch folder (emptied first)")
    ap.add_argument("--yade", default="yade")
    a = ap.parse_args()
    if shutil.which(a.yade) is None:
        print(f"SKIP: {a.yade} not found (Debian: apt-get install yade)")
        return 77
    shutil.rmtree(a.work, ignore_errors=True)
    os.makedirs(a.work)
    w = lambda *p: os.path.join(a.work, *p)

    def run(*cmd):
        p = subprocess.run(list(cmd), cwd=a.work, stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, text=True)
        if p.returncode != 0:
            print("$ " + " ".join(cmd) + "\n" + p.stdout + f"\nFAIL: exit status {p.returncode}")
            sys.exit(2)
        return p.stdout

    ck = os.path.abspath(a.clumpkit)
    run(ck, "paper", "--out", w("templates"))
    run(ck, "mesh", "rock", "-o", w("rock.stl"))
    run(ck, "fill", w("rock.stl"), "--method", "optimal", "--spheres", "10", "-o",
        w("templates", "rock_optimal_10.json"))
    files = []
    for t in sorted(glob.glob(w("templates", "*.json"))):
        run(ck, "export", t, "--format", "yade", "-o", w("yade"))
        files.append(w("yade", os.path.basename(t)[:-5] + "_yade.py"))
    with open(w("files.json"), "w") as f:
        json.dump(files, f)
    with open(w("driver.py"), "w") as f:
        f.write(DRIVER)
    # yade -x runs the script and exits; its argv follows the script name.
    p = subprocess.run([a.yade, "-n", "-x", w("driver.py"), w("files.json"), w("result.json")],
                       cwd=a.work, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       timeout=600)
    if p.returncode != 0 or not os.path.exists(w("result.json")):
        print(p.stdout + f"\nFAIL: yade exit status {p.returncode}")
        return 2
    with open(w("result.json")) as f:
        res = json.load(f)

    failures = []

    def check(ok, what):
        if not ok:
            failures.append(what)
            print("FAIL " + what)

    rel = lambda x, y: abs(x - y) / abs(y)
    print("Yade against clumpkit's union: centre-of-mass offsets in smallest radii (add_clump,\n"
          "Yade's grid at 40, Yade's sum over spheres), grid mass and largest moment error, the\n"
          "sum's mass, replaceByClumps's size (ratio; R_REPLACE: minus 1) on a sphere of R_REF\n"
          "and of R_REPLACE")
    print(f"{'template':<24} {'n':>3} {'add COM':>8} {'grid COM':>8} {'sum COM':>8} "
          f"{'grid mass':>10} {'grid I':>7} {'sum mass':>9} {'R_REF':>8} {'R_REPLACE':>9}")
    for r in res:
        name = os.path.basename(r["file"])[:-8]
        grid_i = max(rel(x, y) for x, y in zip(r["grid_moments"], r["moments"]))
        print(f"{name:<24} {r['spheres']:>3} {r['com_offset']:>8.4f} {r['grid_com_offset']:>8.4f} "
              f"{r['sum_com_offset']:>8.4f} "
              f"{r['grid_mass'] / r['mass'] - 1:>+10.3%} {grid_i:>7.2%} "
              f"{r['sum_mass'] / r['mass']:>8.3f}x {r['R_REF_size_ratio']:>8.4f} "
              f"{r['R_REPLACE_size_ratio'] - 1:>+9.1e}")
        check(r["members"] == r["spheres"],
              f"{name}: {r['members']} members, {r['spheres']} spheres")
        check(r["member_pos_err"] < 1e-9, f"{name}: member positions off by "
              f"{r['member_pos_err']:.2e} r_min")
        check(r["member_radius_err"] < 1e-12,
              f"{name}: member radii off by {r['member_radius_err']:.2e}")
        check(r["com_offset"] < 0.02, f"{name}: add_clump's reference point {r['com_offset']:.4f} "
              "r_min from clumpkit's centre of mass")
        check(r["grid_com_offset"] < 0.005, f"{name}: Yade's grid centre of mass "
              f"{r['grid_com_offset']:.4f} r_min from clumpkit's")
        check(rel(r["add_mass"], r["mass"]) < 1e-12, f"{name}: add_clump mass {r['add_mass']}")
        check(r["turned_pos_err"] < 1e-9 and r["turned_com_offset"] < 0.02 and
              max(rel(x, y) for x, y in zip(r["turned_moments"], r["moments"])) < 1e-12,
              f"{name}: add_clump with an orientation: spheres off by {r['turned_pos_err']:.2e}, "
              f"centre {r['turned_com_offset']:.4f} r_min, moments {r['turned_moments']}")
        check(max(rel(x, y) for x, y in zip(r["add_moments"], r["moments"])) < 1e-12,
              f"{name}: add_clump moments {r['add_moments']} against {r['moments']}")
        check(rel(r["grid_mass"], r["mass"]) < 0.005, f"{name}: Yade's grid mass "
              f"{r['grid_mass']:.6g} against clumpkit's {r['mass']:.6g} kg")
        check(grid_i < 0.01, f"{name}: Yade's grid moments {r['grid_moments']} against "
              f"{r['moments']}")
        if r["spheres"] > 1:
            check(r["sum_mass"] > 1.01 * r["mass"], f"{name}: the sum over overlapping spheres "
                  f"({r['sum_mass']:.6g} kg) should exceed the union's")
        check(abs(r["R_REF_size_ratio"] - 1) < 0.015 and r["R_REF_ratio_spread"] < 1e-9,
              f"{name}: replaceByClumps on R_REF: size ratio {r['R_REF_size_ratio']:.4f}")
        check(abs(r["R_REPLACE_size_ratio"] - 1) < 1e-9 and r["R_REPLACE_ratio_spread"] < 1e-9,
              f"{name}: replaceByClumps on R_REPLACE: size ratio "
              f"{r['R_REPLACE_size_ratio']:.12f}, not 1 (Yade's volume estimate not replayed)")
        check(rel(r["R_REPLACE_mass"], r["mass"]) < 1e-12, f"{name}: set_union_mass after "
              f"replaceByClumps gave {r['R_REPLACE_mass']}")
        check(rel(r["fall"], r["fall_expected"]) < 1e-9, f"{name}: free fall {r['fall']:.9g} m "
              f"against {r['fall_expected']:.9g}")
        check(r["turn"] < 1e-9, f"{name}: turned {r['turn']:.2e} rad in free fall")
    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    print(f"all checks passed ({len(res)} templates)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
