"""What the three sweep studies share: choosing where the runs go, and where figures go.

``--workers N``: a thread pool of N threads in this process (the default: every CPU).
``--dask local:N``: a Dask LocalCluster of N worker processes on this machine.
``--dask tcp://HOST:8786``: an existing Dask scheduler (``dask scheduler`` on one machine,
``dask worker tcp://HOST:8786`` on each of N machines, every one with nanohaptics installed):
the same code, the runs spread over every worker of the cluster.
"""

from __future__ import annotations

import argparse
import contextlib
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
FIGURES = ROOT / "docs" / "sweeps"
SIZES = ("short", "docs", "large")


def check_size(size: str) -> str:
    if size not in SIZES:
        raise ValueError(f"size = {size!r}: allowed one of {', '.join(SIZES)}")
    return size


def noop_run(run: dict, seed: int) -> dict:
    """A run that does nothing: what a task costs on an executor, with nothing to run."""
    return {"i": run["i"]}


def parser(doc: str) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=doc.strip().splitlines()[0])
    p.add_argument("--workers", type=int, default=None, help="threads of the default pool (default: every CPU)")
    p.add_argument("--dask", default=None, help="local:N (a LocalCluster of N processes) or a scheduler address")
    p.add_argument("--out", type=Path, default=FIGURES, help="folder of the figure (default docs/sweeps)")
    p.add_argument("--no-progress", action="store_true")
    p.add_argument("--size", choices=SIZES, default="docs",
                   help="short (a few runs: a smoke test), docs (the figure and table of docs/sweeps.md, "
                        "a few seconds), large (the benchmark's: ≥ 30 s on one core)")
    p.add_argument("--chunksize", type=int, default=None,
                   help="runs per task (default: chosen from the measured run time)")
    return p


@contextlib.contextmanager
def executor(dask: str | None, *modules):
    """None (the default thread pool) or a Dask Client; the study modules are shipped to the
    workers by value (they are scripts, not installed packages)."""
    if dask is None:
        yield None
        return
    import cloudpickle
    from distributed import Client, LocalCluster

    for m in modules:
        cloudpickle.register_pickle_by_value(sys.modules[m] if isinstance(m, str) else m)
    if dask.startswith("local:"):
        n = int(dask.split(":", 1)[1])
        with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None) as c:
            with Client(c) as client:
                yield client
    else:
        with Client(dask) as client:
            yield client
