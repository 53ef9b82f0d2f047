"""Issue 25, item 2: bad input that was still accepted or unclear — a working envelope of
unbounded work, params validated only in part, extra array elements dropped, and Python
arguments whose errors did not name them."""

import math

import numpy as np
import pytest

import nanohaptics as nh

ROOT = __import__("pathlib").Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"


# ---------------------------------------------------------------- bounded envelope work


def test_an_envelope_of_many_oscillations_is_refused_naming_the_limit():
    with pytest.raises(ValueError) as e:
        nh.working_envelope(nh.paper_trap(), [1e-12, 1e-12], 9.5e-5)
    assert str(e.value) == (
        "dt [s] = 9.5e-5 is out of range: allowed ≤ 6.4037e-6 s, 4 periods of the well's "
        "fastest oscillation (ω = 3.9247e6 rad/s); a longer tick folds the map so often that "
        "the envelope's boundary search grows without bound"
    )


def test_the_inverse_solve_refuses_the_envelope_s_tick_bound_quickly():
    # Issue 34: solve_trap ran for more than 20 s on this tick (62 oscillations); it now meets
    # the one bound of a tick's length (ot_envelope::tick_length) before sampling the map.
    import time

    start = time.perf_counter()
    with pytest.raises(ValueError) as e:
        nh.solve_trap(nh.paper_trap(), [-0.288, -0.070], 9.97e-5, [-3.6e-144, -2.3e-274])
    took = time.perf_counter() - start
    assert str(e.value).startswith(
        "dt [s] = 9.97e-5 is out of range: allowed ≤ 6.4037e-6 s, 4 periods of the well's "
        "fastest oscillation (ω = 3.9247e6 rad/s)"
    )
    # A hang guard, not a speed target: the refusal comes before any map is sampled (µs);
    # the hang it replaces ran for more than 20 s.
    assert took < 10.0, took


def test_a_tangled_tick_map_is_refused_and_the_default_one_is_not_tangled():
    trap = nh.paper_trap()
    # 8 fixed RK4 substeps over 5 µs (ω·h = 2.5 rad): the polynomial map folds where the
    # flow does not; its boundary search is refused before it starts.
    with pytest.raises(ValueError) as e:
        nh.working_envelope(trap, (0.0, 0.0), 5e-6, substeps=8)
    assert str(e.value) == (
        "physics: envelope boundary: segment pairs to test = 5.3854177e7 is out of range: "
        "allowed ≤ 2e6 (the images of the map's folds are tangled: take a shorter tick, a "
        "slower particle or a tick map with more substeps)"
    )
    # The default substeps grow with the tick (max(8, ⌈ω·Δt / 0.5⌉) = 40 here): within
    # 4.3 nm of the envelope of the converged adaptive tick map, whose reach is 2.65 µm.
    default = nh.working_envelope(trap, (0.0, 0.0), 5e-6)
    adaptive = nh.working_envelope(trap, (0.0, 0.0), 5e-6, method="adaptive")
    theta = np.linspace(0.0, 2.0 * np.pi, 512, endpoint=False)
    r_default = nh.polygon_radius(default, (0.0, 0.0), theta)
    r_adaptive = nh.polygon_radius(adaptive, (0.0, 0.0), theta)
    assert 2.64e-6 < r_adaptive.max() < 2.65e-6
    assert np.abs(r_default - r_adaptive).max() < 4.3e-9
    # At the paper's tick the default is still 8 substeps: the same polygon, bit for bit.
    assert np.array_equal(nh.working_envelope(trap, (0.05, 0.0), nh.PAPER_DT),
                          nh.working_envelope(trap, (0.05, 0.0), nh.PAPER_DT, substeps=8))


# ---------------------------------------------------------------- params validated whole


@pytest.mark.parametrize("edit, message", [
    (lambda p: p["loading_zone"]["min_xy_m"].__setitem__(0, math.nan),
     "loading_zone.min_xy_m[0] = NaN is out of range: allowed a finite number"),
    (lambda p: p["house"]["slots_m"][2].__setitem__(1, math.nan),
     "house.slots_m[2][1] = NaN is out of range: allowed a finite number"),
    (lambda p: p["initial_atoms_xy_m"][0].__setitem__(1, math.nan),
     "initial_atoms_xy_m[0][1] = NaN is out of range: allowed inside the substrate, "
     "0..=1.17e-8 x 0..=1.17e-8 m"),
    (lambda p: p["loading_zone"]["spawn_xy_m"].__setitem__(1, math.nan),
     "loading_zone.spawn_xy_m[1] = NaN is out of range: allowed inside the zone "
     "[1e-9, 3e-9] and inside the substrate, 0..=1.17e-8 x 0..=1.17e-8 m"),
])
def test_every_entry_point_validates_the_whole_params(edit, message):
    p = nh.nano_params()
    edit(p)
    for call in (lambda: nh.force_distance_curve(p),
                 lambda: nh.NanoWorld((3e-9, 3e-9, 2e-9), params=p),
                 lambda: nh.NanoWorld((3e-9, 3e-9, 2e-9)).set_params(p)):
        with pytest.raises(ValueError) as e:
            call()
        assert str(e.value) == message


# ---------------------------------------------------------------- fixed-length arrays


def _line_col(text: str, needle: str):
    for n, line in enumerate(text.splitlines(), 1):
        if needle in line:
            return n, line.index("[") + 1
    raise AssertionError(needle)


@pytest.mark.parametrize("scene, old, new", [
    ("wall.toml", "normal = [0.0, 0.0, 1.0]", "normal = [0.0, 0.0, 1.0, 5.0]"),
    ("wall.toml", "origin_m = [0.0, 0.0, 0.0]", "origin_m = [0.0, 0.0, 0.0, 7.0]"),
])
def test_an_extra_array_element_in_a_scene_is_refused_at_its_line(tmp_path, scene, old, new):
    text = (SCENES / scene).read_text()
    assert old in text
    bad = text.replace(old, new)
    path = tmp_path / scene
    path.write_text(bad)
    (tmp_path / "wall.script.toml").write_text((SCENES / "wall.script.toml").read_text())
    line, col = _line_col(bad, new)
    with pytest.raises(ValueError) as e:
        nh.resolve_scene(str(path))
    assert str(e.value) == (
        f"{path}:{line}:{col}: scene: invalid length 4, expected an array of 3 numbers"
    )


def test_an_extra_element_of_a_waypoint_is_refused_at_its_line(tmp_path):
    text = (SCENES / "wall.script.toml").read_text()
    i = text.index("position_mm = [")
    j = text.index("]", i)
    bad = text[:j] + ", 9.0" + text[j:]
    (tmp_path / "wall.script.toml").write_text(bad)
    (tmp_path / "wall.toml").write_text((SCENES / "wall.toml").read_text())
    line = bad[:i].count("\n") + 1
    col = bad[i:].index("[") + 1 + (i - (bad.rfind("\n", 0, i) + 1))
    with pytest.raises(ValueError) as e:
        nh.run_scene(str(tmp_path / "wall.toml"), seconds=0.1)
    assert str(e.value) == (
        f"{tmp_path / 'wall.script.toml'}:{line}:{col}: script: invalid length 4, expected "
        "an array of 3 numbers"
    )


def test_an_extra_element_in_a_params_dict_is_refused_by_name():
    p = nh.nano_params()
    p["loading_zone"]["min_xy_m"] = [0.0, 0.0, 1.0]
    with pytest.raises(ValueError) as e:
        nh.NanoWorld((3e-9, 3e-9, 2e-9), params=p)
    assert "loading_zone.min_xy_m" in str(e.value), str(e.value)
    assert "invalid length 3, expected an array of 2 numbers" in str(e.value), str(e.value)


# ---------------------------------------------------------------- arguments named


def test_integer_and_text_arguments_are_named():
    zone = {"min_m": [-0.6, -0.3], "max_m": [-0.3, 0.3], "height_m": 0.5, "spawn_m": [-0.45, 0.0]}
    bw = nh.BrickWorld({"loading_zone": zone})
    cases = [
        (lambda: bw.run_wall_script((0.5, 0.5, 0.3), max_ticks=-1), ValueError,
         "max_ticks = -1 is out of range: allowed 0 ..= 1000000000000"),
        (lambda: bw.run_wall_script((0.5, 0.5, 0.3), settle_ticks=2**70), ValueError,
         "settle_ticks = 1180591620717411303424 is out of range: allowed 0 ..= 1000000000000"),
        (lambda: bw.run_wall_script((0.5, 0.5, 0.3), max_ticks=1.5), TypeError,
         "max_ticks: expected an integer, got float"),
        (lambda: bw.run_wall_script((0.5, 0.5, 0.3), max_ticks=True), TypeError,
         "max_ticks: expected an integer, got bool"),
        (lambda: nh.nano_params(1), TypeError, "mode: expected a str, got int"),
        (lambda: nh.nano_params("x"), ValueError, 'mode = "x": allowed "game", "physical"'),
        (lambda: nh.render_audio("x.mcap", sample_rate=2**70), ValueError,
         "sample_rate = 1180591620717411303424 is out of range: allowed 8000–192000 Hz"),
        (lambda: nh.render_audio("x.mcap", sample_rate="fast"), TypeError,
         "sample_rate: expected an integer, got str"),
        (lambda: nh.paper_trap().trajectory((0, 0), (0, 0), 1e-6, -2), ValueError,
         "samples = -2 is out of range: allowed 2 ..= 10000000"),
    ]
    for call, kind, message in cases:
        with pytest.raises(kind) as e:
            call()
        assert str(e.value) == message
    # The named extractors keep the signatures' defaults visible.
    assert str(__import__("inspect").signature(nh.nano_params)) == "(mode='game')"
    assert nh.nano_params()["substrate"]["nx"] == 40


# ---------------------------------------------------------------- polygon_radius


def test_polygon_radius_of_a_square_and_its_errors():
    square = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    r = nh.polygon_radius(square, (0.0, 0.0), [0.0, math.pi / 4, math.pi / 2, math.pi])
    np.testing.assert_allclose(r, [1.0, math.sqrt(2.0), 1.0, 1.0], rtol=1e-15)
    # About an off-centre point: the ray along +x meets the edge x = 1 at distance 0.5.
    assert nh.polygon_radius(square, (0.5, 0.0), [0.0])[0] == 0.5
    with pytest.raises(ValueError) as e:
        nh.polygon_radius(square[:2], (0.0, 0.0), [0.0])
    assert str(e.value) == "polygon: expected at least 3 vertices, got 2"
    with pytest.raises(ValueError) as e:
        nh.polygon_radius(square, (0.0, 0.0), [0.0, math.inf])
    assert str(e.value) == "angles[1] = inf is out of range: allowed finite (rad)"
