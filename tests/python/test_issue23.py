"""ot-py is a thin layer (issue 23, item 3): operator names mean what they mean on the command
line (one parser, `OperatorChoice::parse`), dicts are serde's form of the crates' types (one
conversion), overrides are resolved by the engine (`haptic_loop::session::resolve`), and the
Python sources are files of the package (maturin's mixed layout), not text inside the extension.
"""

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

import nanohaptics as nh

ROOT = Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"
CLI = ROOT / "target" / "release" / "nanohaptics"
SAME = ("device_position_m", "device_force_n", "cursor_m", "state")


def cli() -> Path:
    if not CLI.is_file():
        pytest.skip("the nanohaptics program is not built (scripts/test.sh builds it before pytest)")
    return CLI


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([str(cli()), *map(str, args)], capture_output=True, text=True, timeout=300)


# ------------------------------------------------------------------------------ operator names


@pytest.mark.parametrize(
    "scene, name",
    [
        ("wall.toml", "hand"),
        ("wall.toml", "rigid"),
        ("wall.toml", "hand:stiffness_n_per_m=100,yield_force_n=0.5"),
        # the nano world's script says `operator = "rigid"`: "hand" plays it as it says
        ("nanoworld.toml", "hand"),
    ],
)
def test_an_operator_name_runs_the_same_session_in_python_and_on_the_command_line(tmp_path, scene, name):
    rec = tmp_path / "cli.mcap"
    p = run_cli("run", SCENES / scene, "--operator", name, "--seconds", "1", "--out", rec)
    assert p.returncode == 0, p.stderr
    on_cli = nh.read_recording(rec)
    in_python = nh.run_scene(SCENES / scene, operator=name, seconds=1.0)
    assert len(in_python["tick"]) == 1000
    for k in SAME:
        assert np.array_equal(on_cli[k], in_python[k]), k


@pytest.mark.parametrize(
    "name, message",
    [
        ("script", "operator `script` is not one of: rigid, hand, hand:key=value,..."),
        ("hand:stiffness_n_per_m=0", "script: `stiffness_n_per_m` = 0 is out of range: allowed 1 ≤ stiffness_n_per_m ≤ 10000"),
    ],
)
def test_a_refused_operator_name_is_refused_alike(name, message):
    with pytest.raises(ValueError) as e:
        nh.run_scene(SCENES / "wall.toml", operator=name)
    assert str(e.value) == message
    p = run_cli("run", SCENES / "wall.toml", "--operator", name)
    assert p.returncode != 0 and message in p.stderr, p.stderr


def test_hand_is_the_scripts_operator_and_a_dict_is_the_hand_with_those_values():
    wall = SCENES / "wall.toml"
    default = nh.run_scene(wall, seconds=0.5)
    hand = nh.run_scene(wall, operator="hand", seconds=0.5)
    rigid = nh.run_scene(wall, operator="rigid", seconds=0.5)
    soft = nh.run_scene(wall, operator="hand:stiffness_n_per_m=100", seconds=0.5)
    soft_dict = nh.run_scene(wall, operator={"stiffness_n_per_m": 100.0}, seconds=0.5)
    for k in SAME:
        assert np.array_equal(default[k], hand[k]), k
        assert np.array_equal(soft[k], soft_dict[k]), k
    assert not np.array_equal(hand["device_position_m"], rigid["device_position_m"])
    assert not np.array_equal(hand["device_position_m"], soft["device_position_m"])
    # A script that asks for a rigid stylus gets one from "hand" (the command line's meaning).
    nano = SCENES / "nanoworld.toml"
    a = nh.run_scene(nano, operator="hand", seconds=0.2)
    b = nh.run_scene(nano, operator="rigid", seconds=0.2)
    for k in SAME:
        assert np.array_equal(a[k], b[k]), k


# ------------------------------------------------------------------------------ serde's form


def test_nano_params_round_trip_in_serdes_form():
    for mode in ("game", "physical"):
        p = nh.nano_params(mode)
        assert json.loads(json.dumps(p)) == p  # plain data: dicts, lists, numbers, None
        w = nh.NanoWorld((3e-9, 3e-9, 2e-9), params=p)
        assert w.params == p
        assert w.device == {"max_force_n": w.device["max_force_n"], "max_stiffness_n_per_m": w.device["max_stiffness_n_per_m"]}
    p = nh.nano_params("game")
    assert set(p) == {"substrate", "tip", "atoms", "interaction", "gravity_m_per_s2", "inertia",
                      "loading_zone", "initial_atoms_xy_m", "house"}
    assert list(p["interaction"]) == ["game"]  # an enum is {variant: fields}, as in the scene file
    p["loading_zone"], p["house"], p["initial_atoms_xy_m"] = None, None, []
    p["substrate"]["nx"] = 7
    w = nh.NanoWorld((3e-9, 3e-9, 2e-9), params=p)
    assert w.params == p and len(w.substrate) == 7 * p["substrate"]["ny"]


def test_nano_events_have_the_form_of_a_recordings_event_detail():
    # The recording's event detail is the serde JSON of nanoworld::Event; NanoWorld.run gives
    # the same events as dicts: decoding the one gives the other.
    run = nh.run_scene(SCENES / "nanoworld.toml", seconds=3.0)
    recorded = [json.loads(d) for _, name, d in run["events"] if name.startswith("nano.")]
    assert recorded, [n for _, n, _ in run["events"]][:10]
    w = nh.NanoWorld((3e-9, 3e-9, 2e-9))
    out = w.run(w.house_script())
    live = [e for _, e in out["events"]]
    assert {"snap", "pull_off", "atom_transferred", "house_complete"} <= {e["type"] for e in live}
    assert json.loads(json.dumps(live)) == live  # plain data, as the detail decodes
    by_type = {}
    for e in recorded + live:
        by_type.setdefault(e["type"], set()).add(tuple(sorted(e)))
    for t, keys in by_type.items():
        assert len(keys) == 1, (t, keys)  # one key set per event type, whichever the source
    assert {"snap", "pull_off"} <= {e["type"] for e in recorded}
    for e in recorded + live:
        if e["type"] in ("snap", "pull_off"):
            assert e["member"] == "tip" or list(e["member"]) == ["atom"], e
            assert e["target"] == "substrate_plane" or list(e["target"])[0] in ("substrate_atom", "atom"), e


def test_brick_events_and_touches_are_serdes_form():
    b = nh.BrickWorld()
    brick = b.add_brick((0.0, 0.0, 0.05))
    r = b.run(np.tile([0.0, 0.0, 0.3], (50, 1)))
    assert all(isinstance(e, dict) and "type" in e for _, e in r["events"])
    assert b.touching == []
    # the cursor pressed into the brick's top face (z = 0.06 m): the proxy rests on it, and
    # touching names it as the events do
    for _ in range(100):
        report = b.step((0.0, 0.0, 0.055))
    assert b.touching == [{"brick": brick}]
    assert report["stiffness_n_per_m"] > 0 and report["force_n"][2] > 0
    assert set(report) >= {"tick", "force_n", "events", "saturated", "proxy_penetration_m"}


def test_closed_loop_report_is_serdes_form_with_stable_added():
    r = nh.check_closed_loop(SCENES / "wall.toml", seconds=0.3)
    assert list(r)[0] == "stable" and r["stable"] is True
    assert r["ticks"] == 300 and "house_complete_s" in r and r["house_complete_s"] is None


# ------------------------------------------------------------------------------ overrides


def test_override_errors_are_the_engines():
    # The same text the engine's own tests check (haptic_loop::scene::overrides).
    wall = SCENES / "wall.toml"
    with pytest.raises(ValueError) as e:
        nh.resolve_scene(wall, overrides={"loop.rate_hz.x": 1})
    assert str(e.value) == "override `loop.rate_hz.x`: `loop.rate_hz` is a value, not a table of fields"
    with pytest.raises(ValueError) as e:
        nh.resolve_scene(wall, overrides={"mapping.origin_m[x]": 1})
    assert str(e.value) == "override `mapping.origin_m[x]`: `origin_m[x]`: the index must be a whole number ≥ 0"
    # operator.* names go to the script, the others to the scene, in the dict's order
    r = nh.resolve_scene(wall, overrides={"operator.stiffness_n_per_m": 150.0, "loop.rate_hz": 2000})
    assert "operator.stiffness_n_per_m = 150.0" in r["script_toml"]
    assert "loop.rate_hz = 2000" in r["scene_toml"] and "operator" not in r["scene_toml"].split("\n")[0]


def test_a_bad_scene_file_is_located_without_overrides_and_named_by_field_with_them(tmp_path):
    bad = tmp_path / "bad.toml"
    text = (SCENES / "wall.toml").read_text().replace("rate_hz = 1000", "rate_hz = 999")
    assert text != (SCENES / "wall.toml").read_text()
    bad.write_text(text)
    (tmp_path / "wall.script.toml").write_text((SCENES / "wall.script.toml").read_text())
    with pytest.raises(ValueError) as e:
        nh.resolve_scene(bad)
    line = next(n for n, l in enumerate(text.splitlines(), 1) if l.startswith("rate_hz = 999"))
    assert str(e.value).startswith(f"{bad}:{line}:11: scene: `loop.rate_hz` = 999 is out of range")
    with pytest.raises(ValueError) as e:
        nh.resolve_scene(bad, overrides={"loop.watchdog_grace_s": 0.005})
    assert str(e.value).startswith("scene: `loop.rate_hz` = 999 is out of range")


# ------------------------------------------------------------------------------ mixed layout


def test_the_python_modules_are_files_of_the_package():
    pkg = Path(nh.__file__).parent
    for name in ("bridge", "sweeps", "closed_loop"):
        mod = __import__(f"nanohaptics.{name}", fromlist=["_"])
        assert Path(mod.__file__) == pkg / f"{name}.py"
        src = ROOT / "crates" / "ot-py" / "python" / "nanohaptics" / f"{name}.py"
        assert (pkg / f"{name}.py").read_bytes() == src.read_bytes()
    assert nh.sweeps.sweep is nh.sweep and nh.sweeps.grid is nh.grid and nh.sweeps.run_seed is nh.run_seed
    assert callable(nh.closed_loop) and nh.closed_loop.__module__ == "nanohaptics.closed_loop"
    # a function of a worker pickles by reference to its module
    assert nh.sweeps._execute.__module__ == "nanohaptics.sweeps"
    stub = (ROOT / "crates" / "ot-py" / "nanohaptics.pyi").read_bytes()
    assert (pkg / "__init__.pyi").read_bytes() == stub
    assert nh.__doc__.startswith("Haptic manipulation at the nanoscale")
    assert sorted(set(nh.__all__)) == sorted(nh.__all__)
    assert {k for k in dir(nh) if not k.startswith("_")} - {"nanohaptics"} == set(nh.__all__) - {"__version__"}
    lib = (ROOT / "crates" / "ot-py" / "src" / "lib.rs").read_text()
    assert "include_str!" not in lib and "from_code" not in lib
