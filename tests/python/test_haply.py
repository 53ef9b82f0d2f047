"""nanohaptics.bridge.HaplyInverse3Device against a mock of Haply's Python API
(``HaplyHardwareAPI``): a session on the wall scene through the UDP bridge, as test_live.py
tests the Touch and Force Dimension adapters, plus the adapter's own servo rules.

The mock follows the real API (HaplyHardwareAPI 0.1.13): ``detect_inverse3s()`` and
``detect_handles()`` list serial ports, ``SerialStream(port)``, ``Inverse3(stream)``,
``device_wakeup_dict()``, ``end_effector_force(force) -> (position, velocity)`` (N in, m and
m/s out, base frame), ``Handle(stream).GetVersegripStatus() -> dict`` with ``"buttons"``.
"""

import math
import sys
import time
import types

import numpy as np
import pytest

import nanohaptics as nh
from nanohaptics import bridge

# pytest's default (prepend) import mode puts this folder on sys.path: the session helpers are
# shared with test_live.py rather than copied.
from test_live import bridged_session, free_port, press_path, retry_while_disturbed

# A made-up centre of reach in the Inverse3's base frame (not the adapter's default), and the
# cursor's x, y in the centred frame: the simulator must see the mock's positions minus CENTRE.
CENTRE = (0.05, -0.12, 0.16)
OFFSET_XY = (0.003, -0.002)


@pytest.fixture
def mock_haply(monkeypatch):
    state = {"t0": time.perf_counter(), "forces": [], "positions": [], "ports": [],
             "woken": False, "inverse3s": ["/dev/ttyACM7"], "handles": ["/dev/ttyACM8"],
             "handle_buttons": 0b1001}
    api = types.ModuleType("HaplyHardwareAPI")
    api.detect_inverse3s = lambda: list(state["inverse3s"])
    api.detect_handles = lambda: list(state["handles"])

    class SerialStream:
        def __init__(self, port):
            state["ports"].append(port)

    class Inverse3:
        def __init__(self, stream, timeout=5.0):
            self.stream = stream

        def device_wakeup_dict(self):
            state["woken"] = True
            return {"device_id": 1234, "device_model_number": 0, "hardware_version": 0,
                    "firmware_version": 0}

        def end_effector_force(self, forces=(0.0, 0.0, 0.0)):
            state["forces"].append(tuple(forces))
            z = press_path(time.perf_counter() - state["t0"])
            p = [CENTRE[0] + OFFSET_XY[0], CENTRE[1] + OFFSET_XY[1], CENTRE[2] + z]
            state["positions"].append(tuple(p))
            return p, [0.0, 0.0, 0.0]

    class Handle:
        def __init__(self, stream):
            self.stream = stream

        def GetVersegripStatus(self):
            return {"device_id": 7, "quaternion": [1.0, 0.0, 0.0, 0.0], "buttons": state["handle_buttons"],
                    "battery_level": 0.9, "error_flag": 0}

    api.SerialStream, api.Inverse3, api.Handle = SerialStream, Inverse3, Handle
    monkeypatch.setitem(sys.modules, "HaplyHardwareAPI", api)
    return state


def _inverse3_session(out, mock_haply):
    """One bridged session of the wall with the mocked Inverse3: the device, its specs, the
    adapter's stats and the simulator's result."""
    for key in ("forces", "positions", "ports"):
        mock_haply[key].clear()
    mock_haply["woken"] = False
    port = free_port()
    t, sim = bridged_session(port, out)
    dev = bridge.HaplyInverse3Device(handle_port="auto", workspace_centre_m=CENTRE,
                                     max_force_n=2.5, max_stiffness_n_per_m=1500.0)
    assert mock_haply["woken"] and mock_haply["ports"] == ["/dev/ttyACM7", "/dev/ttyACM8"]
    s = dev.specs()
    assert (s.name, s.max_force_n, s.max_stiffness_n_per_m, s.workspace_radius_m, s.buttons) == (
        "inverse3", 2.5, 1500.0, 0.10, ["a", "b", "c"])
    mock_haply["t0"] = time.perf_counter()
    stats = bridge.run(dev, ("127.0.0.1", port), seconds=1.0)
    t.join()
    return stats, sim


def _check_inverse3_session(out, stats, sim, mock_haply):
    assert stats["sent"] >= 500 and stats["answered"] >= 0.9 * stats["sent"]
    assert sim["stats"]["end"] == "device_ended"
    assert sim["stats"]["link"]["received"] == stats["sent"]

    # The limits came from its hello: the wall's 5000 N/m capped at the announced 1500 N/m,
    # and 2 mm deep (3 N) scaled down to the announced 2.5 N, flagged as clamped.
    assert sim["device_stiffness_n_per_m"][:, 2, 2].max() == pytest.approx(1500.0)
    f_sim = np.linalg.norm(sim["device_force_n"], axis=1)
    assert f_sim.max() == pytest.approx(2.5) and np.all(f_sim <= 2.5 + 1e-12)
    assert np.any(sim["status"] & 1)

    # The frame: every position the simulator saw is a mock position minus the centre.
    seen = sim["device_position_m"]
    assert np.all(np.abs(seen[:, :2] - OFFSET_XY) <= 1e-15)
    assert seen[:, 2].min() == pytest.approx(-0.007, abs=2e-4) and seen[:, 2].max() <= 0.0100001
    mock_centred = np.array(mock_haply["positions"]) - np.array(CENTRE)
    gap = np.abs(seen[:, None, :] - mock_centred[None, :, :]).max(axis=2).min(axis=1)
    assert gap.max() <= 1e-15
    assert not [e for e in sim["events"] if e[1] == "input.invalid"]  # all inside the 0.1 m sphere

    # Buttons: the handle's bit 3 is not one of the three announced buttons and is dropped.
    assert np.all(sim["device_buttons"] == 1)

    # What the hand felt: finite, within the announced 2.5 N, up out of the wall ...
    felt = np.array(mock_haply["forces"])
    assert np.all(np.isfinite(felt))
    assert np.all(np.linalg.norm(felt, axis=1) <= 2.5 + 1e-12)
    assert felt[:, 2].max() == pytest.approx(2.5, rel=0.02)
    # ... and zero at the end, with no command after it (the servo thread has stopped).
    assert tuple(felt[-1]) == (0.0, 0.0, 0.0)
    n = len(mock_haply["forces"])
    time.sleep(0.02)
    assert len(mock_haply["forces"]) == n
    back = nh.read_recording(out)
    assert np.array_equal(back["device_position_m"], seen)


def test_an_inverse3_is_centred_announces_its_limits_and_ends_at_zero_force(tmp_path, mock_haply):
    # A peak of 1250 N/m instead of 1500 was seen under load: the watchdog faded the force and
    # the soft engagement ramped the stiffness back in mid-press (retry_while_disturbed).
    outs = []

    def session(k):
        outs.append(tmp_path / f"inverse3-{k}.mcap")
        return _inverse3_session(outs[-1], mock_haply)

    retry_while_disturbed(
        session, lambda stats, sim: _check_inverse3_session(outs[-1], stats, sim, mock_haply))


def wait_until(predicate, timeout_s=2.0):
    """Poll until ``predicate()`` holds (the servo runs in its own thread); False on timeout."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(0.002)
    return False


def test_the_servo_renders_the_local_force_until_hold_s_then_zero(mock_haply):
    dev = bridge.HaplyInverse3Device(workspace_centre_m=CENTRE, hold_s=0.5, max_force_n=3.0)
    assert dev.specs().buttons == [] and dev.specs().rate_hz == 1000  # no handle: no buttons
    mock_haply["t0"] = time.perf_counter() - 10.0  # the mock cursor rests at press_path's end
    time.sleep(0.01)
    p, b = dev.read()
    assert b == 0 and p[0] == pytest.approx(OFFSET_XY[0], abs=1e-15)
    assert p[2] == pytest.approx(-0.007, abs=1e-12)
    # An answer computed 1 mm above the cursor: F0 = 1 N up, K = 500 N/m in z, so at the
    # cursor (1 mm lower than p0) the local force is 1 + 500 · 0.001 = 1.5 N up.
    k = (0.0,) * 8 + (500.0,)
    dev.render(bridge.ForceReply(0, 0, (0.0, 0.0, 1.0), k, 0), (p[0], p[1], p[2] + 0.001))
    assert wait_until(lambda: len(mock_haply["forces"]) > 10
                      and all(f[2] == pytest.approx(1.5, rel=1e-9) for f in mock_haply["forces"][-10:]))
    time.sleep(0.6)  # past hold_s without a new answer: zero force
    assert mock_haply["forces"][-1] == (0.0, 0.0, 0.0)
    # Closed while an answer is fresh: the servo stops and close() itself sends the zero
    # (the Inverse3 keeps the last force it was sent).
    dev.render(bridge.ForceReply(1, 1, (0.0, 0.0, 1.0), k, 0), (p[0], p[1], p[2] + 0.001))
    assert wait_until(lambda: mock_haply["forces"][-1][2] == pytest.approx(1.5, rel=1e-9))
    dev.close()
    n = len(mock_haply["forces"])
    assert mock_haply["forces"][-1] == (0.0, 0.0, 0.0)
    time.sleep(0.02)
    assert len(mock_haply["forces"]) == n


def test_handedness_centre_and_missing_devices_are_clear(mock_haply):
    mock_haply["t0"] = time.perf_counter() - 10.0  # a cursor at rest
    right = bridge.HaplyInverse3Device()
    left = bridge.HaplyInverse3Device(handedness="left")
    assert left.centre_m == (-right.centre_m[0], right.centre_m[1], right.centre_m[2])
    raw = right.raw_position_m
    assert right.read()[0] == tuple(raw[i] - right.centre_m[i] for i in range(3))
    right.close()
    left.close()
    with pytest.raises(ValueError, match='handedness = "both"'):
        bridge.HaplyInverse3Device(handedness="both")
    with pytest.raises(ValueError, match="workspace_centre_m"):
        bridge.HaplyInverse3Device(workspace_centre_m=(0.0, math.nan, 0.0))
    mock_haply["inverse3s"] = []
    with pytest.raises(ConnectionError, match="no Haply Inverse3 found"):
        bridge.HaplyInverse3Device()


def test_without_the_sdk_the_error_says_how_to_install_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "HaplyHardwareAPI", None)  # import fails
    with pytest.raises(ImportError, match=r"pip install HaplyHardwareAPI \(see docs/device-bridge.md\)"):
        bridge.HaplyInverse3Device()
