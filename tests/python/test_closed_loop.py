"""A device and a hand in the loop from Python (issue 22): DeviceModel, closed_loop around a
Session, and check_closed_loop."""

import numpy as np
import pytest

import nanohaptics as nh


def test_a_loose_hand_yields_to_a_constant_push_by_f_over_k():
    dev = nh.DeviceModel("falcon", grip="loose", counts=False)
    for _ in range(3000):
        dev.advance(1e-3, [0.0, 0.0, 1.0], [0.0, 0.0, 0.0])
    # 1 N against the loose grip's 300 N/m: 3.33 mm; the motors did F·x of work on the hand.
    assert dev.position[2] == pytest.approx(1.0 / 300.0, abs=1e-6)
    assert dev.energy_to_hand_j == pytest.approx(1.0 / 300.0, rel=1e-3)
    assert dev.time_s == pytest.approx(3.0)


def test_the_encoders_report_whole_counts():
    dev = nh.DeviceModel("falcon", grip="firm")
    q = dev.specs["encoder_quantum_m"]
    assert q == pytest.approx(0.0635e-3)
    for _ in range(100):
        dev.advance(1e-3, [0.0, 0.0, 0.0], [0.0012345, -0.0007, 0.0])
    r = dev.reading / q
    assert np.all(r == np.round(r))
    assert np.all(np.abs(dev.reading - dev.position) <= q / 2 + 1e-15)
    assert dev.specs["grip"] == {"stiffness_n_per_m": 1000.0, "damping_n_s_per_m": 8.0, "mass_kg": 0.0}


def test_bad_arguments_name_the_argument():
    with pytest.raises(ValueError, match=r"model: unknown device model `omega7` \(allowed: falcon, touch, delta3, inverse3\)"):
        nh.DeviceModel("omega7")
    with pytest.raises(ValueError, match=r"^grip: grip `k` = 0 is out of range: allowed 0 < k ≤ 10000 N/m$"):
        nh.DeviceModel(grip="k=0,b=1")
    dev = nh.DeviceModel()
    with pytest.raises(ValueError, match=r"^dt_s = -0.001 is out of range: allowed 0 < dt_s ≤ 1 s$"):
        dev.advance(-1e-3, [0, 0, 0], [0, 0, 0])
    with pytest.raises(ValueError, match="force: expected 3 numbers, got 4"):
        dev.advance(1e-3, [0, 0, 0, 1], [0, 0, 0])
    with pytest.raises(ValueError, match=r"^intent_position\[1\] must be finite, got NaN$"):
        dev.advance(1e-3, [0, 0, 0], [0, np.nan, 0])
    with pytest.raises(ValueError, match=r"stiffness: expected a \(3, 3\) array"):
        dev.advance(1e-3, [0, 0, 0], [0, 0, 0], stiffness=np.zeros((2, 2)))


def test_closed_loop_around_a_session_settles_where_the_hand_and_the_wall_balance():
    # The wall (3000 N/m on a Falcon) is at z = -5 mm; the hand wants 3 mm into it: the
    # stylus settles where 300 N/m x (3 mm - d) = 3000 N/m x d, d = 0.273 mm, F = 0.82 N.
    dev = nh.DeviceModel("falcon", grip="loose", counts=False, start=[0.0, 0.0, 0.0])

    def path(t):
        z = -0.008 * min(t / 0.5, 1.0)
        return [0.0, 0.0, z], [0.0, 0.0, -0.016 if t < 0.5 else 0.0]

    with nh.Session("wall") as s:
        a = nh.closed_loop(s, dev, path, seconds=2.0)
    f = a["force_n"][-200:, 2]
    d = 300.0 * 0.003 / 3300.0
    assert f.mean() == pytest.approx(3000.0 * d, rel=0.01)
    assert np.ptp(f) < 0.01, "settled, no buzz"
    assert a["reading_m"].shape == (2000, 3)
    with pytest.raises(ValueError, match="seconds = 0 is out of range"):
        with nh.Session("wall") as s2:
            nh.closed_loop(s2, dev, path, seconds=0)


def test_check_closed_loop_finds_the_papers_buzz_and_the_couplings_calm():
    coupled = nh.check_closed_loop("brickworld", model="falcon", grip="loose")
    assert coupled["stable"] and coupled["undeclared_jumps"] == 0
    assert coupled["hf_fraction"] < 0.1
    paper = nh.resolve_scene("brickworld", overrides={"brickworld.params.inertia": "paper"})
    buzz = nh.check_closed_loop(paper, model="falcon", grip="loose")
    assert not buzz["stable"]
    assert buzz["undeclared_jumps"] > 1000 and buzz["hf_fraction"] > 0.5
    with pytest.raises(ValueError, match="seconds = -1 is out of range"):
        nh.check_closed_loop("wall", seconds=-1)


def test_brick_world_inertia_modes_from_python():
    w = nh.BrickWorld()
    w.set_inertia("paper")
    w.set_inertia(True)
    w.set_inertia("off")
    with pytest.raises(ValueError, match=r"inertia = 'heavy' is not allowed"):
        w.set_inertia("heavy")
