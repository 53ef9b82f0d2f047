"""How much latency each device adapter of ``nanohaptics.bridge`` adds, without hardware.

Each adapter (Touch, Force Dimension, Haply Inverse3) runs against a mock of its vendor SDK
(the same names and signatures as the mocks of tests/python/test_live.py and test_haply.py),
driven by a 1 kHz servo thread, and ``bridge.run`` connects it to a fake simulator: a UDP
socket thread in this script that answers every sample at once with a force packet made by
the Python encoder (version 2 with a local model, or version 1), so no simulator process is
needed.

What is measured, per adapter and protocol (times on ``time.perf_counter``):

* **force age**: at every servo tick, the time since the stylus reading was taken (the SDK
  call that returned it) that the applied force answers. The mock SDK numbers its readings
  (x = 1 µm per reading), the fake simulator echoes the number in the force (1e-5 N per
  reading along x; no stiffness, a contact plane far away and a large world energy, so the
  device side renders that force exactly), and the mock decodes it at the force command;
* **first use**: the age at the first servo tick that applies a new answer (reading → SDK
  read → ``run`` → UDP → fake simulator → UDP → ``run`` → device side → next servo tick);
* **raw round trip**: a bare socket sending samples to the same fake simulator and waiting
  for each answer (no adapter, no ``run``): what the link and the fake simulator cost;
* **added**: force age minus raw round trip (p50 and p99): the adapter's and ``run``'s share,
  which includes waiting for the next 1 kHz servo tick and, because a force is held until
  the next answer, about one sample period of holding.

Prints a Markdown table. A few seconds per adapter and protocol::

    python examples/bridge/adapter_latency.py [--seconds 3] [--protocols 2,1]

Runs from a checkout without the wheel too (the bridge module is standard-library Python).
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import os
import socket
import sys
import threading
import time
import types
from pathlib import Path

try:
    from nanohaptics import bridge
except ImportError:  # a checkout without the wheel: the module is plain Python
    _path = Path(__file__).resolve().parents[2] / "crates" / "ot-py" / "python" / "nanohaptics" / "bridge.py"
    _spec = importlib.util.spec_from_file_location("nanohaptics_bridge", _path)
    bridge = importlib.util.module_from_spec(_spec)
    sys.modules[_spec.name] = bridge
    _spec.loader.exec_module(bridge)

STEP_M = 1e-6  # the mock's reading number k is x = k µm
STEP_N = 1e-5  # the fake simulator's answer to reading k pushes (k + 1) · 1e-5 N along x
SERVO_S = 1e-3


# ---------------------------------------------------------------- the fake simulator


class FakeSimulator:
    """A UDP socket thread that welcomes any hello (with its version, at most 2) and answers
    every sample at once: the force encodes the reading number (see the module doc)."""

    def __init__(self, rate_hz: int = 1000):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(0.05)
        self.address = self.sock.getsockname()
        self.rate_hz = rate_hz
        self.versions = {}  # peer -> session version
        self.received_at = {}  # reading number -> perf_counter() when its sample arrived
        self.answered_at = {}  # reading number -> perf_counter() when its answer was sent
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._serve, name="fake-simulator", daemon=True)
        self.thread.start()

    def _serve(self) -> None:
        far = bridge.Plane((0.0, 0.0, 1.0), -1.0, 1000.0)  # a plane the stylus never touches
        while not self.stop.is_set():
            try:
                data, peer = self.sock.recvfrom(2048)
            except socket.timeout:
                continue
            except OSError:
                return
            at = time.perf_counter()
            try:
                kind, value = bridge.decode(data)
            except ValueError:
                continue
            if kind == "hello":
                version = min(value["version"], bridge.VERSION_2)
                self.versions[peer] = version
                self.sock.sendto(bridge.encode_welcome(self.rate_hz, time.time_ns(), "fake", version), peer)
            elif kind == "sample":
                k = round(value["position_m"][0] / STEP_M)
                self.received_at.setdefault(k, at)
                force = ((k + 1) * STEP_N, 0.0, 0.0)
                local = None
                if self.versions.get(peer, bridge.VERSION_2) == bridge.VERSION_2:
                    local = bridge.LocalModel(residual_force_n=force, planes=[far], world_energy_j=1e6)
                reply = bridge.ForceReply(value["seq"], value["seq"], force, (0.0,) * 9, 0, local=local)
                self.sock.sendto(bridge.encode_force(reply), peer)
                self.answered_at.setdefault(k, time.perf_counter())

    def close(self) -> None:
        self.stop.set()
        self.thread.join()
        self.sock.close()


def raw_round_trip(seconds: float, version: int) -> list:
    """A bare socket against a fresh fake simulator, paced at 1 kHz: round trips, s."""
    sim = FakeSimulator()
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.settimeout(0.05)
    specs = bridge.Specs("raw", 8.0, 3000.0, 0.04)
    s.sendto(bridge.encode_hello(specs, version), sim.address)
    s.recvfrom(2048)  # the welcome
    rtts = []
    next_t = time.perf_counter()
    for seq in range(int(seconds / SERVO_S)):
        t0 = time.perf_counter()
        s.sendto(bridge.encode_sample(seq, 0, (seq * STEP_M, 0.0, 0.0), 0), sim.address)
        try:
            s.recvfrom(2048)
            rtts.append(time.perf_counter() - t0)
        except socket.timeout:
            pass
        next_t += SERVO_S
        time.sleep(max(0.0, next_t - time.perf_counter()))
    s.close()
    sim.close()
    return rtts


# ---------------------------------------------------------------- the mock SDKs


class Log:
    """What a mock SDK saw: when it returned each reading, and each force command."""

    def __init__(self):
        self.read_at = []  # reading k was returned at read_at[k]
        self.commands = []  # (perf_counter(), force x)
        self.lock = threading.Lock()

    def reading(self) -> float:
        """The next reading's x (m), numbered."""
        with self.lock:
            k = len(self.read_at)
            self.read_at.append(time.perf_counter())
        return k * STEP_M

    def command(self, f) -> None:
        self.commands.append((time.perf_counter(), float(f[0])))


def mock_openhaptics(log: Log) -> dict:
    """pyOpenHaptics (as tests/python/test_live.py mocks it), with a 1 kHz scheduler thread on
    an absolute schedule."""
    pkg = types.ModuleType("pyOpenHaptics")
    hd = types.ModuleType("pyOpenHaptics.hd")
    hd_callback = types.ModuleType("pyOpenHaptics.hd_callback")
    hd_device = types.ModuleType("pyOpenHaptics.hd_device")
    hd.get_transform = lambda: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [log.reading() * 1e3, 0.0, 0.0, 1]]
    hd.get_buttons = lambda: 0
    hd.set_force = log.command
    hd_callback.hd_callback = lambda fn: fn

    class HapticDevice:
        def __init__(self, callback, device_name="Default Device", scheduler_type="async"):
            self.running = True

            def servo():
                next_t = time.perf_counter()
                while self.running:
                    callback()
                    next_t += SERVO_S
                    time.sleep(max(0.0, next_t - time.perf_counter()))

            self.thread = threading.Thread(target=servo, name="hd-scheduler", daemon=True)
            self.thread.start()

        def close(self):
            self.running = False
            self.thread.join()

    hd_device.HapticDevice = HapticDevice
    pkg.hd, pkg.hd_callback, pkg.hd_device = hd, hd_callback, hd_device
    return {"pyOpenHaptics": pkg, "pyOpenHaptics.hd": hd, "pyOpenHaptics.hd_callback": hd_callback,
            "pyOpenHaptics.hd_device": hd_device}


def mock_dhd(log: Log) -> dict:
    """forcedimension_core.dhd (as tests/python/test_live.py mocks it)."""
    pkg = types.ModuleType("forcedimension_core")
    dhd = types.ModuleType("forcedimension_core.dhd")
    dhd.open = lambda: 0
    dhd.openID = lambda i: i
    dhd.enableForce = lambda on, ID=-1: 0
    dhd.getMaxForce = lambda ID=-1: 12.0
    dhd.getSystemName = lambda ID=-1: "delta.3"
    dhd.errorGetLastStr = lambda: "no error"

    def get_position(out, ID=-1):
        out[0], out[1], out[2] = log.reading(), 0.0, 0.0
        return 0

    dhd.getPosition = get_position
    dhd.getButtonMask = lambda ID=-1: 0
    dhd.setForce = lambda f, ID=-1: log.command(f) or 0
    dhd.close = lambda ID=-1: 0
    pkg.dhd = dhd
    return {"forcedimension_core": pkg, "forcedimension_core.dhd": dhd}


def mock_haply(log: Log) -> dict:
    """HaplyHardwareAPI (as tests/python/test_haply.py mocks it): force in, position out."""
    api = types.ModuleType("HaplyHardwareAPI")
    api.detect_inverse3s = lambda: ["/dev/ttyACM7"]
    api.detect_handles = lambda: []

    class SerialStream:
        def __init__(self, port):
            self.port = port

    class Inverse3:
        def __init__(self, stream, timeout=5.0):
            self.stream = stream

        def device_wakeup_dict(self):
            return {"device_id": 1234}

        def end_effector_force(self, forces=(0.0, 0.0, 0.0)):
            log.command(forces)
            return [log.reading(), 0.0, 0.0], [0.0, 0.0, 0.0]

    api.SerialStream, api.Inverse3 = SerialStream, Inverse3
    return {"HaplyHardwareAPI": api}


ADAPTERS = {
    "Touch (pyOpenHaptics)": (mock_openhaptics, lambda p: bridge.TouchDevice(protocol=p)),
    "Force Dimension (forcedimension_core)": (mock_dhd, lambda p: bridge.ForceDimensionDevice(protocol=p)),
    "Haply Inverse3 (HaplyHardwareAPI)": (
        mock_haply, lambda p: bridge.HaplyInverse3Device(workspace_centre_m=(0.0, 0.0, 0.0), protocol=p)),
}


# ---------------------------------------------------------------- one measurement


def percentile(values, q: float) -> float:
    if not values:
        return math.nan
    v = sorted(values)
    return v[min(len(v) - 1, max(0, math.ceil(q * len(v)) - 1))]


def measure(mock, make, protocol: int, seconds: float) -> dict:
    log = Log()
    modules = mock(log)
    saved = {name: sys.modules.get(name) for name in modules}
    sys.modules.update(modules)
    sim = FakeSimulator()
    try:
        dev = make(protocol)
        stats = bridge.run(dev, sim.address, seconds=seconds, protocol=protocol)
    finally:
        sim.close()
        for name, mod in saved.items():
            if mod is None:
                sys.modules.pop(name, None)
            else:
                sys.modules[name] = mod
    # From 0.1 s after the first answer was applied (the connection is not measured).
    # The zero forces after the session (run() detaches the device side, close() sends zero)
    # are not counted either.
    start = next(t for t, fx in log.commands if fx != 0.0) + 0.1
    end = max(t for t, fx in log.commands if fx != 0.0)
    ages, first, to_sim, to_motor, seen, zero, ticks = [], [], [], [], set(), 0, 0
    for t, fx in log.commands:
        if t < start or t > end:
            continue
        ticks += 1
        if fx == 0.0:
            zero += 1  # the newest answer was older than hold_s
            continue
        k = round(fx / STEP_N) - 1
        age = t - log.read_at[k]
        ages.append(age)
        if k not in seen:
            seen.add(k)
            first.append(age)
            to_sim.append(sim.received_at[k] - log.read_at[k])
            to_motor.append(t - sim.answered_at[k])
    return {"stats": stats, "ages": ages, "first": first, "to_sim": to_sim, "to_motor": to_motor,
            "zero": zero, "ticks": ticks}


def ms(x: float) -> str:
    return f"{1e3 * x:.2f}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=3.0, help="session length per adapter and protocol, s")
    ap.add_argument("--protocols", default="2,1", help="protocol versions to measure, comma separated")
    a = ap.parse_args()
    protocols = [int(p) for p in a.protocols.split(",")]
    rows = []
    for name, (mock, make) in ADAPTERS.items():
        for p in protocols:
            raw = raw_round_trip(min(a.seconds, 1.0), p)  # just before, under the same load
            r = measure(mock, make, p, a.seconds)
            s, ages, first = r["stats"], r["ages"], r["first"]
            rp50, rp99 = percentile(raw, 0.5), percentile(raw, 0.99)
            rows.append(
                f"| {name} | {p} | {ms(rp50)} / {ms(rp99)} | {ms(s['round_trip_p50_s'])} / {ms(s['round_trip_p99_s'])} "
                f"| {ms(percentile(ages, 0.5))} / {ms(percentile(ages, 0.99))} / {ms(max(ages))} "
                f"| {ms(percentile(first, 0.5))} / {ms(percentile(first, 0.99))} "
                f"| {ms(percentile(r['to_sim'], 0.5))} | {ms(percentile(r['to_motor'], 0.5))} / {ms(percentile(r['to_motor'], 0.99))} "
                f"| {ms(percentile(ages, 0.5) - rp50)} | {r['zero']}/{r['ticks']} |")
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else math.nan
    print(f"Adapter latency against mock SDKs and a fake simulator in this process: {a.seconds:g} s per row "
          f"at 1 kHz; Python {sys.version.split()[0]}, {os.cpu_count()} CPUs, 1-minute load {load:.2f} at the end. "
          "Times in ms.\n")
    print("| adapter | protocol | raw round trip p50 / p99 | run() round trip p50 / p99 "
          "| force age p50 / p99 / max | first use p50 / p99 | reading → simulator p50 "
          "| answer → motor p50 / p99 | added p50 | zero-force ticks |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for row in rows:
        print(row)
    print("\n*force age*: at each servo tick, time since the reading its force answers was taken; "
          "*first use*: the age at the first tick that applies an answer; *reading → simulator*: from the SDK "
          "read to the sample's arrival; *answer → motor*: from the answer's send to the first force command "
          "with it; *added*: force age p50 − raw round trip p50 (with a 1 kHz servo a reading's answer is "
          "applied one servo period after the reading at best, so about 1 ms of it is the servo's period); "
          "*zero-force ticks*: answer older than hold_s (10 ms).")


if __name__ == "__main__":
    main()
