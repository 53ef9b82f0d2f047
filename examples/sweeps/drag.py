"""Drag experiment over operator stiffness × feedback gain (optical tweezers, paper §3.3).

The operator grabs the particle and drags the stylus 10 µm (world) in 0.25 s, faster than
the trap can follow. With force feedback off the cursor runs far ahead of the particle (the
paper: up to 3 µm); with feedback on the spring on the excess pushes the hand back (the paper:
under 0.3 µm). This sweep maps the largest cursor–particle distance while grabbed over the
hand's stiffness (``operator.stiffness_n_per_m``, the simulated hand's pull toward its intended
path, N/m at the device) and the feedback gain (``optical_tweezers.stiffness_n_per_m``, N/m in
the world; felt ×1000 at the device with the scene's mapping), for a passive hand and for one
that slows down when it feels a force (``operator.yield_force_n = 0.5``: 0.5 N halves its
speed), as the paper's operators did.

    python examples/sweeps/drag.py [--workers N | --dask local:2 | --dask tcp://HOST:8786]
                                   [--size short|docs|large] [--chunksize N]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import nanohaptics as nh

sys.path.insert(0, str(Path(__file__).resolve().parent))
import common  # noqa: E402

HERE = Path(__file__).resolve().parent
SCENE = common.ROOT / "scenes" / "optical_tweezers.toml"
SCRIPT = HERE / "drag.script.toml"
GAINS_N_PER_M = [0.1, 0.2, 0.4, 0.8, 1.6, 3.0]  # world; the Falcon's cap maps to 3 N/m
HANDS_N_PER_M = [100.0, 200.0, 400.0, 800.0, 1600.0, 3200.0]
YIELD_N = [0.0, 0.5]
# size → (gains, hands, yield forces). docs: the 6 × 6 × 2 map of docs/sweeps.md (84 runs);
# large: the same ranges on 24 log-spaced steps each (a factor 1.16 apart) and five hands
# (passive; 0.25, 0.5, 1 or 2 N halves the speed): 3000 runs, ≥ 30 s on one core.
SIZES = {
    "short": ([0.4, 3.0], [200.0, 1600.0], [0.0, 0.5]),
    "docs": (GAINS_N_PER_M, HANDS_N_PER_M, YIELD_N),
    "large": (np.geomspace(0.1, 3.0, 24).round(4).tolist(), np.geomspace(100.0, 3200.0, 24).round(1).tolist(),
              [0.0, 0.25, 0.5, 1.0, 2.0]),
}


def runs(size: str = "docs") -> list:
    """Feedback on over the gain grid, and feedback off (gain unused), for each hand."""
    gains, hands, yields = SIZES[common.check_size(size)]
    on = nh.grid({
        "operator.yield_force_n": yields,
        "operator.stiffness_n_per_m": hands,
        "optical_tweezers.feedback": [True],
        "optical_tweezers.stiffness_n_per_m": gains,
    })
    off = nh.grid({
        "operator.yield_force_n": yields,
        "operator.stiffness_n_per_m": hands,
        "optical_tweezers.feedback": [False],
        "optical_tweezers.stiffness_n_per_m": [0.8],
    })
    return on + off


def study(executor=None, workers=None, progress=True, size="docs", chunksize=None):
    return nh.sweep(SCENE, runs(size), script=SCRIPT, executor=executor, workers=workers, progress=progress,
                    chunksize=chunksize)


def figure(df, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    on = df[df["optical_tweezers.feedback"].astype(bool)]
    gains = sorted(on["optical_tweezers.stiffness_n_per_m"].unique())
    hands = sorted(df["operator.stiffness_n_per_m"].unique())
    yields = sorted(df["operator.yield_force_n"].unique())
    label = len(gains) <= 8 and len(hands) <= 8  # numbers in the cells of a coarse map
    fig, axes = plt.subplots(1, len(yields), figsize=(5.5 * len(yields), 4.6), constrained_layout=True)
    axes = np.atleast_1d(axes)
    cols = [f"{g:g}" for g in gains] + ["off"]
    vmax = df["max_lag_grabbed_m"].max() * 1e6
    for ax, y in zip(axes, yields):
        sub = df[df["operator.yield_force_n"] == y]
        m = np.zeros((len(hands), len(cols)))
        for i, k in enumerate(hands):
            h = sub[sub["operator.stiffness_n_per_m"] == k]
            for j, g in enumerate(gains):
                m[i, j] = h[(h["optical_tweezers.feedback"]) & (h["optical_tweezers.stiffness_n_per_m"] == g)][
                    "max_lag_grabbed_m"].iloc[0] * 1e6
            m[i, -1] = h[~h["optical_tweezers.feedback"].astype(bool)]["max_lag_grabbed_m"].iloc[0] * 1e6
        im = ax.imshow(m, origin="lower", cmap="viridis", vmin=0, vmax=vmax, aspect="auto")
        for i in range(m.shape[0] if label else 0):
            for j in range(m.shape[1]):
                ax.text(j, i, f"{m[i, j]:.2f}", ha="center", va="center", fontsize=8,
                        color="white" if m[i, j] < 0.6 * vmax else "black")
        step = 1 if label else 4
        ax.set_xticks(range(0, len(cols), step), cols[::step])
        ax.set_yticks(range(0, len(hands), step), [f"{k:g}" for k in hands][::step])
        ax.set_xlabel("feedback gain, world N/m (×1000 felt at the device)")
        ax.set_ylabel("operator (hand) stiffness, N/m")
        ax.set_title("passive hand" if y == 0 else f"hand that yields ({y:g} N halves its speed)")
    fig.colorbar(im, ax=axes, label="largest cursor–particle distance while grabbed, µm")
    fig.suptitle("Drag experiment: 10 µm in 0.25 s (paper: up to 3 µm with feedback off, < 0.3 µm on)")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)


def main() -> None:
    args = common.parser(__doc__).parse_args()
    with common.executor(args.dask, __name__) as ex:
        df = study(ex, args.workers, not args.no_progress, args.size, args.chunksize)
    figure(df, args.out / ("drag-map.png" if args.size == "docs" else f"drag-map-{args.size}.png"))
    show = df[["operator.yield_force_n", "operator.stiffness_n_per_m", "optical_tweezers.feedback",
               "optical_tweezers.stiffness_n_per_m", "max_lag_grabbed_m", "peak_device_force_n"]]
    if len(df) <= 100:
        print(show.to_string(index=False))
    else:  # the large map: the range of the lag per hand that yields, feedback on and off
        print((show.groupby(["operator.yield_force_n", "optical_tweezers.feedback"])["max_lag_grabbed_m"]
               .agg(["min", "median", "max"]) * 1e6).round(3).to_string())
    print(f"{len(df)} runs in {df.attrs['wall_s']:.2f} s ({len(df) / df.attrs['wall_s']:.1f} runs/s)")


if __name__ == "__main__":
    main()
