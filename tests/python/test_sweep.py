"""Parameter studies (issue 16): overrides by dotted name, seeds from (master seed, run index),
and sweeps that give the same bits serially, on threads and on a Dask process cluster."""

from __future__ import annotations

import pickle
import sys
import threading
import _thread
from pathlib import Path

import numpy as np
import pytest

import nanohaptics as nh

pd = pytest.importorskip("pandas")

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"
OT = SCENES / "optical_tweezers.toml"
TIMING = ("compute_ns", "start_late_ns")


# ------------------------------------------------------------------------------ overrides


def test_overrides_reach_the_session():
    base = nh.run_scene(SCENES / "wall.toml", seconds=0.5)
    fast = nh.run_scene(SCENES / "wall.toml", seconds=0.5, overrides={"loop.rate_hz": 2000})
    assert (base["rate_hz"], len(base["tick"])) == (1000, 500)
    assert (fast["rate_hz"], len(fast["tick"])) == (2000, 1000)
    r = nh.resolve_scene("scenes/wall.toml", overrides={"wall.stiffness_n_per_m": 2500.0, "loop.rate_hz": 2000})
    assert r["kind"] == "wall" and r["device"] == "falcon"
    assert r["scene_toml"].splitlines()[0] == (
        "# scene with overrides: wall.stiffness_n_per_m = 2500.0, loop.rate_hz = 2000"
    )
    # a resolved scene is plain data: it pickles, and runs like the file with the overrides
    again = nh.run_scene(pickle.loads(pickle.dumps(r)), seconds=0.5)
    direct = nh.run_scene(SCENES / "wall.toml", seconds=0.5,
                          overrides={"wall.stiffness_n_per_m": 2500.0, "loop.rate_hz": 2000})
    for k in direct:
        if k not in TIMING and k != "stats" and isinstance(direct[k], np.ndarray):
            assert np.array_equal(direct[k], again[k]), k


def test_an_overridden_stiffness_changes_the_felt_force():
    # the simulated hand pushes ~ the same depth into the wall: half the stiffness, less force
    stiff = nh.run_scene(SCENES / "wall.toml", operator="rigid")
    soft = nh.run_scene(SCENES / "wall.toml", operator="rigid", overrides={"wall.stiffness_n_per_m": 2500.0})
    f_stiff = np.abs(stiff["world_force_n"][:, 2]).max()
    f_soft = np.abs(soft["world_force_n"][:, 2]).max()
    assert f_soft < f_stiff


def test_unknown_fields_are_named_with_the_valid_names():
    with pytest.raises(ValueError) as e:
        nh.resolve_scene(OT, overrides={"optical_tweezers.stifness_n_per_m": 0.4})
    msg = str(e.value)
    assert msg.startswith(
        "override `optical_tweezers.stifness_n_per_m`: unknown field `stifness_n_per_m`, "
        "expected one of `depth_nj`, `waist_x_nm`"
    ), msg
    assert "`stiffness_n_per_m`" in msg
    with pytest.raises(ValueError, match=r"^override `lop\.rate_hz`: unknown field `lop`, expected one of `scene`"):
        nh.run_scene(OT, overrides={"lop.rate_hz": 2000})
    with pytest.raises(ValueError, match=r"^override `operator\.stifness`: unknown field `stifness`, expected one of `mass_kg`"):
        nh.resolve_scene(OT, overrides={"operator.stifness": 1.0})


def test_wrong_types_and_ranges_are_the_scene_files_errors():
    with pytest.raises(ValueError) as e:
        nh.resolve_scene(OT, overrides={"loop.rate_hz": "fast"})
    assert str(e.value) == 'override `loop.rate_hz`: invalid type: string "fast", expected u32'
    with pytest.raises(ValueError) as e:
        nh.resolve_scene(OT, overrides={"loop.rate_hz": 999})
    assert str(e.value) == (
        "scene: `loop.rate_hz` = 999 is out of range: allowed 100 ≤ rate_hz ≤ 20000 with "
        "10^9 / rate_hz a whole number"
    )
    with pytest.raises(ValueError) as e:
        nh.resolve_scene(OT, overrides={"optical_tweezers.stiffness_n_per_m": float("nan")})
    assert str(e.value).startswith("scene: `optical_tweezers.stiffness_n_per_m` = NaN is out of range")
    with pytest.raises(ValueError) as e:
        nh.resolve_scene(OT, overrides={"operator.stiffness_n_per_m": -1.0})
    assert "`operator.stiffness_n_per_m` = -1 is out of range" in str(e.value)
    with pytest.raises(ValueError, match=r"^overrides: expected a dict"):
        nh.run_scene(OT, overrides=[("loop.rate_hz", 2000)])


def test_a_sweep_fails_before_its_first_run_naming_the_run():
    runs = [{"loop.rate_hz": 1000}, {"loop.rate_hz": 999}]
    with pytest.raises(ValueError, match=r"^runs\[1\]: scene: `loop.rate_hz` = 999 is out of range"):
        nh.sweep(OT, runs, progress=False)


# ------------------------------------------------------------------------------ seeds and grids


def test_run_seeds_depend_on_master_seed_and_index_only():
    s = [nh.run_seed(7, i) for i in range(100)]
    assert len(set(s)) == 100 and all(0 <= x < 2**64 for x in s)
    assert s[3] == nh.run_seed(7, 3) and nh.run_seed(8, 3) != s[3]
    # the documented derivation, fixed for good: numpy's SeedSequence
    assert s[0] == int(np.random.SeedSequence(7, spawn_key=(0,)).generate_state(1, np.uint64)[0])
    for bad in (-1, 1.5, True):
        with pytest.raises(ValueError):
            nh.run_seed(bad, 0)


def test_grid_is_the_cartesian_product_last_axis_fastest():
    g = nh.grid({"a.x": [1, 2], "b.y": [10, 20, 30]})
    assert g[:4] == [{"a.x": 1, "b.y": 10}, {"a.x": 1, "b.y": 20}, {"a.x": 1, "b.y": 30}, {"a.x": 2, "b.y": 10}]
    assert len(g) == 6
    with pytest.raises(ValueError, match="axis 'a' has no values"):
        nh.grid({"a": []})
    with pytest.raises(ValueError, match="must be a list of values"):
        nh.grid({"a": 3})


# ------------------------------------------------------------------------------ same bits anywhere


def thermal_run(run, seed):
    """A seeded run: the variance of a thermal trace and the trace itself."""
    kappa, a = run["kappa_n_per_m"], 1e-6
    bead = nh.GaussianTrap(kappa * a**2 / (2 * np.log(2)), (a, a), None,
                           radius=0.5e-6, viscosity=1.002e-3, temperature=293.15)
    x = bead.brownian(0.05, 20_000.0, seed=seed)
    return {"var_x_m2": float(np.var(x[:, 0])), "trace_m": x}


OT_RUNS = nh.grid({"optical_tweezers.stiffness_n_per_m": [0.4, 1.6], "operator.stiffness_n_per_m": [150.0, 600.0]})
THERMAL_RUNS = nh.grid({"kappa_n_per_m": [5e-5, 1e-4, 2e-4]}) * 2


def both(executor=None, workers=None):
    ot = nh.sweep(OT, OT_RUNS, seconds=0.7, arrays=True, executor=executor, workers=workers, progress=False)
    th = nh.sweep(thermal_run, THERMAL_RUNS, seed=11, arrays=True, executor=executor, workers=workers,
                  progress=False)
    return ot, th


def assert_identical(a, b):
    cols = [c for c in a.columns if c != "arrays"]
    assert list(a.columns) == list(b.columns)
    pd.testing.assert_frame_equal(a[cols], b[cols], check_exact=True)
    for x, y in zip(a["arrays"], b["arrays"]):
        assert set(x) == set(y)
        for k in x:
            if isinstance(x[k], np.ndarray):
                assert x[k].dtype == y[k].dtype and x[k].tobytes() == y[k].tobytes(), k
            else:
                assert x[k] == y[k], k


@pytest.fixture(scope="module")
def serial():
    return both(workers=1)


def test_a_sweep_summarises_each_run_with_units(serial):
    ot, th = serial
    assert list(ot["run"]) == [0, 1, 2, 3]
    assert list(ot.columns[:4]) == ["run", "seed", "optical_tweezers.stiffness_n_per_m", "operator.stiffness_n_per_m"]
    for c in ("ticks", "session_s", "peak_device_force_n", "max_lag_grabbed_m", "clipped_fraction", "max_lag_m"):
        assert c in ot.columns, c
    assert (ot["ticks"] == 700).all()
    assert list(ot["seed"]) == [nh.run_seed(0, i) for i in range(4)]
    # the particle lags the cursor while grabbed: a few hundred nm at most in this gentle part
    assert ((ot["max_lag_grabbed_m"] > 0) & (ot["max_lag_grabbed_m"] < 1e-6)).all()
    # thermal runs: same κ, different seeds → different traces, variance near kT/κ
    assert th["var_x_m2"][0] != th["var_x_m2"][3]
    kT = 1.380649e-23 * 293.15
    ratio = th["var_x_m2"] * th["kappa_n_per_m"] / kT
    assert ((ratio > 0.5) & (ratio < 1.5)).all(), ratio.tolist()


def test_two_threads_give_the_serial_bits(serial):
    ot, th = both(workers=2)
    assert_identical(serial[0], ot)
    assert_identical(serial[1], th)
    # any concurrent.futures executor, runs handed out in chunks: the same bits
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(2) as pool:
        chunked = nh.sweep(thermal_run, THERMAL_RUNS, seed=11, arrays=True, executor=pool,
                           chunksize=4, progress=False)
    assert_identical(serial[1], chunked)


def failing_run(run, seed):
    if run["i"] == 2:
        raise ZeroDivisionError("division by zero")
    return {"i": run["i"]}


def test_a_failed_run_is_named():
    for workers in (1, 2):
        with pytest.raises(RuntimeError, match=r"^sweep: run 2: ZeroDivisionError: division by zero$"):
            nh.sweep(failing_run, [{"i": i} for i in range(4)], workers=workers, progress=False)


# ------------------------------------------------------------------------------ batching


def test_batching_gives_identical_dataframes(serial):
    """Whatever the runs per task — one, a few, uneven chunks, all in one, or chosen from the
    measured run time — the DataFrame is the serial one, bit for bit and in run order."""
    ot0, th0 = serial
    for chunksize in (1, 2, 3, 5, 100, None):
        ot = nh.sweep(OT, OT_RUNS, seconds=0.7, arrays=True, workers=2, chunksize=chunksize, progress=False)
        th = nh.sweep(thermal_run, THERMAL_RUNS, seed=11, arrays=True, workers=2, chunksize=chunksize,
                      progress=False)
        assert_identical(ot0, ot)
        assert_identical(th0, th)
        if chunksize is not None:
            assert th.attrs["chunksize"] == chunksize
            assert th.attrs["tasks"] == -(-len(THERMAL_RUNS) // chunksize)


def square_run(run, seed):
    return {"square": run["i"] ** 2, "seed_mod_7": seed % 7}


def test_short_runs_are_batched_automatically_with_the_same_results():
    runs = [{"i": i} for i in range(3000)]
    one = nh.sweep(square_run, runs, workers=1, progress=False)
    assert one.attrs["chunksize"] is None and one.attrs["tasks"] == 3000
    assert one["square"].tolist() == [i * i for i in range(3000)]
    for kw in (dict(workers=2), dict(workers=2, chunksize=1), dict(workers=2, chunksize=7)):
        df = nh.sweep(square_run, runs, progress=False, **kw)
        pd.testing.assert_frame_equal(one, df, check_exact=True)
    auto = nh.sweep(square_run, runs, workers=2, progress=False)
    # a µs run against a task's ≥ 20 µs: batched, capped at 16 tasks per thread (3000 // 32)
    assert 1 < auto.attrs["chunksize"] <= 3000 // 32
    assert auto.attrs["tasks"] == 2 + -(-(3000 - 2) // auto.attrs["chunksize"])  # 2 probes + chunks
    pd.testing.assert_frame_equal(one, auto, check_exact=True)


def test_auto_chunksize_pays_the_task_cost_once_per_100_and_keeps_16_tasks_per_thread():
    from nanohaptics.sweeps import auto_chunksize

    assert auto_chunksize(0.0007, 2e-3, 50_000, 2) == 286        # 286 × 0.7 ms ≥ 100 × 2 ms
    assert auto_chunksize(0.0007, 2e-3, 2_000, 2) == 2_000 // 32  # load balance wins
    assert auto_chunksize(0.3, 2e-3, 1_000, 2) == 1               # long runs: one per task
    assert auto_chunksize(0.0, 2e-3, 10, 4) == 1                  # fewer runs than 16 per thread
    assert auto_chunksize(1e-6, 1e-3, 0, 2) == 1


def test_bad_chunksizes_are_refused_naming_the_argument_and_the_range():
    for bad in (0, -3, 1.5, True, "4", float("nan")):
        with pytest.raises(ValueError) as e:
            nh.sweep(failing_run, [{"i": 2}], chunksize=bad, workers=2, progress=False)
        assert str(e.value) == (
            f"chunksize = {bad!r}: allowed a whole number ≥ 1 (runs per task), or None (chosen from a "
            "measured run time)"
        )
    # numpy integers are whole numbers
    df = nh.sweep(square_run, [{"i": 3}], chunksize=np.int64(2), workers=2, progress=False)
    assert df.attrs["chunksize"] == 2 and df["square"].tolist() == [9]


def test_the_benchmark_runs_in_a_short_mode(tmp_path):
    """examples/sweeps/bench.py --short: the benchmark's code (per-task costs, the three
    studies serially, on threads and on Dask, the same-bits check) on a few runs each."""
    pytest.importorskip("distributed")
    import subprocess

    out = tmp_path / "sweeps.md"
    p = subprocess.run([sys.executable, str(ROOT / "examples" / "sweeps" / "bench.py"), "--short", "--out", str(out)],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-3000:]
    text = out.read_text(encoding="utf-8")
    assert "## What a task costs" in text and "## The studies, three ways" in text
    study_rows = [line for line in text.splitlines()
                  if line.startswith(("| drag map | 1 ", "| envelope cache | 1 ", "| calibration | 1 "))]
    assert len(study_rows) == 3, text
    assert all(line.endswith("| yes |") for line in study_rows), text
    cost_rows = [line for line in text.splitlines() if line.startswith(("| 2 threads |", "| Dask, 2 processes |"))]
    assert len(cost_rows) == 8, text
    for line in cost_rows:
        per_run = float(line.split("|")[5])
        assert 0 < per_run < 1e6, line


def test_a_dask_process_cluster_gives_the_serial_bits(serial):
    distributed = pytest.importorskip("distributed")
    import cloudpickle

    # this test module is not importable on the workers: ship its functions by value
    cloudpickle.register_pickle_by_value(sys.modules[__name__])
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        ot, th = both(executor=client)
        pids = client.run(lambda: __import__("os").getpid())
        # batched on Dask, a few runs per task or chosen from the measured run time
        batched = [nh.sweep(thermal_run, THERMAL_RUNS, seed=11, arrays=True, executor=client,
                            chunksize=c, progress=False) for c in (4, None)]
    assert len(set(pids.values())) == 2
    assert_identical(serial[0], ot)
    assert_identical(serial[1], th)
    for df in batched:
        assert_identical(serial[1], df)
    assert batched[0].attrs["tasks"] == 2


def test_recordings_of_a_sweep_replay_its_arrays(tmp_path, serial):
    df = nh.sweep(OT, OT_RUNS[:2], seconds=0.7, arrays=True, record_dir=tmp_path, progress=False, workers=2)
    assert [Path(p).name for p in df["recording"]] == ["run-00000.mcap", "run-00001.mcap"]
    for p, a in zip(df["recording"], df["arrays"]):
        rec = nh.read_recording(p)
        for k in ("state", "device_force_n", "cursor_m"):
            assert np.array_equal(rec[k], a[k]), k
    assert_identical(df.drop(columns=["recording"]), serial[0].iloc[:2])


def test_ctrl_c_returns_the_runs_that_finished(sigint_raises):
    started = threading.Event()

    def run(r, seed):
        if r["i"] == 3:
            started.set()
            _thread.interrupt_main()  # as Ctrl-C would, while the main thread waits
            return {"i2": -1}
        if r["i"] > 3:
            started.wait(5)
            threading.Event().wait(0.5)
        return {"i2": r["i"] * 2}

    df = nh.sweep(run, [{"i": i} for i in range(40)], workers=2, progress=True)
    assert df.attrs["interrupted"] is True
    assert 3 <= len(df) < 40
    assert set(range(3)) <= set(df["run"])
    assert (df["i2"][df["i"] != 3] == df["i"][df["i"] != 3] * 2).all()


def test_the_worker_function_pickles_by_reference():
    f = pickle.loads(pickle.dumps(nh.sweeps._execute))
    assert f is nh.sweeps._execute
    assert nh.sweep.__module__ == "nanohaptics.sweeps"
