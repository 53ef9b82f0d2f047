"""Buttons by role and refusals in nanohaptics.bridge (issue 41): the welcome's role bytes,
the refusal packet, the adapters' default button names mapped to grip, and a refused hello
surfaced with the simulator's words."""

import inspect
import socket
import threading
from pathlib import Path

import pytest

import nanohaptics as nh
from nanohaptics import bridge

ROOT = Path(__file__).resolve().parents[2]
WALL = str(ROOT / "scenes" / "wall.toml")
BRICKS = str(ROOT / "scenes" / "brickworld.toml")


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_welcome_roles_and_refusal_round_trip():
    w = bridge.encode_welcome(1000, 7, "wall", version=2, roles=(0, 2, 255, 1))
    assert len(w) == 8 + 12 + 1 + 4 + 4
    kind, v = bridge.decode(w)
    assert kind == "welcome"
    assert v["roles"] == {"grip": 0, "turn_x": 2, "turn_y": None, "turn_z": 1}
    # A welcome from a simulator before issue 41 ends at the scene name.
    assert bridge.decode(bridge.encode_welcome(1000, 7, "wall"))[1]["roles"] is None
    r = bridge.encode_refusal("version", "1 or more", "hello refused: `version` = 0")
    assert r[4:6] == bytes([1, 6])
    assert bridge.decode(r) == ("refusal", {"field": "version", "allowed": "1 or more",
                                            "message": "hello refused: `version` = 0"})
    with pytest.raises(ValueError, match="too long"):
        bridge.decode(r + b"\0")


def _welcome_of(specs, scene=WALL, protocol=2):
    port = free_port()
    sim = {}

    def serve():
        try:
            sim.update(nh.run_scene(scene, device=f"udp:127.0.0.1:{port}", wait_s=20.0,
                                    seconds=0.05))
        except Exception as e:  # the simulator's own message, checked by the caller
            sim["error"] = str(e)

    t = threading.Thread(target=serve)
    t.start()
    client = bridge.BridgeClient(("127.0.0.1", port), specs, protocol=protocol)
    try:
        welcome = client.connect(timeout_s=20.0)
        for _ in range(100):
            client.send((0.0, 0.0, 0.01))
            client.receive(0.01)
    finally:
        client.close()
        t.join()
    return welcome


@pytest.mark.parametrize("adapter, expected", [
    (bridge.HaplyInverse3Device, {"grip": 0, "turn_x": 2, "turn_y": None, "turn_z": 1}),
    (bridge.ForceDimensionDevice, {"grip": 0, "turn_x": 1, "turn_y": 2, "turn_z": 3}),
])
def test_the_adapters_default_button_names_grab(adapter, expected):
    """The Haply adapter's a, b, c and the Force Dimension adapter's Falcon names are
    welcomed with button 0 as grip (the Touch adapter's button1/button2 are the Touch preset,
    tested in Rust)."""
    names = list(inspect.signature(adapter.__init__).parameters["buttons"].default)
    specs = bridge.Specs("lab", 3.0, 1000.0, 0.1, names)
    welcome = _welcome_of(specs, scene=BRICKS)
    assert welcome["roles"] == expected


def test_a_refused_hello_raises_with_the_simulators_words():
    port = free_port()
    err = {}

    def serve():
        with pytest.raises(ValueError) as e:
            nh.run_scene(WALL, device=f"udp:127.0.0.1:{port}", wait_s=1.0)
        err["sim"] = str(e.value)

    t = threading.Thread(target=serve)
    t.start()
    specs = bridge.Specs("lab", 5000.0, 1000.0, 0.1, ["a"])
    client = bridge.BridgeClient(("127.0.0.1", port), specs)
    with pytest.raises(bridge.HelloRefused) as refused:
        client.connect(timeout_s=5.0)
    client.sock.close()
    t.join()
    r = refused.value
    assert (r.field, r.allowed) == ("max_force_n", "0.001 ≤ max_force_n ≤ 1000")
    assert str(r) == ("hello refused: device specs: `max_force_n` = 5000 is out of range: "
                      "allowed 0.001 ≤ max_force_n ≤ 1000")
    assert "hello refused: device specs: `max_force_n` = 5000" in err["sim"]
    assert "no device said hello" in err["sim"]
