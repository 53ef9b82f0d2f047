#!/usr/bin/env python3
"""scipy's solve_ivp (DOP853) on the optical-tweezers paper problem.

Driven by `cargo run --release -p ot-physics --example bench_report`, which
writes the start states to a JSON file and reads back the displacements and
the CPU time per trajectory. Units inside: nm and µs (scalar tolerances are
meaningful there), the same scaling the compiled peer gets.

usage: scipy_peer.py IN.json OUT.json
IN:  {"depth": J, "waists": [m, m], "mass": kg, "dt": s,
      "starts": [[ox, oy, vx, vy], ...] (m, m/s), "tols": [..]}
OUT: {"scipy": version, "rows": [{"tol": t, "ns_per_traj": ns,
      "evals_per_traj": n, "displacements": [[dx, dy] (m), ...]}, ...]}
"""
import json
import math
import sys
import time

import numpy as np
import scipy
from scipy.integrate import solve_ivp


def main() -> None:
    src, dst = sys.argv[1], sys.argv[2]
    with open(src) as f:
        cfg = json.load(f)
    nm, us = 1e-9, 1e-6
    kx = math.log(2) / (cfg["waists"][0] / nm) ** 2
    ky = math.log(2) / (cfg["waists"][1] / nm) ** 2
    c = 2 * cfg["depth"] / cfg["mass"] * (us / nm) ** 2
    t_end = cfg["dt"] / us

    def rhs(_t, y):
        e = math.exp(-(kx * y[0] * y[0] + ky * y[1] * y[1]))
        return [y[2], y[3], -c * kx * y[0] * e, -c * ky * y[1] * e]

    rows = []
    for tol in cfg["tols"]:
        disp, evals = [], 0
        t0 = time.process_time()
        for ox, oy, vx, vy in cfg["starts"]:
            y0 = [-ox / nm, -oy / nm, vx * us / nm, vy * us / nm]
            sol = solve_ivp(rhs, (0.0, t_end), y0, method="DOP853", rtol=tol, atol=tol)
            evals += sol.nfev
            disp.append([(sol.y[0, -1] - y0[0]) * nm, (sol.y[1, -1] - y0[1]) * nm])
        elapsed = time.process_time() - t0
        n = len(cfg["starts"])
        rows.append(
            {
                "tol": tol,
                "ns_per_traj": elapsed * 1e9 / n,
                "evals_per_traj": evals / n,
                "displacements": disp,
            }
        )
    with open(dst, "w") as f:
        json.dump({"scipy": scipy.__version__, "numpy": np.__version__, "rows": rows}, f)


if __name__ == "__main__":
    main()
