"""Parameter studies: many runs of a scene (or of a function) on threads, processes or a Dask cluster.

:func:`sweep` runs a list of override dicts (one per run, see :func:`grid`) and returns a
pandas DataFrame of per-run summary metrics, one row per run, in run order. Every run gets
its seed from ``(seed, run index)`` (:func:`run_seed`), never from the worker that ran it or
from the order runs finished in, so a sweep gives the same bits serially, on a thread pool
and on a Dask cluster of any size.

What crosses a process boundary is plain data that pickles: the scene and script as TOML text
(resolved and validated here, before the first run, with the overrides applied), the run's
overrides and seed, and back a dict of metrics (and, when asked, numpy arrays). A worker on
another machine needs the ``nanohaptics`` wheel, not the scene files.

pandas is needed for the DataFrame (``pip install nanohaptics[sweep]``); Dask is optional
(``pip install nanohaptics[dask]``). Units: every metric column says its unit in its name.
"""

from __future__ import annotations

import concurrent.futures as cf
import itertools
import math
import os
import queue
import sys
import time
from typing import Any, Callable, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple

import numpy as np

__all__ = ["sweep", "grid", "run_seed", "scene_metrics", "auto_chunksize"]

Run = Mapping[str, Any]


def run_seed(seed: int, index: int) -> int:
    """The seed of run ``index`` of a sweep with master seed ``seed``: an integer in
    0 ..= 2**64 - 1, from numpy's ``SeedSequence(seed, spawn_key=(index,))`` (a documented,
    portable hash: the same pair gives the same seed on every machine and numpy version).
    Distinct runs get independent streams; pass it to ``GaussianTrap.brownian(seed=...)`` or
    ``numpy.random.default_rng``."""
    for name, v in (("seed", seed), ("index", index)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < 0:
            raise ValueError(f"{name} = {v!r}: allowed a whole number ≥ 0")
    ss = np.random.SeedSequence(int(seed), spawn_key=(int(index),))
    return int(ss.generate_state(1, dtype=np.uint64)[0])


def grid(axes: Mapping[str, Sequence[Any]]) -> List[Dict[str, Any]]:
    """Every combination of ``axes`` (dotted field name → list of values) as a list of
    override dicts, the last axis varying fastest (a field fixed for every run is an axis of
    one value).

    >>> grid({"a.x": [1, 2], "b.y": [10, 20]})
    [{'a.x': 1, 'b.y': 10}, {'a.x': 1, 'b.y': 20}, {'a.x': 2, 'b.y': 10}, {'a.x': 2, 'b.y': 20}]
    """
    names = list(axes)
    for n in names:
        vals = axes[n]
        if isinstance(vals, (str, bytes)) or not isinstance(vals, Iterable):
            raise ValueError(f"grid: axis {n!r} must be a list of values, got {vals!r}")
    values = [list(axes[n]) for n in names]
    for n, v in zip(names, values):
        if not v:
            raise ValueError(f"grid: axis {n!r} has no values")
    return [dict(zip(names, combo)) for combo in itertools.product(*values)]


# ------------------------------------------------------------------------------ metrics


def _grabbed_or_all(a: dict) -> np.ndarray:
    fields = list(a["state_fields"])
    if "grabbed" in fields:
        g = a["state"][:, fields.index("grabbed")] > 0.5
        if g.any():
            return g
    return np.ones(len(a["tick"]), dtype=bool)


def scene_metrics(a: dict) -> Dict[str, float]:
    """Per-run summary of a session's arrays (as :func:`nanohaptics.run_scene` returns them):

    * ``ticks``, ``session_s`` — length;
    * ``peak_device_force_n``, ``rms_device_force_n`` — force sent to the device (N, device
      frame), largest norm and root mean square;
    * ``max_<field>`` and ``final_<field>`` for every state field of the scene (its unit is
      the field's suffix, e.g. ``max_lag_m``);
    * optical tweezers: ``max_lag_grabbed_m``, ``mean_lag_grabbed_m`` (cursor − particle
      distance while grabbed, m), ``clipped_fraction`` (grabbed ticks whose command left the
      working envelope);
    * ``events`` — how many events the world raised.
    """
    t = len(a["tick"])
    f = np.linalg.norm(a["device_force_n"], axis=1) if t else np.zeros(0)
    out: Dict[str, float] = {
        "ticks": int(t),
        "session_s": float(t / a["rate_hz"]),
        "peak_device_force_n": float(f.max()) if t else 0.0,
        "rms_device_force_n": float(np.sqrt(np.mean(f * f))) if t else 0.0,
    }
    fields = list(a["state_fields"])
    st = a["state"]
    for i, name in enumerate(fields):
        col = st[:, i]
        out[f"max_{name}"] = float(col.max()) if t else math.nan
        out[f"final_{name}"] = float(col[-1]) if t else math.nan
    if "lag_m" in fields and "excess_m" in fields:
        g = _grabbed_or_all(a)
        lag = st[g, fields.index("lag_m")]
        exc = st[g, fields.index("excess_m")]
        out["max_lag_grabbed_m"] = float(lag.max()) if lag.size else math.nan
        out["mean_lag_grabbed_m"] = float(lag.mean()) if lag.size else math.nan
        out["clipped_fraction"] = float(np.mean(exc > 0.0)) if exc.size else math.nan
    out["events"] = int(len(a["events"]))
    return out


# ------------------------------------------------------------------------------ one run

# What a worker receives: (index, seed, task, payload, want_arrays, out_path).
# task "scene": payload = (resolved scene dict, run_scene keyword arguments, metrics function)
# task "call":  payload = (function, overrides dict)


def _split(result: Mapping[str, Any], want_arrays: bool) -> Tuple[Dict[str, Any], Optional[dict]]:
    scalars: Dict[str, Any] = {}
    rest: Dict[str, Any] = {}
    for k, v in result.items():
        if isinstance(v, (bool, int, float, str, np.integer, np.floating, np.bool_)) or v is None:
            scalars[k] = v.item() if isinstance(v, np.generic) else v
        else:
            rest[k] = v
    return scalars, (rest if want_arrays else None)


def _execute(job: tuple) -> tuple:
    """Runs one job of a sweep (module-level, so that it pickles by reference)."""
    index, seed, task, payload, want_arrays, out_path = job
    if task == "scene":
        import nanohaptics as nh

        scene, kwargs, metrics = payload
        a = nh.run_scene(scene, out=out_path, **kwargs)
        a.pop("stats", None)
        m = (metrics or scene_metrics)(a)
        if not isinstance(m, Mapping):
            raise TypeError(f"metrics must return a dict, got {type(m).__name__}")
        scalars, _ = _split(m, False)
        if want_arrays:
            # wall-clock fields are not results: they differ between runs of the same bits
            for k in ("compute_ns", "start_late_ns"):
                a.pop(k, None)
        return index, scalars, (a if want_arrays else None)
    fn, run = payload
    result = fn(dict(run), seed)
    if not isinstance(result, Mapping):
        raise TypeError(f"run {index}: the function must return a dict, got {type(result).__name__}")
    scalars, arrays = _split(result, want_arrays)
    return index, scalars, arrays


def _execute_many(jobs: list) -> tuple:
    """Runs a chunk of jobs in order (one task on an executor: fewer, larger tasks when each
    run is short) and returns ``(results, seconds)``, the seconds spent in the runs as timed
    on the worker (what the automatic chunk size is chosen from). A failure names its run."""
    out = []
    t0 = time.perf_counter()
    for job in jobs:
        try:
            out.append(_execute(job))
        except Exception as e:
            raise RuntimeError(f"run {job[0]}: {type(e).__name__}: {e}") from e
    return out, time.perf_counter() - t0


# ------------------------------------------------------------------------------ progress


class _Progress:
    def __init__(self, total: int, enabled: bool, stream=None):
        self.total, self.enabled = total, enabled and total > 0
        self.stream = stream or sys.stderr
        self.t0 = time.perf_counter()
        self.done = 0
        self._last = 0.0

    def update(self, n: int = 1) -> None:
        self.done += n
        now = time.perf_counter()
        if self.enabled and (now - self._last >= 0.1 or self.done == self.total):
            self._last = now
            el = now - self.t0
            rate = self.done / el if el > 0 else 0.0
            eta = (self.total - self.done) / rate if rate > 0 else float("inf")
            width = 24
            fill = int(width * self.done / self.total)
            eta_s = f"{eta:.0f} s" if math.isfinite(eta) else "?"
            self.stream.write(
                f"\rsweep [{'#' * fill}{'.' * (width - fill)}] {self.done}/{self.total} runs"
                f"  {rate:.2f} runs/s  eta {eta_s} "
            )
            self.stream.flush()

    def close(self, note: str = "") -> None:
        if self.enabled:
            self.stream.write(f"  {note}\n" if note else "\n")
            self.stream.flush()


# ------------------------------------------------------------------------------ the sweep


def _executor_for(executor: Any):
    """(executor, owned): a Dask ``Client`` becomes its concurrent.futures executor."""
    mod = type(executor).__module__ or ""
    if mod.split(".")[0] == "distributed" and hasattr(executor, "get_executor"):
        return executor.get_executor(pure=False), True
    if not hasattr(executor, "submit"):
        raise ValueError(
            "executor: expected a concurrent.futures-style executor (with submit) or a Dask "
            f"Client, got {type(executor).__name__}"
        )
    return executor, False


# Per-task cost assumed at least this (s), whatever one probe measured: a thread pool's
# submit + hand-off + result (≈ 10–30 µs measured, docs/bench/sweeps.md) and a process or
# Dask executor's (≈ 1–3 ms: scheduling, pickling, two messages).
_MIN_TASK_COST_S = {"threads": 20e-6, "other": 1e-3}
# A task should run for at least this many times its cost (so the cost is ≤ 1 %) ...
_COST_FACTOR = 100.0
# ... and there should be at least this many tasks per worker thread, so that the last
# task to finish leaves the others idle for at most ~1/16 of a worker's share.
_TASKS_PER_THREAD = 16


def _threads_of(executor: Any, n_workers: Optional[int]) -> int:
    """Worker threads behind an executor: the default pool's, a Dask cluster's (sum of
    nthreads), a concurrent.futures pool's ``_max_workers``, else the CPUs here."""
    if executor is None:
        return n_workers or 1
    if hasattr(executor, "nthreads"):  # a Dask Client
        try:
            return max(1, sum(executor.nthreads().values()))
        except Exception:  # pragma: no cover - a client without workers yet
            pass
    return getattr(executor, "_max_workers", None) or os.cpu_count() or 1


def auto_chunksize(run_s: float, task_cost_s: float, runs: int, threads: int) -> int:
    """Runs per task for ``runs`` runs of ``run_s`` seconds each (as measured) on ``threads``
    worker threads whose executor costs ``task_cost_s`` per task: long enough that the cost
    is ≤ 1 % of a task (100 × the cost), short enough to leave ≥ 16 tasks per thread (load
    balance), and at least 1.

    >>> auto_chunksize(0.0007, 2e-3, 50_000, 2)   # 0.7 ms runs on Dask: 286 per task
    286
    >>> auto_chunksize(0.3, 2e-3, 1000, 2)        # 0.3 s runs: one per task
    1
    """
    if runs <= 0:
        return 1
    run_s = max(run_s, 1e-7)
    want_s = _COST_FACTOR * task_cost_s
    cap = max(1, runs // (_TASKS_PER_THREAD * max(1, threads)))
    return int(max(1, min(cap, math.ceil(want_s / run_s))))


class _SigintFlag:
    """While the main thread waits for a pool, SIGINT sets a flag the wait loop checks instead
    of raising where it lands: a KeyboardInterrupt raised inside a weakref or ``__del__``
    callback that the main thread happens to run (garbage from a previous Dask cluster, a
    finished thread leaving ``threading._dangling``) is printed and lost, and the sweep would
    run to the end. Installed only when SIGINT has Python's default handler and this is the
    main thread (a SIGINT the process ignores stays ignored); restored on exit."""

    def __init__(self) -> None:
        self.raised = False
        self._previous: Any = None

    def __enter__(self) -> "_SigintFlag":
        import signal
        import threading

        if threading.current_thread() is threading.main_thread() and \
                signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            self._previous = signal.signal(signal.SIGINT, self._handle)
        return self

    def _handle(self, signum, frame) -> None:
        self.raised = True

    def __exit__(self, *exc) -> None:
        if self._previous is not None:
            import signal

            signal.signal(signal.SIGINT, self._previous)


def _shutdown(pool: Any, wait: bool) -> None:
    if isinstance(pool, cf.ThreadPoolExecutor):
        pool.shutdown(wait=wait, cancel_futures=True)
    else:  # a Dask ClientExecutor: shutdown(wait=False) cancels what is left
        pool.shutdown(wait=wait)


def sweep(
    scene: Any,
    runs: Sequence[Run],
    *,
    seed: int = 0,
    executor: Any = None,
    arrays: bool = False,
    progress: bool = True,
    workers: Optional[int] = None,
    script: Any = None,
    seconds: Optional[float] = None,
    operator: Any = None,
    device: Optional[str] = None,
    metrics: Optional[Callable[[dict], Mapping[str, Any]]] = None,
    record_dir: Any = None,
    chunksize: Optional[int] = None,
):
    """Run ``scene`` once per override dict in ``runs`` and return a pandas DataFrame with
    one row per run.

    Args:
        scene: a scene file path or built-in name (each run is
            :func:`nanohaptics.run_scene` with that run's overrides), or a function
            ``fn(run: dict, seed: int) -> dict`` (each run calls it; scalar values become
            columns, anything else is kept only with ``arrays=True``). A function run on
            other processes must pickle (a module-level function; Dask pickles a script's
            own functions by value).
        runs: list of dicts of dotted field name → value (see :func:`grid`);
            ``operator.*`` names change the simulated hand. Every run's overrides are
            validated before the first run starts (ValueError naming the run and the
            field).
        seed: master seed; run ``i`` gets ``run_seed(seed, i)`` (column ``seed``).
        executor: None (a thread pool of ``workers`` threads; the GIL is released while a
            session runs), any ``concurrent.futures.Executor`` (e.g. a
            ``ProcessPoolExecutor``) or a Dask ``distributed.Client``.
        arrays: keep each run's per-tick arrays (scene runs: the dict of ``run_scene``
            without its wall-clock fields; function runs: the non-scalar values) in an
            ``arrays`` column.
        progress: draw a progress bar on stderr.
        workers: threads of the default pool (default: the number of CPUs); 1 runs
            serially in the calling thread.
        script, seconds, operator, device: as for :func:`nanohaptics.run_scene`, the same
            for every run.
        metrics: ``fn(arrays) -> dict`` summarising a scene run (default
            :func:`scene_metrics`).
        record_dir: a folder: record every scene run to ``run-00000.mcap`` ... there
            (column ``recording``); the folder must be reachable from the workers.
        chunksize: runs per task handed to the executor (a whole number ≥ 1). None
            (the default): the first run on each worker thread goes alone, and the first of
            those to come back gives the run time (timed on the worker) and the task's cost
            (its round trip less the run); the rest go in chunks of
            :func:`auto_chunksize` runs — a task lasting 100 × its cost, but no fewer
            than 16 tasks per worker thread (load balance). Results, and their order, do not depend on it
            (``df.attrs["chunksize"]`` says what was used, ``df.attrs["tasks"]`` how many
            tasks).

    Returns:
        DataFrame: columns ``run`` (index), ``seed``, one per override name, then the
        metrics (units in their names); ``df.attrs`` holds ``interrupted`` (True when
        Ctrl-C stopped the sweep: the rows are the runs that had finished),
        ``wall_s``, ``workers``, ``chunksize`` and ``tasks``. Ctrl-C cancels the runs not
        started; runs in progress on threads finish in the background.
    """
    try:
        import pandas as pd
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("sweep returns a pandas DataFrame: pip install nanohaptics[sweep]") from e
    import nanohaptics as nh

    runs = list(runs)
    for i, r in enumerate(runs):
        if not isinstance(r, Mapping):
            raise ValueError(f"runs[{i}]: expected a dict of dotted field names to values, got {r!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed < 2**64:
        raise ValueError(f"seed = {seed!r}: allowed a whole number 0 ..= 2**64 - 1")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise ValueError(f"workers = {workers!r}: allowed a whole number ≥ 1")
    if chunksize is not None and (isinstance(chunksize, bool) or not isinstance(chunksize, (int, np.integer))
                                  or chunksize < 1):
        raise ValueError(
            f"chunksize = {chunksize!r}: allowed a whole number ≥ 1 (runs per task), or None "
            "(chosen from a measured run time)"
        )
    if chunksize is not None:
        chunksize = int(chunksize)
    seeds = [run_seed(int(seed), i) for i in range(len(runs))]

    jobs = []
    if callable(scene) and not isinstance(scene, (str, os.PathLike, dict)):
        if any(x is not None for x in (script, seconds, operator, device, metrics, record_dir)):
            raise ValueError("script, seconds, operator, device, metrics and record_dir apply to scene runs, not to a function")
        for i, r in enumerate(runs):
            jobs.append((i, seeds[i], "call", (scene, dict(r)), arrays, None))
    else:
        base = nh.resolve_scene(scene, script=script, device=device)
        kwargs: Dict[str, Any] = {}
        if seconds is not None:
            kwargs["seconds"] = seconds
        if operator is not None:
            kwargs["operator"] = operator
        if device is not None:
            kwargs["device"] = device
        rec = None
        if record_dir is not None:
            rec = os.fspath(record_dir)
            os.makedirs(rec, exist_ok=True)
        for i, r in enumerate(runs):
            try:
                resolved = nh.resolve_scene(base, overrides=dict(r), device=device) if r else base
            except ValueError as e:
                raise ValueError(f"runs[{i}]: {e}") from None
            out = os.path.join(rec, f"run-{i:05d}.mcap") if rec is not None else None
            jobs.append((i, seeds[i], "scene", (resolved, kwargs, metrics), arrays, out))

    results: Dict[int, tuple] = {}
    futures: Dict[Any, list] = {}  # future → its chunk of jobs
    bar = _Progress(len(jobs), progress)
    interrupted = False
    t0 = time.perf_counter()
    owned = executor is None
    n_workers = workers if workers is not None else (os.cpu_count() or 1)
    if executor is None and n_workers == 1:
        pool = None
    elif executor is None:
        pool = cf.ThreadPoolExecutor(max_workers=n_workers, thread_name_prefix="nanohaptics-sweep")
    else:
        pool, owned = _executor_for(executor)
        n_workers = None
    try:
        if pool is None:
            for job in jobs:
                try:
                    ((idx, scal, arr),), _ = _execute_many([job])
                except Exception as e:
                    raise RuntimeError(f"sweep: {e}") from e
                results[idx] = (scal, arr)
                bar.update()
        else:
            threads = _threads_of(executor, n_workers)
            kind = "threads" if isinstance(pool, cf.ThreadPoolExecutor) else "other"
            with _SigintFlag() as sigint:
                # Each finished future is queued by its own callback: collecting N futures
                # costs O(N). (cf.wait(pending, FIRST_COMPLETED) installs a waiter on every
                # pending future at each call, O(N²) under the GIL: with 2578 one-run tasks
                # it made 2 threads slower than 1.)
                finished: "queue.SimpleQueue[Any]" = queue.SimpleQueue()
                futures = {}
                submitted: Dict[Any, float] = {}

                def submit(chunk: list) -> None:
                    f = pool.submit(_execute_many, chunk)
                    futures[f] = chunk
                    submitted[f] = time.perf_counter()
                    f.add_done_callback(lambda f: finished.put((f, time.perf_counter())))

                rest: list = []
                if chunksize is None and len(jobs) > threads:
                    # Probe: one run per task on every worker thread; the first to come back
                    # gives the run time (timed on the worker) and the task's cost (round
                    # trip − run time), from which the rest is cut into chunks.
                    for job in jobs[:threads]:
                        submit([job])
                    rest = jobs[threads:]
                else:
                    size = chunksize or 1
                    for k in range(0, len(jobs), size):
                        submit(jobs[k:k + size])
                    chunksize = size
                remaining = len(futures)
                while remaining:
                    if sigint.raised:
                        raise KeyboardInterrupt
                    try:
                        f, t_done = finished.get(timeout=0.25)
                    except queue.Empty:
                        continue
                    remaining -= 1
                    try:
                        got, work_s = f.result()
                    except Exception as e:
                        raise RuntimeError(f"sweep: {e}") from e
                    for idx, scal, arr in got:
                        results[idx] = (scal, arr)
                    bar.update(len(got))
                    if rest:
                        run_s = work_s / max(1, len(got))
                        cost_s = max(_MIN_TASK_COST_S[kind], t_done - submitted[f] - work_s)
                        chunksize = auto_chunksize(run_s, cost_s, len(rest), threads)
                        for k in range(0, len(rest), chunksize):
                            submit(rest[k:k + chunksize])
                            remaining += 1
                        rest = []
    except KeyboardInterrupt:
        interrupted = True
        if pool is not None:
            for f in list(futures):
                f.cancel()
            # keep every run that had finished, collected or not
            for f in list(futures):
                if f.done() and not f.cancelled() and f.exception() is None:
                    for idx, scal, arr in f.result()[0]:
                        results.setdefault(idx, (scal, arr))
    except BaseException:
        if pool is not None:
            for f in list(futures):
                f.cancel()
        bar.close("failed")
        if pool is not None and owned:
            _shutdown(pool, wait=False)
        raise
    if pool is not None and owned:
        _shutdown(pool, wait=not interrupted)
    wall = time.perf_counter() - t0
    bar.close(f"interrupted: {len(results)} of {len(jobs)} runs finished" if interrupted else f"{wall:.1f} s")

    keys: List[str] = []
    for r in runs:
        for k in r:
            if k not in keys:
                keys.append(k)
    metric_cols: List[str] = []
    for i in sorted(results):
        for k in results[i][0]:
            if k not in metric_cols and k not in keys:
                metric_cols.append(k)
    rows = []
    for i in sorted(results):
        scal, arr = results[i]
        row: Dict[str, Any] = {"run": i, "seed": seeds[i]}
        for k in keys:
            row[k] = runs[i].get(k, math.nan)
        for k in metric_cols:
            row[k] = scal.get(k, math.nan)
        if jobs and jobs[i][5] is not None:
            row["recording"] = jobs[i][5]
        if arrays:
            row["arrays"] = arr
        rows.append(row)
    cols = ["run", "seed", *keys, *metric_cols]
    if record_dir is not None and not callable(scene):
        cols.append("recording")
    if arrays:
        cols.append("arrays")
    df = pd.DataFrame.from_records(rows, columns=cols)
    df["seed"] = df["seed"].astype("uint64")
    df.attrs["interrupted"] = interrupted
    df.attrs["wall_s"] = wall
    df.attrs["workers"] = n_workers
    df.attrs["chunksize"] = chunksize if pool is not None else None
    df.attrs["tasks"] = len(futures) if pool is not None else len(jobs)
    if interrupted:
        sys.stderr.write(
            f"sweep: interrupted; returning the {len(results)} of {len(jobs)} runs that finished\n"
        )
    return df
