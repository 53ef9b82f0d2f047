"""`nanohaptics device-check` against the Python reference client (issue 41, item 4): a device
written from docs/device-bridge.md with `bridge.BridgeClient` and `bridge.DeviceSide`, its
stylus a mass held by a hand that does what the check asks, passes every rule; the same device
numbering its samples from 1 fails `sample.seq` and nothing else.

The device runs at 200 Hz (the check's `--rate 200`) so that pure Python keeps its period on a
loaded machine; its servo renders the local model at 1 kHz (five servo steps per period), as an
adapter's servo thread does.
"""

from __future__ import annotations

import json
import socket
import subprocess
import sysconfig
import time
from pathlib import Path

import pytest

from nanohaptics import bridge

COMMAND = Path(sysconfig.get_path("scripts")) / "nanohaptics"
FALCON_BUTTONS = ["centre", "plus", "minus", "forward"]
RATE_HZ = 200
SERVO_STEPS = 5

# The hand: a loose grip (docs/devices.md) on a Falcon's moving mass.
MASS_KG, HAND_K, HAND_B, FRICTION = 0.15, 300.0, 2.0, 0.2


def free_port() -> int:
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def intent_z(t: float) -> float:
    """Where the hand wants the stylus, m along z: still until 0.6 s, 8 mm down by 1.0 s (the
    check's own hand, `fake-device --check-hand`)."""
    return -0.008 * min(max((t - 0.6) / 0.4, 0.0), 1.0)


def play(port: int, first_seq: int) -> dict:
    """The device: hello until welcome, then each period the mass and hand over five servo
    steps rendered by the device side, one sample, the answers as they come; until the
    check's bye. Returns counts."""
    specs = bridge.Specs("falcon", 8.0, 3000.0, 0.04, FALCON_BUTTONS)
    client = bridge.BridgeClient(("127.0.0.1", port), specs)
    welcome = client.connect(20.0)
    assert welcome["rate_hz"] == RATE_HZ and welcome["version"] == 2
    client.seq = first_seq
    period = 1.0 / RATE_HZ
    h = period / SERVO_STEPS
    side = bridge.DeviceSide(welcome["version"], specs.max_force_n, h)
    z = v = 0.0
    t0 = time.perf_counter()
    next_t = t0
    sent = 0
    try:
        while not client.ended and time.perf_counter() - t0 < 20.0:
            t = client.seq * period
            # The device and hand over the last period (semi-implicit Euler), the force
            # rendered by the device side from the local model at each servo step.
            for k in range(SERVO_STEPS):
                ts = t - period + (k + 1) * h
                f = side.render((0.0, 0.0, z), h)[2]
                hand = HAND_K * (intent_z(ts) - z) - HAND_B * v
                v += h * (hand + f - FRICTION * v) / MASS_KG
                z += h * v
            side.record_reading(client.seq, (0.0, 0.0, z))
            client.send((0.0, 0.0, z), 0, side.interventions)
            sent += 1
            while True:
                reply = client.receive(max(0.0, next_t + period - time.perf_counter()))
                if reply is None:
                    break
                side.receive(reply)
            next_t += period
            delay = next_t - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
    finally:
        client.sock.close()
    return {"sent": sent, "ended": client.ended}


def check(first_seq: int) -> tuple[int, dict, dict]:
    port = free_port()
    proc = subprocess.Popen(
        [str(COMMAND), "device-check", f"udp:127.0.0.1:{port}", "--rate", str(RATE_HZ),
         "--wait-s", "20", "--json"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    try:
        device = play(port, first_seq)
        out, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert out, err
    return proc.returncode, json.loads(out), device


def rules(report: dict) -> dict:
    return {r["rule"]: r for r in report["rules"]}


def test_the_reference_client_passes_every_rule():
    code, report, device = check(first_seq=0)
    by = rules(report)
    failed = [r for r, x in by.items() if x["verdict"] == "fail"]
    assert failed == [], json.dumps(report, indent=1)
    assert code == 0
    assert report["device"] == "falcon" and report["version"] == 2 and report["rate_hz"] == RATE_HZ
    assert len(by) == 14 and all(x["verdict"] == "pass" for x in by.values())
    # The check's bye ended the device (7 s of the stages and the hello, not the 20 s guard).
    assert device["ended"] and device["sent"] < 10 * RATE_HZ
    # The wall held where a loose hand pushing 6 mm through a 3000 N/m wall sits statically:
    # 6 mm x 300 / 3300 = 0.55 mm deep (its bound is the Falcon's 8 N at 3000 N/m, 2.67 mm).
    depth = by["render.planes"]["value"]
    assert 0.4e-3 < depth < 0.75e-3, depth
    # Resting on the floor through the 1500 N/m coupling: 6 mm x 300 / 1800 = 1.0 mm.
    body = by["render.body"]["value"]
    assert 0.8e-3 < body < 1.25e-3, body


def test_the_reference_client_numbering_from_1_fails_sample_seq_alone():
    code, report, _ = check(first_seq=1)
    by = rules(report)
    failed = [r for r, x in by.items() if x["verdict"] == "fail"]
    assert failed == ["sample.seq"], json.dumps(report, indent=1)
    assert code == 2
    assert "the first numbered 1 after the hello" in by["sample.seq"]["figure"]
