"""The teaching game from Python: the sound of a recording, and switches in a stepped session."""

import json
from pathlib import Path

import numpy as np
import pytest

import nanohaptics as nh

ROOT = Path(__file__).resolve().parents[2]
BRICKS = ROOT / "recordings" / "brickworld.mcap"


def test_render_audio_returns_samples_with_a_sound_on_each_isolated_impact(tmp_path):
    samples, rate = nh.render_audio(BRICKS, out=tmp_path / "b.wav")
    assert rate == 44100 and samples.dtype == np.float32
    rec = nh.read_recording(BRICKS)
    ticks = len(rec["tick"])
    assert len(samples) == round(ticks / 1000 * rate)
    assert np.max(np.abs(samples)) <= 0.98 + 1e-6
    assert (tmp_path / "b.wav").stat().st_size == 44 + 2 * len(samples)
    hits = [(t / 1000, json.loads(d)) for t, n, d in rec["events"] if n == "brick.impact"]
    assert hits
    checked = 0
    for t, d in hits:
        if any(0 < t - u < 0.15 for u, _ in hits):
            continue
        k = round(t * rate)
        assert np.all(np.abs(samples[k - 880 : k - 44]) < 1e-3)  # silence before
        win = np.abs(samples[k - 44 : k + 1100])
        first = np.argmax(win >= 0.1 * win.max())
        assert abs((first - 44) / rate) <= 1e-3  # onset within 1 ms of the tick
        checked += 1
    assert checked >= 4


def test_render_audio_errors_name_the_problem():
    with pytest.raises(ValueError, match=r"the wall scene records no distance"):
        nh.render_audio(ROOT / "recordings" / "wall.mcap", proximity=True)
    with pytest.raises(ValueError, match=r"sample_rate = 10 is out of range: allowed 8000–192000 Hz"):
        nh.render_audio(BRICKS, sample_rate=10)
    with pytest.raises(OSError):
        nh.render_audio(ROOT / "recordings" / "missing.mcap")


def test_a_switch_in_a_stepped_session_changes_the_world_and_is_recorded(tmp_path):
    out = tmp_path / "s.mcap"
    with nh.Session("nanoworld", out=out) as s:
        s.switch("adhesion_scale", 0.5)
        s.tick([0.0, 0.0, 0.0])
        assert ("switch.set", '{"name":"adhesion_scale","value":0.5}') in s.events
        with pytest.raises(ValueError) as e:
            s.switch("gravity", 1.0)
        assert str(e.value) == (
            "tick 1: the nanoworld scene has no switch `gravity` (its switches: adhesion_scale, "
            "tip_substrate_scale, tip_atom_scale, atom_atom_scale, atom_substrate_scale, "
            "atom_mass_kg, gravity_m_per_s2, inertia)"
        )
        with pytest.raises(ValueError, match=r"switch `inertia` = 0.5 is out of range"):
            s.switch("inertia", 0.5)
        s.switch("inertia", False)
        s.tick([0.0, 0.0, 0.0])
    rec = nh.read_recording(out)
    sets = [(t, d) for t, n, d in rec["events"] if n == "switch.set"]
    assert sets == [(0, '{"name":"adhesion_scale","value":0.5}'), (1, '{"name":"inertia","value":0.0}')]
