"""Power-spectrum calibration of a trap across sampling rates (the aliasing, quantified).

A 1 µm bead (radius 0.5 µm, water at 293.15 K, γ = 6πηr) in a trap of stiffness κ = 1e-4 N/m
(0.1 pN/nm, corner frequency fc = κ/(2πγ) ≈ 1.69 kHz) is sampled at rates from 2 kHz to
100 kHz, 2 s each, with 8 seeds per rate (run_seed of the sweep: every run its own thermal
stream). Each trace is calibrated as pylake does it — a blocked periodogram, a fit of the
corner frequency, κ = 2πγ·fc — three ways: with the continuous Lorentzian D/(π²(fc² + f²)),
which ignores that instantaneous samples alias, fitted up to the Nyquist frequency fs/2 and up
to fs/4 (keeping away from where aliasing folds the most power back), and with the exact aliased spectrum of a sampled
Ornstein–Uhlenbeck process σ²Δt / (1 + c² − 2c·cos 2πfΔt), c = exp(−2π fc Δt)
(Berg-Sørensen & Flyvbjerg 2004). Both fits are weighted least-squares lines through 1/S, the
same as ot-physics' ``analysis::fit_corner_lorentzian`` / ``fit_corner_aliased``.

    python examples/sweeps/calibration.py [--workers N | --dask local:2 | --dask tcp://HOST:8786]
                                          [--size short|docs|large] [--chunksize N]
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

import nanohaptics as nh

sys.path.insert(0, str(Path(__file__).resolve().parent))
import common  # noqa: E402

KAPPA_N_PER_M = 1e-4
WAIST_M = 1e-6
RADIUS_M = 0.5e-6
VISCOSITY_PA_S = 1.002e-3
TEMPERATURE_K = 293.15
DURATION_S = 2.0
RATES_HZ = [2_000.0, 3_000.0, 5_000.0, 10_000.0, 20_000.0, 50_000.0, 100_000.0]
SEEDS = 8
# size → (rates, seeds per rate). docs: the table of docs/sweeps.md (56 runs); large: 160
# seeds per rate (1120 runs, ≥ 30 s on one core), the mean error to ±0.1–0.2 % (sd/√160)
# instead of ±0.3–0.6 %, enough to see whether the aliased fit is biased at the 0.1 % level.
SIZES = {
    "short": ([5_000.0, 50_000.0], 2),
    "docs": (RATES_HZ, SEEDS),
    "large": (RATES_HZ, 160),
}
BLOCK_HZ = 10.0  # frequency resolution of the blocked periodogram
INNER_STEP_S = 1e-5  # Langevin step inside each sample interval (at most)


def block_periodogram(x: np.ndarray, fs: float, block: int):
    """One-sided PSD (m²/Hz) averaged over non-overlapping blocks, bins 1 .. block/2 − 1."""
    nb = len(x) // block
    seg = x[: nb * block].reshape(nb, block)
    seg = seg - seg.mean(axis=1, keepdims=True)
    p = 2.0 * np.abs(np.fft.rfft(seg, axis=1)) ** 2 / (fs * block)
    psd = p.mean(axis=0)[1: block // 2]
    f = np.arange(1, block // 2) * fs / block
    return f, psd


def weighted_line(u, y, w):
    sw, su, sy = w.sum(), (w * u).sum(), (w * y).sum()
    suu, suy = (w * u * u).sum(), (w * u * y).sum()
    beta = (sw * suy - su * sy) / (sw * suu - su * su)
    return (sy - beta * su) / sw, beta


def fit_lorentzian(f, s):
    a, b = weighted_line(f * f, 1.0 / s, s * s)
    return math.sqrt(a / b) if a / b > 0 else math.nan


def fit_aliased(f, s, fs):
    a, b = weighted_line(np.cos(2 * np.pi * f / fs), 1.0 / s, s * s)
    rho = -b / a
    if not 0 < rho < 1:
        return math.nan
    c = (1 - math.sqrt(1 - rho * rho)) / rho
    return -math.log(c) * fs / (2 * np.pi)


def calibration_run(run: dict, seed: int) -> dict:
    """One run: a 2 s thermal trace at ``sample_rate_hz`` calibrated both ways."""
    fs = run["sample_rate_hz"]
    depth = KAPPA_N_PER_M * WAIST_M**2 / (2 * math.log(2))
    bead = nh.GaussianTrap(depth, (WAIST_M, WAIST_M), None, radius=RADIUS_M,
                           viscosity=VISCOSITY_PA_S, temperature=TEMPERATURE_K)
    sub = max(1, math.ceil(1.0 / (fs * INNER_STEP_S)))
    x = bead.brownian(DURATION_S, fs, seed=seed, substeps=sub)[:, 0]
    f, s = block_periodogram(x, fs, int(round(fs / BLOCK_HZ)))
    gamma = bead.drag
    k_lor = 2 * np.pi * gamma * fit_lorentzian(f, s)
    low = f <= fs / 4
    k_lor4 = 2 * np.pi * gamma * fit_lorentzian(f[low], s[low])
    k_ali = 2 * np.pi * gamma * fit_aliased(f, s, fs)
    return {
        "kappa_lorentzian_n_per_m": k_lor,
        "kappa_lorentzian_quarter_n_per_m": k_lor4,
        "kappa_aliased_n_per_m": k_ali,
        "error_lorentzian": k_lor / KAPPA_N_PER_M - 1,
        "error_lorentzian_quarter": k_lor4 / KAPPA_N_PER_M - 1,
        "error_aliased": k_ali / KAPPA_N_PER_M - 1,
        "fc_hz": KAPPA_N_PER_M / (2 * np.pi * gamma),
    }


def runs(size: str = "docs") -> list:
    rates, seeds = SIZES[common.check_size(size)]
    return nh.grid({"sample_rate_hz": rates, "repeat": list(range(seeds))})


def study(executor=None, workers=None, progress=True, seed=2024, size="docs", chunksize=None):
    return nh.sweep(calibration_run, runs(size), seed=seed, executor=executor, workers=workers, progress=progress,
                    chunksize=chunksize)


def figure(df, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    g = df.groupby("sample_rate_hz")
    fc = df["fc_hz"].iloc[0]
    fig, ax = plt.subplots(figsize=(7.5, 4.6), constrained_layout=True)
    for col, label, style in (("error_lorentzian", "continuous Lorentzian, fit up to fs/2", "o-"),
                              ("error_lorentzian_quarter", "continuous Lorentzian, fit up to fs/4", "^-"),
                              ("error_aliased", "aliased (sampled OU) spectrum, up to fs/2", "s-")):
        m, s = g[col].mean() * 100, g[col].std() * 100
        ax.errorbar(m.index / 1e3, m.values, yerr=s.values, fmt=style, capsize=3, label=label)
    ax.axhline(0, color="k", lw=0.8)
    ax.axvline(2 * fc / 1e3, color="grey", ls=":", label=f"2·fc = {2 * fc / 1e3:.2f} kHz")
    ax.set_xscale("log")
    ax.set_xlabel("sampling rate, kHz")
    ax.set_ylabel(f"stiffness error, % (mean ± sd of {int(g.size().iloc[0])} seeds)")
    ax.set_title(f"Calibration of κ = 0.1 pN/nm (fc = {fc:.0f} Hz) from 2 s of instantaneous samples")
    ax.legend()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)


def main() -> None:
    args = common.parser(__doc__).parse_args()
    with common.executor(args.dask, __name__) as ex:
        df = study(ex, args.workers, not args.no_progress, size=args.size, chunksize=args.chunksize)
    figure(df, args.out / ("calibration-aliasing.png" if args.size == "docs"
                           else f"calibration-aliasing-{args.size}.png"))
    cols = ["error_lorentzian", "error_lorentzian_quarter", "error_aliased"]
    t = df.groupby("sample_rate_hz")[cols].agg(["mean", "std", "sem"]) * 100
    seeds = SIZES[args.size][1]
    print(f"stiffness error, % (mean ± sd over {seeds} seeds; ± the mean's standard error)")
    print("| sampling rate, kHz | Lorentzian to fs/2 | Lorentzian to fs/4 | aliased to fs/2 |")
    print("|---|---|---|---|")
    for rate, r in t.iterrows():
        cells = " | ".join(f"{r[(c, 'mean')]:+.2f} ± {r[(c, 'std')]:.1f} (± {r[(c, 'sem')]:.2f})" for c in cols)
        print(f"| {rate / 1e3:g} | {cells} |")
    print(f"{len(df)} runs in {df.attrs['wall_s']:.2f} s ({len(df) / df.attrs['wall_s']:.1f} runs/s)")


if __name__ == "__main__":
    main()
