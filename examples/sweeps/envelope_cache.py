"""A cache of working envelopes over a velocity grid, against on-line envelopes.

The paper precomputed working envelopes (WE) for particle velocities −80…80 nm/µs on a
31 × 31 grid (step 5.33 nm/µs, Δt = 0.2 µs): 961 envelopes, 20 hours on a 4-CPU SGI Onyx,
28 MB. Here, for Δt = 0.2 µs (the paper's cache) and Δt = 1 µs (the paper's haptic tick),
every envelope of the finest grid (33 × 33, step 5 nm/µs) is one run of a sweep;
each is stored as its radial function r(θ) about the free-drift point v·Δt (which the
envelope contains: a far trap pulls with zero force) at 256 angles. Coarser caches are
sub-grids of it (17², 9², 5², 3²). An envelope at any velocity is the bilinear interpolation
of r(θ) between the four cached neighbours; its error is measured against the envelope
computed on line at 200 random velocities (seeded: run_seed of the sweep), as the largest
difference of r(θ) over the angles, in nm and relative to the envelope's size.

    python examples/sweeps/envelope_cache.py [--workers N | --dask local:2 | --dask tcp://HOST:8786]
                                             [--size short|docs|large] [--chunksize N]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import nanohaptics as nh

sys.path.insert(0, str(Path(__file__).resolve().parent))
import common  # noqa: E402

DTS_S = [0.2e-6, 1e-6]
V_MAX_M_PER_S = 0.08  # 80 nm/µs
FINE = 33  # points per axis of the finest cache; 2^k + 1 so that coarser ones nest
ANGLES = 256
TESTS = 200
THETA = np.linspace(0.0, 2 * np.pi, ANGLES, endpoint=False)
# size → (points per axis of the finest cache, Δt's, test velocities per Δt). docs: the table
# of docs/sweeps.md (2578 runs); large: a 129 × 129 cache (step 1.25 nm/µs, 17× the paper's
# 961 envelopes per Δt) at Δt = 0.2, 0.5 and 1 µs, tested at 400 velocities each: 51 123
# runs of ~0.7 ms, ≥ 30 s on one core — the study whose runs are too short to send one a task.
SIZES = {
    "short": (5, [1e-6], 4),
    "docs": (FINE, DTS_S, TESTS),
    "large": (129, [0.2e-6, 0.5e-6, 1e-6], 400),
}


def radial(poly: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """Distance (m) from ``centre`` to the polygon boundary along each angle of THETA (the
    farthest crossing, so a ray that grazes a fold still sees the outer boundary):
    :func:`nanohaptics.polygon_radius`, which releases the GIL (the numpy version of this
    held it for twice as long as the envelope took, and serialised the threads)."""
    return nh.polygon_radius(poly, centre, THETA)


def envelope_run(run: dict, seed: int) -> dict:
    """One run: the working envelope at velocity (vx, vy), m/s, over dt_s, as r(θ) about v·Δt
    (the envelope's geometric tolerance is working_envelope's default, 0.5 nm)."""
    trap = nh.paper_trap()
    v = np.array([run["vx_m_per_s"], run["vy_m_per_s"]])
    poly = nh.working_envelope(trap, tuple(v), run["dt_s"])
    r = radial(poly, v * run["dt_s"])
    return {"vertices": int(len(poly)), "polygon_bytes": int(poly.nbytes), "r_max_m": float(r.max()), "r_m": r}


def runs(seed: int = 0, size: str = "docs") -> list:
    fine, dts, n_tests = SIZES[common.check_size(size)]
    axis = np.linspace(-V_MAX_M_PER_S, V_MAX_M_PER_S, fine)
    rng = np.random.default_rng(nh.run_seed(seed, 2**32))  # the test velocities, seeded
    tests = rng.uniform(-V_MAX_M_PER_S, V_MAX_M_PER_S, size=(n_tests, 2))
    out = []
    for dt in dts:
        grid = nh.grid({"dt_s": [dt], "vx_m_per_s": axis.tolist(), "vy_m_per_s": axis.tolist()})
        out += [{**g, "role": "cache"} for g in grid]
        out += [{"dt_s": dt, "vx_m_per_s": float(x), "vy_m_per_s": float(y), "role": "test"} for x, y in tests]
    return out


def study(executor=None, workers=None, progress=True, size="docs", chunksize=None):
    return nh.sweep(envelope_run, runs(size=size), arrays=True, executor=executor, workers=workers,
                    progress=progress, chunksize=chunksize)


def cache_of(df, dt):
    """The finest cache r(θ) at Δt = dt as a (fine, fine, ANGLES) array (vx, vy, θ)."""
    cache = df[(df["role"] == "cache") & (df["dt_s"] == dt)]
    fine = int(round(len(cache) ** 0.5))
    return np.stack(cache["arrays"].map(lambda a: a["r_m"]).to_list()).reshape(fine, fine, ANGLES)


def interpolate(r_fine, every, v):
    """Bilinear interpolation of r(θ) at velocity v from every `every`-th cached velocity."""
    ax = np.linspace(-V_MAX_M_PER_S, V_MAX_M_PER_S, r_fine.shape[0])[::every]
    r = r_fine[::every, ::every]
    n = len(ax)
    i = min(int(np.searchsorted(ax, v[0], side="right")) - 1, n - 2)
    j = min(int(np.searchsorted(ax, v[1], side="right")) - 1, n - 2)
    tx = (v[0] - ax[i]) / (ax[i + 1] - ax[i])
    ty = (v[1] - ax[j]) / (ax[j + 1] - ax[j])
    return ((1 - tx) * (1 - ty) * r[i, j] + tx * (1 - ty) * r[i + 1, j]
            + (1 - tx) * ty * r[i, j + 1] + tx * ty * r[i + 1, j + 1])


def tests_of(df, dt):
    return df[(df["role"] == "test") & (df["dt_s"] == dt)]


def interpolation_errors(df, dt) -> list:
    """Per cache size at Δt = dt: (points per axis, step nm/µs, cache bytes, median and max
    error nm, median and max error relative to the envelope size)."""
    tests = df[(df["role"] == "test") & (df["dt_s"] == dt)]
    r_fine = cache_of(df, dt)
    fine = r_fine.shape[0]
    out = []
    for every in [2**k for k in range(int(np.log2(fine - 1)) - 1, -1, -1)]:  # 3² … fine² velocities
        n = (fine - 1) // every + 1
        errs, rels = [], []
        for vx, vy, a in zip(tests["vx_m_per_s"], tests["vy_m_per_s"], tests["arrays"]):
            ri = interpolate(r_fine, every, (vx, vy))
            e = np.abs(ri - a["r_m"]).max()
            errs.append(e)
            rels.append(e / a["r_m"].max())
        errs, rels = np.array(errs), np.array(rels)
        out.append((n, 2 * V_MAX_M_PER_S / (n - 1) * 1e3, n * n * ANGLES * 8,
                    np.median(errs) * 1e9, errs.max() * 1e9, np.median(rels), rels.max()))
    return out


def figure(df, tables, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 4.8), constrained_layout=True)
    for (dt, rows), colour in zip(tables.items(), ("tab:blue", "tab:green", "tab:red")):
        kb = np.array([r[2] for r in rows]) / 1024
        a1.loglog(kb, [r[4] for r in rows], "o-", color=colour, label=f"Δt = {dt * 1e6:g} µs, largest")
        a1.loglog(kb, [r[3] for r in rows], "s--", color=colour, label=f"Δt = {dt * 1e6:g} µs, median")
    rows = next(iter(tables.values()))
    for r in rows:
        a1.annotate(f"{r[0]}²", (r[2] / 1024, a1.get_ylim()[0]), textcoords="offset points",
                    xytext=(0, 4), ha="center", fontsize=8)
    a1.set_xlabel(f"cache size, KiB (r(θ) at 256 angles, float64; 3² … {rows[-1][0]}² velocities)")
    a1.set_ylabel("interpolated vs on-line envelope, max |Δr|, nm")
    a1.set_title(f"Bilinear interpolation error at {len(tests_of(df, next(iter(tables))))} random velocities")
    a1.grid(True, which="both", alpha=0.3)
    a1.legend(fontsize=8)
    dt = list(tables)[-1]
    tests = tests_of(df, dt)
    k = int(np.argmax(np.hypot(tests["vx_m_per_s"], tests["vy_m_per_s"])))
    row = tests.iloc[k]
    v = np.array([row["vx_m_per_s"], row["vy_m_per_s"]])
    r_fine = cache_of(df, dt)
    fine = r_fine.shape[0]
    for every, style in (((fine - 1) // 2, "r-"), (max(1, (fine - 1) // 8), "b-"), (1, "g-")):
        ri = interpolate(r_fine, every, v)
        a2.plot(np.degrees(THETA), (ri - row["arrays"]["r_m"]) * 1e9, style, lw=1,
                label=f"from the {(fine - 1) // every + 1}² cache")
    a2.axhline(0, color="k", lw=0.6)
    a2.set_xlabel("angle θ about the free drift v·Δt, degrees")
    a2.set_ylabel("r(θ) interpolated − on line, nm")
    a2.set_title(f"Δt = {dt * 1e6:g} µs, v = ({v[0] * 1e3:.1f}, {v[1] * 1e3:.1f}) nm/µs "
                 f"(envelope r up to {row['r_max_m'] * 1e9:.0f} nm)")
    a2.legend(fontsize=8)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)


def main() -> None:
    args = common.parser(__doc__).parse_args()
    with common.executor(args.dask, __name__) as ex:
        df = study(ex, args.workers, not args.no_progress, args.size, args.chunksize)
    tables = {dt: interpolation_errors(df, dt) for dt in SIZES[args.size][1]}
    figure(df, tables, args.out / ("envelope-cache.png" if args.size == "docs" else f"envelope-cache-{args.size}.png"))
    for dt, rows in tables.items():
        cache = df[(df["role"] == "cache") & (df["dt_s"] == dt)]
        print(f"Δt = {dt * 1e6:g} µs: {len(cache)} envelopes, {cache['vertices'].sum()} vertices, "
              f"{cache['polygon_bytes'].sum() / 1e6:.2f} MB as polygons, "
              f"{len(cache) * ANGLES * 8 / 1e6:.2f} MB as r(θ) at {ANGLES} angles")
        print("| velocities | step, nm/µs | cache, KiB | median error, nm | largest error, nm | median relative | largest relative |")
        print("|---|---|---|---|---|---|---|")
        for n, step, b, med, mx, rmed, rmx in rows:
            print(f"| {n}² | {step:.2f} | {b / 1024:.1f} | {med:.3f} | {mx:.3f} | {rmed:.1e} | {rmx:.1e} |")
    print(f"{len(df)} runs in {df.attrs['wall_s']:.2f} s ({len(df) / df.attrs['wall_s']:.1f} runs/s)")


if __name__ == "__main__":
    main()
