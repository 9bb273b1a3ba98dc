#!/usr/bin/env python3
"""Stability of the engine's damping integration for a pure dashpot (docs/dem.md, implicit damping).

A mass on a linear dashpot, x = Γ dt, velocity Verlet as in lib/src/dem/step.cpp: the damping
force of a step uses the extrapolated velocity u = v(t - dt/2) + dt/2 · F_prev/m (tangential
dashpots), or the telescoped normal impulse Φ(δ(t + dt/2)) - Φ(δ(t - dt/2)) whose upper end is
predicted with u. The implicit filter of a clump above the gate divides the step's velocity
change by 1 + w x. Prints |v| after 600 steps from v = 1: tiny = stable, large = unstable.

    python3 bench/damping_schemes.py
"""


def run(x, scheme, w, steps=600):
    v, f, u_prev = 1.0, 0.0, 1.0
    for _ in range(steps):
        u = v + 0.5 * f  # extrapolated velocity at the step's time
        if scheme == "half-step":
            g = -x * v
        elif scheme == "extrapolated":
            g = -x * u
        else:  # telescoped: -x (v(t - dt/2) + (u_k - u_{k-1}) / 2)
            g = -x * (v + 0.5 * (u - u_prev))
        u_prev = u
        f = g / (1.0 + w(x) * x)
        v += f
    return abs(v)


FILTERS = {
    "explicit": lambda x: 0.0,
    "w=1": lambda x: 1.0,
    "w=1+x/(1+x)": lambda x: 1.0 + x / (1.0 + x),
}

if __name__ == "__main__":
    xs = [0.3, 0.6, 0.7, 1.0, 1.5, 2.0, 5.0, 20.0, 100.0]
    print("x = Gamma dt; |v| after 600 steps (< 1 decays, > 1 grows)")
    for scheme in ["half-step", "extrapolated", "telescoped"]:
        for name, w in FILTERS.items():
            if scheme == "half-step" and name != "explicit":
                continue
            cells = []
            for x in xs:
                try:
                    cells.append(f"{run(x, scheme, w):9.2g}")
                except OverflowError:
                    cells.append("      inf")
            print(f"{scheme:13s} {name:12s} " + " ".join(cells))
    print("x:" + " " * 25 + " ".join(f"{x:9g}" for x in xs))
