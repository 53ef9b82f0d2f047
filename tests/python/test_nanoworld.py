"""nanohaptics.NanoWorld and force_distance_curve: numbers from the nano world (nanoworld)."""

import copy

import numpy as np
import pytest

import nanohaptics as nh


def single_atom(mode):
    """One substrate atom, nothing else: the tip-substrate law alone."""
    p = nh.nano_params(mode)
    p["substrate"]["nx"] = 1
    p["substrate"]["ny"] = 1
    p["loading_zone"] = None
    p["initial_atoms_xy_m"] = []
    p["house"] = None
    return p


def tip_law(params):
    return nh.NanoWorld((0.0, 0.0, 50e-9), params=params).laws["tip_substrate"]


# ---------------------------------------------------------------- game mode curves


def test_game_snap_force_and_tenfold_pull_off():
    p = single_atom("game")
    law = tip_law(p)
    assert law["snap_force_n"] == pytest.approx(0.3e-9, abs=1e-21)  # the paper's ~0.3 nN
    assert law["pull_off_n"] == 10.0 * law["snap_force_n"]
    steps = 20_000
    h = 2e-9 / steps
    c = nh.force_distance_curve(p, far_gap_m=2e-9, near_gap_m=0.0, steps=steps)
    assert c["approach_gap"].shape == (steps + 1,) and c["retract_force"].shape == (steps + 1,)
    i, j = c["snap_index"], c["pull_off_index"]
    # The snap happens on the first tick inside the snap gap.
    assert c["approach_gap"][i] < law["snap_gap_m"] <= c["approach_gap"][i - 1]
    # Before it the force is the pair law A(1/z² - 1/w²), pointing down.
    z = c["approach_gap"][i - 1]
    a, w = law["coef_n_m2"], law["cutoff_gap_m"]
    assert -c["approach_force"][i - 1] == pytest.approx(a / z**2 - a / w**2, rel=1e-12)
    # No force beyond the activation gap.
    assert np.all(c["approach_force"][c["approach_gap"] >= w] == 0.0)
    # Release at k·z = 10 × snap; the strongest pull felt is 10 × snap within one step.
    max_pull = -c["retract_force"][:j].min()
    assert law["pull_off_n"] - law["stiffness_n_per_m"] * h * 1.000001 <= max_pull < law["pull_off_n"]
    assert max_pull / law["snap_force_n"] == pytest.approx(10.0, abs=1e-3)
    assert c["retract_gap"][j] == pytest.approx(law["pull_off_n"] / law["stiffness_n_per_m"], abs=h)


def test_game_hysteresis_loop_area_matches_the_analytic_integral():
    p = single_atom("game")
    law = tip_law(p)
    a, w, zs, k = law["coef_n_m2"], law["cutoff_gap_m"], law["snap_gap_m"], law["stiffness_n_per_m"]
    zpo = law["pull_off_n"] / k
    exact = 0.5 * k * (zpo**2 - zs**2) - (a * (1 / zs - 1 / w) - a * (w - zs) / w**2)
    errs = []
    for steps in (4_000, 16_000):
        c = nh.force_distance_curve(p, far_gap_m=2e-9, near_gap_m=0.0, steps=steps)
        errs.append(abs(c["hysteresis"] - exact) / exact)
    assert errs[1] < 2e-3
    assert errs[0] / errs[1] == pytest.approx(4.0, rel=0.4)  # first order in the step


def test_pull_off_ratio_is_a_runtime_parameter():
    p = single_atom("game")
    world = nh.NanoWorld((0.0, 0.0, 2e-9), params=p)
    q = copy.deepcopy(p)
    q["interaction"]["game"]["pull_off_ratio"] = 4.0
    world.set_params(q)
    law = world.laws["tip_substrate"]
    assert law["pull_off_n"] == pytest.approx(4.0 * law["snap_force_n"], rel=1e-15)
    assert world.params == q
    c = nh.force_distance_curve(q, far_gap_m=2e-9, near_gap_m=0.0, steps=20_000)
    assert -c["retract_force"][: c["pull_off_index"]].min() / law["snap_force_n"] == pytest.approx(4.0, abs=1e-3)


# ---------------------------------------------------------------- physical mode


def test_physical_mode_reproduces_the_tenfold_pull_off():
    p = single_atom("physical")
    ph = p["interaction"]["physical"]
    A, R, z0, kc = 1e-19, 20e-9, ph["contact_gap_m"], ph["cantilever_stiffness_n_per_m"]
    assert kc == pytest.approx(A * R / (95 * z0**3), rel=1e-15)
    law = tip_law(p)
    z_jtc = (A * R / (3 * kc)) ** (1 / 3)
    assert law["snap_gap_m"] == pytest.approx(z_jtc, rel=1e-12)
    assert law["snap_force_n"] == pytest.approx(A * R / (6 * z_jtc**2), rel=1e-12)
    assert law["pull_off_n"] == pytest.approx(A * R / (6 * z0**2), rel=1e-12)  # DMT
    assert law["pull_off_n"] / law["snap_force_n"] == pytest.approx((95 / 3) ** (2 / 3), rel=1e-12)
    steps = 20_000
    c = nh.force_distance_curve(p, far_gap_m=3e-9, near_gap_m=0.0, steps=steps)
    i, j = c["snap_index"], c["pull_off_index"]
    # Jump to contact with the cantilever base at 1.5 z_jtc.
    assert c["approach_gap"][i] == pytest.approx(1.5 * z_jtc, abs=2 * 3e-9 / steps)
    # The measured pull-off is the DMT force; the largest attraction before the jump
    # approaches A·R/(6 z_jtc²) as sqrt of the step (fold), here within 3 %.
    assert -c["retract_force"][:j].min() == pytest.approx(law["pull_off_n"], rel=1e-3)
    assert -c["approach_force"][:i].min() == pytest.approx(law["snap_force_n"], rel=0.03)


# ---------------------------------------------------------------- stepping a world


def test_force_before_contact_is_the_pair_law_over_one_atom():
    p = single_atom("game")
    law = tip_law(p)
    rt, rs = 0.3e-9, 0.15e-9
    world = nh.NanoWorld((0.0, 0.0, 5e-9), params=p)
    far = world.step((0.0, 0.0, rt + rs + 0.7e-9))
    assert np.array_equal(far["force"], [0.0, 0.0, 0.0]) and far["events"] == []
    gap = 0.4e-9
    near = world.step((0.0, 0.0, rt + rs + gap))
    a, w = law["coef_n_m2"], law["cutoff_gap_m"]
    assert near["force"][2] == pytest.approx(-(a / gap**2 - a / w**2), rel=1e-12)
    assert near["force"][0] == 0.0 and near["force"][1] == 0.0
    assert world.contact is None
    snap = world.step((0.0, 0.0, rt + rs + 0.1e-9))
    assert [e["type"] for e in snap["events"]] == ["snap"]
    e = snap["events"][0]
    # serde's form of nanoworld::Event, as a recording's event detail has it
    assert e == {"type": "snap", "member": "tip", "target": {"substrate_atom": 0},
                 "pair": "tip_substrate", "gap_m": e["gap_m"], "snap_force_n": law["snap_force_n"]}
    c = world.contact
    assert c["member"] == "tip" and c["target"] == {"substrate_atom": 0}
    assert c["pair"] == "tip_substrate"
    np.testing.assert_allclose(c["normal"], [0.0, 0.0, 1.0], atol=1e-12)
    assert world.tick == 3 and world.time == pytest.approx(3e-3)


def test_house_session_builds_the_house_and_replays_bit_for_bit():
    start = (3e-9, 3e-9, 2e-9)
    w1 = nh.NanoWorld(start)
    path = w1.house_script(step_m=2e-12)
    assert path.shape[1] == 3 and len(path) > 100_000
    r1 = w1.run(path)
    assert w1.house["complete"] and w1.house["score"] == 7
    assert r1["score"][-1] == 7 and r1["score"].dtype == np.int64
    types = [e["type"] for _, e in r1["events"]]
    assert types.count("house_complete") == 1
    assert types.count("atom_transferred") == 7  # each atom left on the atom below its slot
    assert types.count("slot_filled") == 7
    # Filled slots hold atoms within the tolerance.
    h = w1.house
    for slot, atom in enumerate(h["filled"]):
        assert np.linalg.norm(w1.atoms[atom] - h["slots"][slot]) <= h["tolerance_m"]
    # The device force never exceeds the limit.
    fmax = w1.device["max_force_n"]
    assert np.all(np.linalg.norm(r1["force"], axis=1) <= fmax * (1 + 1e-12))
    assert np.all(np.isfinite(r1["force"]))
    # Same inputs, same bits.
    w2 = nh.NanoWorld(start)
    r2 = w2.run(path)
    for k in ("force", "unlimited_force", "tip", "anchored", "carried", "score"):
        assert np.array_equal(r1[k], r2[k]), k
    assert np.array_equal(w1.atoms, w2.atoms)


def test_run_equals_repeated_step():
    start = (3e-9, 3e-9, 2e-9)
    path = nh.NanoWorld(start).house_script()[:8000]
    a = nh.NanoWorld(start)
    ra = a.run(path)
    b = nh.NanoWorld(start)
    forces = np.array([b.step(p)["force"] for p in path])
    assert np.array_equal(ra["force"], forces)
    assert np.array_equal(a.tip_position, b.tip_position) and a.carried == b.carried


def test_heavy_atoms_feel_their_weight():
    # At atomic masses gravity is ~14 orders below vdW; a 1e-12 kg atom on the tip weighs 9.81 pN.
    p = nh.nano_params("game")
    p["atoms"]["mass_kg"] = 1e-12
    p["inertia"] = False
    world = nh.NanoWorld((3e-9, 3e-9, 2e-9), params=p)
    path = world.house_script()
    r = world.run(path[:7000])
    k = next(k for k, e in r["events"] if e["type"] == "atom_attached")
    free = (r["carried"] == 1) & ~r["anchored"]
    free[: k + 1] = False
    idx = np.nonzero(free)[0]
    # Far from every surface the only force is the weight -m g.
    far = idx[np.argmax(r["tip"][idx, 2])]
    assert r["force"][far, 2] == pytest.approx(-1e-12 * 9.81, rel=1e-9)


def test_params_round_trip_and_bad_params():
    for mode in ("game", "physical"):
        p = nh.nano_params(mode)
        assert nh.NanoWorld((0, 0, 5e-9), params=p).params == p
    bad = nh.nano_params("game")
    bad["interaction"]["game"]["pairs"]["tip_atom"]["snap_gap_m"] = 7e-10
    with pytest.raises(ValueError) as e:
        nh.NanoWorld((0, 0, 5e-9), params=bad)
    assert str(e.value) == (
        "interaction.game.pairs.tip_atom.snap_gap_m = 7e-10 is out of range: "
        "allowed 0 < value < activation_gap_m = 6e-10"
    )
    unknown = nh.nano_params("game")
    unknown["tip"]["colour"] = "teal"
    with pytest.raises(ValueError, match=r"^params: unknown field `colour`, expected `radius_m`"):
        nh.NanoWorld((0, 0, 5e-9), params=unknown)
    with pytest.raises(ValueError) as e:
        nh.NanoWorld((0, 0, 5e-9), params="quantum")
    assert str(e.value) == 'params = "quantum": allowed "game", "physical" or a dict of the scene table'


def test_step_and_curve_errors_name_the_argument():
    world = nh.NanoWorld((0, 0, 5e-9))
    cases = [
        (lambda: nh.NanoWorld((0, 0)), "start: expected shape (3,), got (2,)"),
        (lambda: world.step((0, 0, float("nan"))), "position[2] = NaN is out of range: allowed finite (m)"),
        (lambda: world.step((0, 0, 5e-9), dt_s=0.0), "dt_s = 0 is out of range: allowed 1e-9 <= dt_s <= 1 s"),
        (lambda: world.run(np.zeros((4, 2))), "positions: expected shape (N, 3), got (4, 2)"),
        (
            lambda: nh.force_distance_curve(far_gap_m=2e-6),
            "far_gap_m = 2e-6 is out of range: allowed 0 < value <= 1e-6 m",
        ),
        (
            lambda: nh.force_distance_curve(near_gap_m=3e-9),
            "near_gap_m = 3e-9 is out of range: allowed finite and < far_gap_m = 2e-9 m",
        ),
        (lambda: nh.force_distance_curve(steps=1), "steps = 1 is out of range: allowed 2 ..= 10000000"),
        (lambda: world.house_script(step_m=0.0), "step_m = 0 is out of range: allowed 0 < step_m <= 1e-6 m"),
        (lambda: nh.nano_params("quantum"), 'mode = "quantum": allowed "game", "physical"'),
    ]
    for fn, msg in cases:
        with pytest.raises(ValueError) as e:
            fn()
        assert str(e.value) == msg
    # Geometry is fixed for the life of a world.
    p = world.params
    p["tip"]["radius_m"] = 0.4e-9
    with pytest.raises(ValueError) as e:
        world.set_params(p)
    assert str(e.value) == (
        "tip.radius_m cannot change at run time (it fixes the geometry); build a new World instead"
    )
    # A failed batch leaves the world untouched: rows are checked before the first tick.
    before = world.tick
    with pytest.raises(ValueError):
        world.run([[0, 0, 5e-9], [0, 0, float("inf")]])
    assert world.tick == before


def test_issue12_limits_come_from_the_device():
    start = (3e-9, 3e-9, 2e-9)
    assert nh.NanoWorld(start).device == {"max_force_n": 8e-9, "max_stiffness_n_per_m": 20.0}
    assert nh.NanoWorld(start, params="physical").device == {"max_force_n": 8e-8, "max_stiffness_n_per_m": 30.0}
    w = nh.NanoWorld(start, device={"max_force_n": 1e-11, "max_stiffness_n_per_m": 20.0})
    r = w.step((3e-9, 3e-9, 0.7e-9))
    assert r["saturated"] and np.linalg.norm(r["force"]) == pytest.approx(1e-11, rel=1e-12)
    p = nh.nano_params()
    assert "max_force_n" not in p
    p["max_force_n"] = 1e-8
    with pytest.raises(ValueError) as e:
        nh.NanoWorld(start, params=p)
    assert "`max_force_n` is no longer a nanoworld parameter: the limit now comes from the device" in str(e.value)
    # A stiffest spring beyond the device's stiffness is refused by name.
    with pytest.raises(ValueError) as e:
        nh.NanoWorld(start, device={"max_force_n": 8e-9, "max_stiffness_n_per_m": 1.0})
    assert str(e.value).startswith("interaction.game.pairs.tip_substrate.stiffness_n_per_m = 2 is out of range")
    # The old unit spelling of gravity still loads.
    q = nh.nano_params()
    q["gravity_m_s2"] = q.pop("gravity_m_per_s2")
    assert nh.NanoWorld(start, params=q).params["gravity_m_per_s2"] == 9.81
