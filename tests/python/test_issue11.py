"""Bad input and API awkwardness found by fuzzing and a newcomer (issue 11, items 7, 8, 9,
15, 21, 22): every bad value is a ValueError naming the field and its range; every result
is finite."""

import _thread
import threading
import time

import numpy as np
import pytest

import nanohaptics as nh

START = (3e-9, 3e-9, 2e-9)


# ---------------------------------------------------------------- item 7: NaN reaches validation


def test_nan_in_a_nano_param_names_the_field():
    p = nh.nano_params()
    p["substrate"]["spacing_m"] = float("nan")
    with pytest.raises(ValueError) as e:
        nh.NanoWorld(START, params=p)
    assert str(e.value) == (
        "substrate.spacing_m = NaN is out of range: allowed 0 < value <= 1e-6"
    )


def test_inf_in_set_params_and_force_distance_curve_names_the_field():
    w = nh.NanoWorld(START)
    p = nh.nano_params()
    p["interaction"]["game"]["pairs"]["tip_atom"]["strength_n_m2"] = float("inf")
    msg = (
        "interaction.game.pairs.tip_atom.strength_n_m2 = inf is out of range: "
        "allowed 0 <= value <= 1e-20"
    )
    with pytest.raises(ValueError) as e:
        w.set_params(p)
    assert str(e.value) == msg
    with pytest.raises(ValueError) as e:
        nh.force_distance_curve(p)
    assert str(e.value) == msg


def test_nan_in_a_brick_param_names_the_field():
    with pytest.raises(ValueError) as e:
        nh.BrickWorld({"friction": float("nan")})
    assert str(e.value) == "parameter `friction` = NaN is out of range: allowed [0, 10]"


def test_params_round_trip_bit_for_bit_without_json():
    p = nh.nano_params()
    p["interaction"]["game"]["pairs"]["tip_atom"]["stiffness_n_per_m"] = 0.1 + 0.2
    w = nh.NanoWorld(START, params=p)
    assert w.params["interaction"]["game"]["pairs"]["tip_atom"]["stiffness_n_per_m"] == 0.1 + 0.2
    # numpy values and tuples are accepted like floats and lists.
    p["substrate"]["spacing_m"] = np.float64(3e-10)
    p["house"]["slots_m"] = np.array(p["house"]["slots_m"])
    assert nh.NanoWorld(START, params=p).params["substrate"]["spacing_m"] == 3e-10


def test_wrong_type_names_the_key():
    p = nh.nano_params()
    p["substrate"]["nx"] = "many"
    with pytest.raises(ValueError) as e:
        nh.NanoWorld(START, params=p)
    assert str(e.value).startswith("params: ")
    assert "substrate.nx" in str(e.value), str(e.value)


# ---------------------------------------------------------------- item 22: extra elements


def test_arrays_longer_than_the_field_are_refused_by_name():
    with pytest.raises(ValueError) as e:
        nh.BrickWorld({"bricks": [{"center_m": [0.0, 0.0, 0.03, 1.0]}]})
    assert "bricks" in str(e.value) and "center_m" in str(e.value), str(e.value)
    assert "invalid length 4" in str(e.value), str(e.value)
    p = nh.nano_params()
    p["initial_atoms_xy_m"][0] = [4.95e-9, 6.15e-9, 0.0]
    with pytest.raises(ValueError) as e:
        nh.NanoWorld(START, params=p)
    assert "initial_atoms_xy_m" in str(e.value) and "invalid length 3" in str(e.value)
    bw = nh.BrickWorld()
    with pytest.raises(ValueError) as e:
        bw.step((0.0, 0.0, 0.5, 0.0))
    assert str(e.value) == "position_m: expected shape (3,), got (4,)"


# ---------------------------------------------------------------- items 8, 9, 21: finite or refused


@pytest.mark.parametrize("mode", ["game", "physical"])
def test_absurd_cursor_is_refused_by_name(mode):
    w = nh.NanoWorld((3e-9, 3e-9, 40e-9), params=mode)
    for pos, axis, value in [
        ((1e308, 0.0, -1e308), "x", "1e308"),
        ((1e300, 1e300, 0.0), "x", "1e300"),
        ((3e-9, 1e308, 2e-9), "y", "1e308"),
    ]:
        with pytest.raises(ValueError) as e:
            w.step(pos)
        assert str(e.value) == (
            f"tip position {axis} = {value} is out of range: allowed |{axis}| <= 1 m"
        )
    assert w.tick == 0 and w.contact is None
    r = w.step((1.0, -1.0, 1.0))
    assert np.all(np.isfinite(r["force"])) and w.contact is None


def test_tiny_dt_while_carrying_is_refused_and_the_smallest_is_finite():
    w = nh.NanoWorld((4e-9, 4e-9, 4e-9))
    path = w.house_script()
    out = w.run(path[:6_000])
    assert out["carried"][-1] >= 1, "the script picks an atom up within 6 000 ticks"
    with pytest.raises(ValueError) as e:
        w.step(path[6_000], dt_s=1e-300)
    assert str(e.value) == "dt_s = 1e-300 is out of range: allowed 1e-9 <= dt_s <= 1 s"
    c = w.cursor
    for dz in (0.0, 0.1, 0.4):
        r = w.step(c + (0.0, 0.0, dz), dt_s=1e-9)
        assert np.all(np.isfinite(r["force"])) and np.all(np.isfinite(r["unlimited_force"]))
        assert np.linalg.norm(r["force"]) <= w.device["max_force_n"] * (1 + 1e-12)
        # 0.1 m in 1 ns: m·a = 1e-8 N on the atom, more than the tip's 3 nN hold: it is thrown
        # off the tip (and the force stays finite, unsaturated).
        thrown = [e for e in r["events"] if e["type"] == "atoms_thrown_off"]
        if dz == 0.1:
            assert len(thrown) == 1 and thrown[0]["atoms"] == 1
            assert abs(thrown[0]["load_n"] / 1e-8 - 1) < 1e-6
            assert abs(thrown[0]["pull_off_n"] / 3e-9 - 1) < 1e-9
        else:
            assert thrown == []
        assert not r["saturated"]


def test_a_refused_row_of_a_batch_is_named():
    w = nh.NanoWorld(START)
    rows = np.tile(np.array(START), (5, 1))
    rows[3, 2] = 2.0
    with pytest.raises(ValueError) as e:
        w.run(rows)
    assert str(e.value) == "positions[3]: tip position z = 2 is out of range: allowed |z| <= 1 m"
    assert w.tick == 0, "a refused batch changes nothing"


# ---------------------------------------------------------------- item 15: API


def test_force_at_probes_without_stepping():
    w = nh.NanoWorld(START)
    p = (3.1e-9, 3e-9, 0.8e-9)
    f = w.force_at(p)
    assert f.shape == (3,) and f[2] < 0.0
    assert w.tick == 0 and w.contact is None
    r = w.step(p)
    assert np.array_equal(r["force"], f)
    with pytest.raises(ValueError):
        w.force_at((float("nan"), 0.0, 0.0))


def test_bricks_and_brick_use_the_same_keys():
    bw = nh.BrickWorld({"bricks": [{"center_m": [0.0, 0.0, 0.03]}]})
    one = bw.brick(0)
    many = bw.bricks
    for k in ("position_m", "orientation_xyzw", "half_extents_m", "velocity_m_per_s", "held", "sleeping"):
        assert k in one and k in many, k
        assert np.array_equal(np.asarray(many[k])[0], np.asarray(one[k])), k
    assert isinstance(bw.awake_brick_count, int)


def test_add_brick_with_velocity_and_friction_slides_v2_over_2_mu_g():
    bw = nh.BrickWorld()
    i = bw.add_brick((0.0, 0.0, 0.03), velocity_m_per_s=(1.0, 0.0, 0.0), friction=0.0, mass_kg=2.0)
    out = bw.run(np.tile([1.5, 1.5, 1.0], (1500, 1)))
    x = out["brick_position_m"][-1, i, 0]
    assert x == pytest.approx(1.0 / (2 * 0.3 * 9.81), rel=0.02)  # mean friction (0.6 + 0) / 2
    assert out["brick_position_m"].shape == (1500, 1, 3)
    assert out["brick_orientation_xyzw"].shape == (1500, 1, 4)
    assert np.array_equal(out["brick_position_m"][-1], bw.bricks["position_m"])
    with pytest.raises(ValueError) as e:
        bw.add_brick((0.5, 0.0, 0.03), restitution=2.0)
    assert str(e.value) == "parameter `brick.restitution` = 2 is out of range: allowed [0, 1]"


def test_long_batches_stop_on_ctrl_c(sigint_raises):
    zone = {"min_m": [-0.6, -0.3], "max_m": [-0.3, 0.3], "height_m": 0.5, "spawn_m": [-0.45, 0.0]}
    bw = nh.BrickWorld({"loading_zone": zone})
    bw.add_brick((0.0, 0.0, 0.03))
    timer = threading.Timer(0.3, _thread.interrupt_main)
    t0 = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        bw.run_wall_script((0.5, 0.5, 0.3), max_ticks=0, settle_ticks=10_000_000)
    elapsed = time.perf_counter() - t0
    timer.cancel()
    assert elapsed < 10.0, elapsed
    assert 0 < bw.tick < 10_000_000 and bw.tick % 10_000 == 0, bw.tick


def test_trap_waist_and_dt_never_give_nan():
    with pytest.raises(ValueError) as e:
        nh.GaussianTrap(1e-15, (1e-200, 3e-7), 1e-15)
    assert str(e.value) == (
        "waist[0] = 1e-200 is out of range: allowed a waist whose stiffness "
        "2*ln2*depth/waist**2 is finite (m)"
    )
    trap = nh.paper_trap()
    with pytest.raises(ValueError) as e:
        trap.displacement([[1e-7, 0.0]], (0.0, 0.0), 1e300, method="rk4")
    assert str(e.value).startswith("displacement[0] is not finite: dt = 1e300 s"), str(e.value)


# ---------------------------------------------------------------- item 20: long work stops on Ctrl-C


def test_a_long_session_stops_on_ctrl_c_with_a_complete_recording(tmp_path, sigint_raises):
    out = tmp_path / "interrupted.mcap"
    threading.Timer(0.5, _thread.interrupt_main).start()
    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        nh.run_scene("wall", seconds=3600.0, out=str(out))
    assert time.perf_counter() - t0 < 30.0
    # The session ended after its current tick: the file is complete, not truncated.
    a = nh.read_recording(str(out))
    n = len(a["tick"])
    assert 0 < n < 3_600_000
    assert np.array_equal(a["tick"], np.arange(n))


def test_a_house_script_step_too_small_for_memory_names_the_bound():
    w = nh.NanoWorld(START)
    with pytest.raises(ValueError) as e:
        w.house_script(1e-15)
    msg = str(e.value)
    assert msg.startswith("step_m = 1e-15 is out of range: allowed ")
    assert "<= step_m <= 1e-6 m for this house (its path is " in msg
    assert msg.endswith(" m long; at most 10000000 samples)")


def test_tick_map_substeps_are_bounded_where_every_call_runs_hundreds_of_flows():
    trap = nh.paper_trap()
    with pytest.raises(ValueError) as e:
        nh.working_envelope(trap, (0.0, 0.0), nh.PAPER_DT, substeps=10_000_000)
    assert str(e.value) == "substeps = 10000000 is out of range: allowed 1 ..= 10000"
    # One flow may take many more (displacement is one flow per offset).
    d = trap.displacement([(0.0, 0.0)], (0.0, 0.0), nh.PAPER_DT, method="rk4", substeps=20_000)
    assert np.all(np.isfinite(d))



def test_a_long_envelope_stops_on_ctrl_c(sigint_raises):
    # A 3D envelope of 40962 rays marched in steps of 0.01 waist: tens of seconds when left
    # alone; Ctrl-C stops it at the next flow.
    t3 = nh.GaussianTrap(1e-15, (600e-9, 300e-9), 1e-15, axial_waist=1.5e-6)
    threading.Timer(0.5, _thread.interrupt_main).start()
    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        nh.working_envelope_3d(t3, (0.0, 0.0, 0.0), nh.PAPER_DT, level=6, step=0.01)
    assert time.perf_counter() - t0 < 60.0
    # The next call is not affected.
    assert len(nh.working_envelope(nh.paper_trap(), (0.0, 0.0), nh.PAPER_DT)) > 10
