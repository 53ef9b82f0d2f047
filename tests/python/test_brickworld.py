"""nanohaptics.BrickWorld: numbers from the macro world (brickworld, rapier)."""

import math

import numpy as np
import pytest

import nanohaptics as nh

PARK = (0.8, 0.8, 1.0)  # cursor far from everything
HZ = 0.03  # default brick half height (m)


def test_free_fall_then_rest_on_the_ground():
    z0 = 0.5
    w = nh.BrickWorld({"restitution": 0.0, "sleeping": False, "bricks": [{"center_m": [0.0, 0.0, z0]}]})
    g, dt = 9.81, w.params["dt_s"]
    z = []
    for _ in range(600):
        w.step(PARK)
        z.append(w.brick(0)["position_m"][2])
    z = np.array(z)
    t = dt * np.arange(1, len(z) + 1)
    fall = z0 - 0.5 * g * t**2
    before = fall > HZ + 0.02
    # Semi-implicit Euler: error at most g·dt·t (first order in dt).
    assert np.all(np.abs(z[before] - fall[before]) <= g * dt * t[before] + 1e-9)
    # Then it lies on the ground: centre at the half height.
    assert z[-1] == pytest.approx(HZ, abs=1e-3)
    t_hit = t[np.argmax(z <= HZ + 1e-3)]
    assert t_hit == pytest.approx(math.sqrt(2 * (z0 - HZ) / g), abs=3 * dt)


def test_bounce_height_ratio_is_e_squared():
    e, drop = 0.5, 0.5
    w = nh.BrickWorld({"restitution": e, "sleeping": False, "bricks": [{"center_m": [0, 0, HZ + drop]}]})
    hit, apex = False, 0.0
    for _ in range(4000):
        w.step(PARK)
        b = w.brick(0)
        bottom, vz = b["position_m"][2] - HZ, b["velocity_m_per_s"][2]
        hit = hit or vz > 0.0
        if hit:
            apex = max(apex, bottom)
            if vz < 0.0:
                break
    assert apex / drop == pytest.approx(e * e, rel=0.03)


def test_proxy_spring_against_the_ground():
    w = nh.BrickWorld()
    r = w.params["proxy_radius_m"]
    k = w.params["proxy_stiffness_n_per_m"]
    w.step((0.0, 0.0, 0.1))
    rep = w.step((0.0, 0.0, -0.001))
    # The proxy stays on the surface (within a few µm of skin); the device feels
    # the spring k·(proxy − cursor), upward.
    pz = w.proxy_position[2]
    assert pz == pytest.approx(r, abs=5e-6)
    assert rep["force_n"][2] == pytest.approx(k * (pz + 0.001), rel=1e-9)
    assert rep["force_n"][0] == 0.0 and rep["force_n"][1] == 0.0
    assert rep["stiffness_n_per_m"] == k
    # Deeper: the force is scaled down to the Falcon's 8 N (9 N before issue 12), direction
    # kept, flagged.
    deep = w.step((0.0, 0.0, -0.05))
    assert deep["saturated"] and deep["force_n"][2] == pytest.approx(8.0, rel=1e-12)
    assert deep["spring_force_n"][2] == pytest.approx(k * (w.proxy_position[2] + 0.05), rel=1e-9)


def _grab_and_lift(w, lift_z=0.3, hold_ticks=600):
    """Touch the brick at the origin from above, press centre, lift, hold still."""
    top = 2 * HZ + w.params["proxy_radius_m"]
    path = np.concatenate(
        [
            np.linspace([0, 0, 0.2], [0, 0, top + 0.001], 300),
            np.tile([0, 0, top + 0.001], (50, 1)),
            np.linspace([0, 0, top + 0.001], [0, 0, lift_z], 400),
            np.tile([0, 0, lift_z], (hold_ticks, 1)),
        ]
    )
    buttons = np.zeros((len(path), 4), dtype=bool)
    buttons[320:, 0] = True  # hold the centre button from tick 320 on
    return w.run(path, buttons)


def test_a_brick_carried_through_the_coupling_weighs_m_g():
    # The default: the brick hangs on the virtual coupling; held still, the hand feels M g
    # through it (issue 22: within 1 %), and no separate weight or inertia term.
    w = nh.BrickWorld({"bricks": [{"center_m": [0, 0, HZ]}]})
    assert w.params["inertia"] == "coupling"
    r = _grab_and_lift(w, hold_ticks=2000)
    m, g = w.params["brick_mass_kg"], w.params["gravity_m_per_s2"]
    assert r["force"][-1][2] == pytest.approx(-m * g, rel=0.01)
    np.testing.assert_array_equal(r["coupling_force"][-1], r["force"][-1])
    np.testing.assert_array_equal(r["weight_force"][-1], [0, 0, 0])
    # The coupling's stiffness (0.3 of the Falcon's 3000 N/m) is what the device renders.
    assert r["stiffness"][-1] == pytest.approx(900.0)


def test_weight_of_a_carried_brick_is_m_g():
    # The paper's rigid carry: weight −M g and inertia −M a as separate terms.
    w = nh.BrickWorld({"bricks": [{"center_m": [0, 0, HZ]}], "inertia": "paper"})
    r = _grab_and_lift(w)
    assert any(e["type"] == "grabbed" and e["brick"] == 0 for _, e in r["events"])
    assert r["held"][-1] == 0 and w.held_brick == 0
    m, g = w.params["brick_mass_kg"], w.params["gravity_m_per_s2"]
    # Held still in free space: only the weight, −M g along z (inertia is zero at rest).
    np.testing.assert_allclose(r["weight_force"][-1], [0, 0, -m * g], rtol=1e-12)
    np.testing.assert_allclose(r["force"][-1], [0, 0, -m * g], rtol=1e-9, atol=1e-9)
    # Run-time switches change what is felt.
    w.set_brick_mass(0.8)
    assert w.step((0, 0, 0.3), {"center": True})["force_n"][2] == pytest.approx(-0.8 * g, rel=1e-9)
    w.set_brick_mass(1.0)  # 9.81 N: more than the Falcon's 8 N, scaled down and flagged
    over = w.step((0, 0, 0.3), {"hold": True})  # the grip's own name; "center" still works
    assert over["saturated"] and over["force_n"][2] == pytest.approx(-8.0, rel=1e-12)
    assert over["weight_force_n"][2] == pytest.approx(-9.81, rel=1e-12)
    w.set_gravity(0.0)
    assert w.step((0, 0, 0.3), {"center": True})["force_n"] == pytest.approx([0, 0, 0], abs=1e-9)
    # Release: the brick falls and lands on the ground.
    rel = w.step((0, 0, 0.3))
    assert [e["type"] for e in rel["events"]] == ["released"]
    assert w.held_brick is None


def test_inertia_of_a_carried_brick_is_minus_m_a():
    w = nh.BrickWorld({"bricks": [{"center_m": [0, 0, HZ]}], "gravity_m_per_s2": 0.0, "inertia": "paper"})
    _grab_and_lift(w, hold_ticks=50)
    # Accelerate the carried brick along x with a = 2 m/s²: x = a t²/2.
    a, dt = 2.0, w.params["dt_s"]
    t = dt * np.arange(1, 301)
    path = np.column_stack([0.5 * a * t**2, np.zeros_like(t), np.full_like(t, 0.3)])
    r = w.run(path, (1, 0, 0, 0))
    m = w.params["brick_mass_kg"]
    # The paper's stencil is exact for quadratic motion once it has five samples.
    np.testing.assert_allclose(r["acceleration"][10:, 0], a, rtol=1e-6)
    np.testing.assert_allclose(r["inertia_force"][10:, 0], -m * a, rtol=1e-6)


def _wall_params():
    h = [0.1, 0.05, 0.03]
    step = 2 * h[0] + 0.004
    slot = lambda c, rz=0.0: {"center_m": c, "rotation_deg": [0.0, 0.0, rz]}
    return {
        "loading_zone": {"min_m": [-0.6, -0.3], "max_m": [-0.3, 0.3], "height_m": 0.5, "spawn_m": [-0.45, 0.0]},
        "blueprint": {
            "slots": [
                slot([0.0, 0.0, h[2]]),
                slot([step, 0.0, h[2]]),
                slot([step / 2, 0.0, 3 * h[2]]),
                slot([2 * step + h[1] + 0.05, h[0] - h[1], h[2]], 90.0),
            ]
        },
    }


def test_scripted_wall_fills_every_slot_and_replays_bit_for_bit():
    a = nh.BrickWorld(_wall_params())
    ra = a.run_wall_script((0.3, -0.4, 0.35))
    assert a.score == {"filled": 4, "total": 4}
    assert ra["filled"][-1] == 4
    types = [e["type"] for _, e in ra["events"]]
    assert types.count("spawned") == 4 and "rotated" in types
    assert all(s["filled_by"] is not None for s in a.slots)
    assert np.all(np.linalg.norm(ra["force"], axis=1) <= 9.0 * (1 + 1e-12))
    b = nh.BrickWorld(_wall_params())
    rb = b.run_wall_script((0.3, -0.4, 0.35))
    for k in ("force", "proxy", "cursor", "buttons", "held", "filled"):
        assert np.array_equal(ra[k], rb[k]), k
    assert np.array_equal(a.bricks["position_m"], b.bricks["position_m"])
    assert np.array_equal(a.bricks["orientation_xyzw"], b.bricks["orientation_xyzw"])
    # Replaying the recorded inputs through run() gives the same bits again.
    c = nh.BrickWorld(_wall_params())
    rc = c.run(ra["cursor"], ra["buttons"])
    assert np.array_equal(rc["force"], ra["force"])


def test_run_equals_repeated_step():
    p = {"bricks": [{"center_m": [0, 0, HZ]}]}
    path = np.linspace([0.0, 0.0, 0.2], [0.0, 0.0, 0.02], 400)
    a = nh.BrickWorld(p)
    ra = a.run(path)
    b = nh.BrickWorld(p)
    forces = np.array([b.step(x)["force_n"] for x in path])
    assert np.array_equal(ra["force"], forces)
    assert ra["penetration"].max() <= 1e-3  # the cursor never sinks into the brick


def test_bad_arguments_raise_value_error_naming_them():
    cases = [
        (lambda: nh.BrickWorld({"restitution": 1.5}), "parameter `restitution` = 1.5 is out of range: allowed [0, 1]"),
        (lambda: nh.BrickWorld(device="phantom"), 'device = "phantom": allowed falcon, touch, udp:HOST:PORT or udp:PORT'),
        (lambda: nh.BrickWorld().step((0, 0, 3.0)), "cursor input `position_m[2]` = 3 m is outside the workspace: allowed [-2, 2] m"),
        (lambda: nh.BrickWorld().step((0, 0)), "position_m: expected shape (3,), got (2,)"),
        (lambda: nh.BrickWorld().step((0, 0, 0.1), {"centre": True}), "buttons: unknown button \"centre\": allowed [\"hold\", \"turn_x\", \"turn_y\", \"turn_z\"] or [\"center\", \"rotate_x\", \"rotate_y\", \"rotate_z\"]"),
        (lambda: nh.BrickWorld().brick(3), "unknown brick id 3"),
        (lambda: nh.BrickWorld().set_restitution(-0.1), "parameter `restitution` = -0.1 is out of range: allowed [0, 1]"),
        (lambda: nh.BrickWorld().run([[0, 0, 0.1], [0, 0, float("nan")]]), "positions_m[1, 2] = NaN is out of range: allowed finite (m)"),
        (lambda: nh.BrickWorld().run([[0, 0, 0.1], [0, 0, 5.0]]), "positions_m[1]: cursor input `position_m[2]` = 5 m is outside the workspace: allowed [-2, 2] m"),
        (lambda: nh.BrickWorld().run_wall_script((0.3, -0.4, 0.35)), "loading_zone is missing: the wall script fetches bricks from it"),
    ]
    for fn, msg in cases:
        with pytest.raises(ValueError) as e:
            fn()
        assert str(e.value) == msg
    with pytest.raises(ValueError, match=r"^params: unknown field `gravity`, expected one of"):
        nh.BrickWorld({"gravity": 9.81})
    w = nh.BrickWorld()
    with pytest.raises(ValueError):
        w.run([[0, 0, 0.1], [0, 0, 5.0]])
    assert w.tick == 0  # a rejected batch steps nothing


def test_issue12_grip_keys_old_unit_names_and_falcon_limits():
    # The hand's grip commands by their new names and by the old button names: same session.
    a = nh.BrickWorld({"bricks": [{"center_m": [0, 0, HZ]}]})
    b = nh.BrickWorld({"bricks": [{"center_m": [0, 0, HZ]}]})
    down = np.linspace((0.0, 0.0, 0.2), (0.0, 0.0, 2 * HZ + 0.002), 200)
    a.run(down)
    b.run(down)
    ra = a.step(down[-1], {"hold": True})
    rb = b.step(down[-1], {"center": True})
    assert [e["type"] for e in ra["events"]][0] == "grabbed"
    assert ra["force_n"] == rb["force_n"] and a.held_brick == b.held_brick == 0
    # Parameter dicts with the old unit spelling load to the same parameters.
    old = nh.BrickWorld({"gravity_m_s2": 3.7, "proxy_stiffness_n_m": 800.0, "throw_min_speed_m_s": 0.4})
    new = nh.BrickWorld({"gravity_m_per_s2": 3.7, "proxy_stiffness_n_per_m": 800.0, "throw_min_speed_m_per_s": 0.4})
    assert old.params == new.params and new.params["gravity_m_per_s2"] == 3.7
    # The Falcon: 8 N, 3000 N/m; the old device key is still accepted.
    assert nh.BrickWorld().device == {"max_force_n": 8.0, "max_stiffness_n_per_m": 3000.0}
    d = nh.BrickWorld(device={"max_force_n": 5.0, "max_stiffness_n_m": 2000.0}).device
    assert d == {"max_force_n": 5.0, "max_stiffness_n_per_m": 2000.0}


def test_device_is_named_as_everywhere_in_the_wheel():
    # A Touch by name: its own limits (3.3 N, 400 N/m), with a proxy within its stiffness cap.
    w = nh.BrickWorld({"proxy_stiffness_n_per_m": 400.0}, device="touch")
    assert w.device == {"max_force_n": 3.3, "max_stiffness_n_per_m": 400.0}
    # Pressed 5 cm into the ground, the spring asks 20 N: the Touch renders 3.3 N.
    r = w.run(np.linspace((0.0, 0.0, 0.05), (0.0, 0.0, -0.05), 100))
    norms = np.linalg.norm(r["force"], axis=1)
    assert norms.max() <= 3.3 + 1e-12 and norms.max() > 3.2
    assert nh.BrickWorld(device="falcon").device == nh.BrickWorld().device
    # The Falcon's default 1000 N/m proxy is too stiff for a Touch: refused naming the field.
    with pytest.raises(ValueError, match=r"proxy_stiffness_n_per_m` = 1000 is out of range"):
        nh.BrickWorld(device="touch")
    # An unknown name: the same text as every other device= argument of the wheel.
    with pytest.raises(ValueError) as brick:
        nh.BrickWorld(device="phantom")
    with pytest.raises(ValueError) as session:
        nh.resolve_scene("wall", device="phantom")
    assert str(brick.value) == str(session.value) == 'device = "phantom": allowed falcon, touch, udp:HOST:PORT or udp:PORT'
    # A bridged device is a device in another process: not a brick world's.
    with pytest.raises(ValueError, match=r'^device = "udp:9870": the brick world renders to a model in this process'):
        nh.BrickWorld(device="udp:9870")
