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


def runs() -> list:
    """Feedback on over the gain grid, and feedback off (gain unused), for each hand."""
    on = nh.grid({
        "operator.yield_force_n": YIELD_N,
        "operator.stiffness_n_per_m": HANDS_N_PER_M,
        "optical_tweezers.feedback": [True],
        "optical_tweezers.stiffness_n_per_m": GAINS_N_PER_M,
    })
    off = nh.grid({
        "operator.yield_force_n": YIELD_N,
        "operator.stiffness_n_per_m": HANDS_N_PER_M,
        "optical_tweezers.feedback": [False],
        "optical_tweezers.stiffness_n_per_m": [0.8],
    })
    return on + off


def study(executor=None, workers=None, progress=True):
    return nh.sweep(SCENE, runs(), script=SCRIPT, executor=executor, workers=workers, progress=progress)


def figure(df, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.6), constrained_layout=True)
    cols = [f"{g:g}" for g in GAINS_N_PER_M] + ["off"]
    vmax = df["max_lag_grabbed_m"].max() * 1e6
    for ax, y in zip(axes, YIELD_N):
        sub = df[df["operator.yield_force_n"] == y]
        m = np.zeros((len(HANDS_N_PER_M), len(cols)))
        for i, k in enumerate(HANDS_N_PER_M):
            h = sub[sub["operator.stiffness_n_per_m"] == k]
            for j, g in enumerate(GAINS_N_PER_M):
                m[i, j] = h[(h["optical_tweezers.feedback"]) & (h["optical_tweezers.stiffness_n_per_m"] == g)][
                    "max_lag_grabbed_m"].iloc[0] * 1e6
            m[i, -1] = h[~h["optical_tweezers.feedback"].astype(bool)]["max_lag_grabbed_m"].iloc[0] * 1e6
        im = ax.imshow(m, origin="lower", cmap="viridis", vmin=0, vmax=vmax, aspect="auto")
        for i in range(m.shape[0]):
            for j in range(m.shape[1]):
                ax.text(j, i, f"{m[i, j]:.2f}", ha="center", va="center", fontsize=8,
                        color="white" if m[i, j] < 0.6 * vmax else "black")
        ax.set_xticks(range(len(cols)), cols)
        ax.set_yticks(range(len(HANDS_N_PER_M)), [f"{k:g}" for k in HANDS_N_PER_M])
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
        df = study(ex, args.workers, not args.no_progress)
    figure(df, args.out / "drag-map.png")
    show = df[["operator.yield_force_n", "operator.stiffness_n_per_m", "optical_tweezers.feedback",
               "optical_tweezers.stiffness_n_per_m", "max_lag_grabbed_m", "peak_device_force_n"]]
    print(show.to_string(index=False))
    print(f"{len(df)} runs in {df.attrs['wall_s']:.2f} s ({len(df) / df.attrs['wall_s']:.1f} runs/s)")


if __name__ == "__main__":
    main()
