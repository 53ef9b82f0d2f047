"""A device in this process, a simulator in another: the nanohaptics device bridge.

The simulator (``nanohaptics run SCENE --device udp:HOST:PORT``, or
``nanohaptics.run_scene(SCENE, device="udp:HOST:PORT")``) listens on UDP; a
device process says hello with its specifications, then sends one sample per
servo period and gets a force (N) and a local stiffness (N/m, 3×3) back for
each. The byte layout is in ``docs/device-bridge.md``; this module is its
Python client, plus adapters for real devices through their Python SDKs:

* :class:`TouchDevice` — 3D Systems Touch / Phantom Omni through
  ``pyOpenHaptics`` (OpenHaptics HD API);
* :class:`ForceDimensionDevice` — Force Dimension devices and the Novint
  Falcon through ``forcedimension_core`` (Force Dimension SDK);
* :class:`HaplyInverse3Device` — a Haply Inverse3 (and optionally its
  VerseGrip handle for buttons) through ``HaplyHardwareAPI`` (Haply's Python
  API over USB serial).

The SDKs are imported only when an adapter is created. Every adapter renders,
between packets and at its own servo rate, ``F = F0 − K (p − p0)`` from the
last answer (the force F0 computed at p0 and the stiffness K), and zero force
once answers stop for longer than ``hold_s`` (the simulator's watchdog does
the same on its side).

Units: metres, newtons, N/m, seconds, in the device frame.
"""

from __future__ import annotations

import math
import socket
import struct
import threading
import time
from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple

__all__ = [
    "MAGIC",
    "VERSION",
    "Specs",
    "ForceReply",
    "BridgeClient",
    "Device",
    "TouchDevice",
    "ForceDimensionDevice",
    "HaplyInverse3Device",
    "encode_hello",
    "encode_sample",
    "decode",
    "run",
]

MAGIC = b"NHDB"
VERSION = 1
HELLO, WELCOME, SAMPLE, FORCE, BYE = 1, 2, 3, 4, 5
_HEADER = struct.Struct("<4sBBH")  # magic, version, type, reserved
_SAMPLE = struct.Struct("<QQdddI")  # seq, device time ns, x, y, z, buttons
_FORCE = struct.Struct("<QQ3d9dB")  # seq answered, tick, force, stiffness, status


@dataclass
class Specs:
    """What a device announces in its hello."""

    name: str
    max_force_n: float
    max_stiffness_n_per_m: float
    workspace_radius_m: float
    buttons: List[str] = field(default_factory=list)
    rate_hz: int = 1000


@dataclass
class ForceReply:
    """The simulator's answer to one sample."""

    seq: int
    tick: int
    force_n: Tuple[float, float, float]
    stiffness_n_per_m: Tuple[float, ...]  # 9 values, row-major 3x3
    status: int
    received_at: float = 0.0  # time.perf_counter() on arrival, s


def _string(s: str) -> bytes:
    b = s.encode("utf-8")[:255]
    return bytes([len(b)]) + b


def encode_hello(specs: Specs) -> bytes:
    """The hello datagram of a device with ``specs``."""
    body = struct.pack(
        "<Iddd",
        specs.rate_hz,
        specs.max_force_n,
        specs.max_stiffness_n_per_m,
        specs.workspace_radius_m,
    )
    body += _string(specs.name) + bytes([len(specs.buttons)])
    body += b"".join(_string(b) for b in specs.buttons)
    return _HEADER.pack(MAGIC, VERSION, HELLO, 0) + body


def encode_sample(seq: int, device_time_ns: int, position_m: Sequence[float], buttons: int) -> bytes:
    """A sample datagram: position in metres (device frame), button bits."""
    x, y, z = (float(v) for v in position_m)
    return _HEADER.pack(MAGIC, VERSION, SAMPLE, 0) + _SAMPLE.pack(
        seq, device_time_ns, x, y, z, buttons
    )


def encode_bye(reason: int = 0) -> bytes:
    """A goodbye datagram (0: end of session, 1: error)."""
    return _HEADER.pack(MAGIC, VERSION, BYE, 0) + bytes([reason])


def decode(data: bytes):
    """Decode a datagram from the simulator: ``("welcome", dict)``,
    ``("force", ForceReply)`` or ``("bye", reason)``. Raises ValueError
    naming what is wrong for anything else."""
    if len(data) < _HEADER.size:
        raise ValueError(f"packet of {len(data)} bytes is shorter than the 8-byte header")
    magic, version, kind, _ = _HEADER.unpack_from(data)
    if magic != MAGIC:
        raise ValueError(f"bad magic {magic!r} (expected b'NHDB')")
    if version != VERSION:
        raise ValueError(f"protocol version {version} (this client speaks {VERSION})")
    body = data[_HEADER.size:]
    if kind == WELCOME:
        if len(body) < 13:
            raise ValueError("welcome packet too short")
        rate, start = struct.unpack_from("<IQ", body)
        n = body[12]
        return "welcome", {
            "rate_hz": rate,
            "start_time_ns": start,
            "scene": body[13:13 + n].decode("utf-8", "replace"),
        }
    if kind == FORCE:
        if len(body) != _FORCE.size:
            raise ValueError(f"force packet of {len(data)} bytes (expected {8 + _FORCE.size})")
        v = _FORCE.unpack(body)
        return "force", ForceReply(v[0], v[1], tuple(v[2:5]), tuple(v[5:14]), v[14])
    if kind == BYE:
        return "bye", body[0] if body else 0
    raise ValueError(f"unexpected packet type {kind}")


class BridgeClient:
    """The device side of the bridge over one UDP socket.

    >>> c = BridgeClient(("127.0.0.1", 9870), Specs("falcon", 8.0, 3000.0, 0.04,
    ...                  ["centre", "plus", "minus", "forward"]))      # doctest: +SKIP
    >>> c.connect()   # hello until welcome                            # doctest: +SKIP
    >>> c.send(position_m=(0, 0, 0), buttons=0)                        # doctest: +SKIP
    >>> reply = c.receive(timeout_s=0.002)                             # doctest: +SKIP
    """

    def __init__(self, address: Tuple[str, int], specs: Specs):
        self.address = (socket.gethostbyname(address[0]), int(address[1]))
        self.specs = specs
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("0.0.0.0", 0))
        self.seq = 0
        self.welcome: Optional[dict] = None
        self.ended = False
        self._t0 = time.perf_counter_ns()

    def connect(self, timeout_s: float = 30.0) -> dict:
        """Say hello every 50 ms until the simulator welcomes this device;
        returns the welcome (rate_hz, start_time_ns, scene)."""
        hello = encode_hello(self.specs)
        deadline = time.monotonic() + timeout_s
        self.sock.settimeout(0.05)
        while time.monotonic() < deadline:
            try:
                self.sock.sendto(hello, self.address)
                data, src = self.sock.recvfrom(2048)
            except (socket.timeout, ConnectionRefusedError):
                continue
            if src != self.address:
                continue
            kind, value = decode(data)
            if kind == "welcome":
                self.welcome = value
                return value
        raise TimeoutError(f"no welcome from udp:{self.address[0]}:{self.address[1]} within {timeout_s} s")

    def send(self, position_m: Sequence[float], buttons: int = 0) -> int:
        """Send one sample; returns its sequence number."""
        seq = self.seq
        self.seq += 1
        t = time.perf_counter_ns() - self._t0
        self.sock.sendto(encode_sample(seq, t, position_m, buttons), self.address)
        return seq

    def receive(self, timeout_s: float) -> Optional[ForceReply]:
        """The next force packet, or None after ``timeout_s``; a goodbye from
        the simulator sets ``ended``."""
        self.sock.settimeout(max(timeout_s, 1e-6))
        while True:
            try:
                data, src = self.sock.recvfrom(2048)
            except (socket.timeout, ConnectionRefusedError):
                return None
            at = time.perf_counter()
            if src != self.address:
                continue
            try:
                kind, value = decode(data)
            except ValueError:
                continue
            if kind == "force":
                value.received_at = at
                return value
            if kind == "bye":
                self.ended = True
                return None

    def close(self) -> None:
        """Say goodbye (the simulator ends the session) and close the socket."""
        try:
            self.sock.sendto(encode_bye(0), self.address)
        finally:
            self.sock.close()

    def __enter__(self) -> "BridgeClient":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class Device:
    """What :func:`run` needs of a device. Subclass and implement
    ``specs``, ``read`` and ``render`` (and ``close`` if the device must be
    released)."""

    def specs(self) -> Specs:
        raise NotImplementedError

    def read(self) -> Tuple[Tuple[float, float, float], int]:
        """Stylus position (m, device frame) and button bits."""
        raise NotImplementedError

    def render(self, reply: Optional[ForceReply], position_m: Sequence[float]) -> None:
        """Render the answer (None: no answer, render zero force)."""
        raise NotImplementedError

    def close(self) -> None:
        pass


def local_force(reply: Optional[ForceReply], p0: Sequence[float], p: Sequence[float],
                max_force_n: float) -> Tuple[float, float, float]:
    """``F0 − K (p − p0)`` from an answer computed at ``p0``, scaled down to
    ``max_force_n``; zero without an answer or on non-finite input."""
    if reply is None:
        return (0.0, 0.0, 0.0)
    d = [p[i] - p0[i] for i in range(3)]
    k = reply.stiffness_n_per_m
    f = [reply.force_n[i] - sum(k[3 * i + j] * d[j] for j in range(3)) for i in range(3)]
    if not all(math.isfinite(v) for v in f):
        return (0.0, 0.0, 0.0)
    n = math.sqrt(sum(v * v for v in f))
    if n > max_force_n > 0:
        f = [v * max_force_n / n for v in f]
    return (f[0], f[1], f[2])


def _percentile(values: List[float], q: float) -> float:
    if not values:
        return 0.0
    v = sorted(values)
    return v[min(len(v) - 1, max(0, math.ceil(q * len(v)) - 1))]


def run(device: Device, address: Tuple[str, int], *, seconds: Optional[float] = None,
        connect_timeout_s: float = 30.0, stop: Optional[threading.Event] = None) -> dict:
    """Drive a simulator session with ``device`` until ``seconds`` pass, the
    simulator says goodbye or ``stop`` is set: each servo period read the
    device, send the sample, wait up to one period for its answer and render
    it. Returns counts and the round-trip percentiles (s)."""
    specs = device.specs()
    client = BridgeClient(address, specs)
    rtts: List[float] = []
    sent = answered = 0
    try:
        welcome = client.connect(connect_timeout_s)
        period = 1.0 / welcome["rate_hz"]
        t_end = None if seconds is None else time.perf_counter() + seconds
        next_t = time.perf_counter()
        last: Optional[ForceReply] = None
        last_p0 = (0.0, 0.0, 0.0)
        while not client.ended and not (stop is not None and stop.is_set()):
            now = time.perf_counter()
            if t_end is not None and now >= t_end:
                break
            p, b = device.read()
            t_send = time.perf_counter()
            seq = client.send(p, b)
            sent += 1
            reply = client.receive(period)
            while reply is not None and reply.seq < seq:
                reply = client.receive(max(0.0, t_send + period - time.perf_counter()))
            if reply is not None and reply.seq == seq:
                answered += 1
                rtts.append(reply.received_at - t_send)
                last, last_p0 = reply, p
            device.render(last, last_p0)
            next_t += period
            delay = next_t - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
            else:
                # Late by one period or more: the device's clock has moved on. Skip the
                # missed sequence numbers (the simulator counts them as a gap and has run
                # those ticks on the last sample) so that sequence numbers keep the
                # device's time: resetting the schedule instead would leave every later
                # sample that many periods old, and the watchdog would fade the force out.
                missed = int(-delay // period)
                client.seq += missed
                next_t += missed * period
    finally:
        device.render(None, (0.0, 0.0, 0.0))
        client.close()
        device.close()
    return {
        "sent": sent,
        "answered": answered,
        "round_trip_p50_s": _percentile(rtts, 0.5),
        "round_trip_p99_s": _percentile(rtts, 0.99),
    }


class TouchDevice(Device):
    """A 3D Systems Touch (Phantom Omni class) through ``pyOpenHaptics``.

    OpenHaptics reports millimetres in its own frame; this adapter reports
    metres. A servo callback of the HD scheduler (1 kHz) renders the local
    force ``F0 − K (p − p0)`` of the last answer between packets.
    """

    def __init__(self, device_name: str = "Default Device", *, hold_s: float = 0.01,
                 max_force_n: float = 3.3, max_stiffness_n_per_m: float = 400.0,
                 workspace_radius_m: float = 0.075):
        try:
            import pyOpenHaptics.hd as hd
            from pyOpenHaptics.hd_callback import hd_callback
            from pyOpenHaptics.hd_device import HapticDevice
        except ImportError as e:  # pragma: no cover - depends on the machine
            raise ImportError(
                "TouchDevice needs pyOpenHaptics and the OpenHaptics runtime: "
                "pip install pyOpenHaptics (see docs/device-bridge.md)"
            ) from e
        self._hd = hd
        self._lock = threading.Lock()
        self._position = (0.0, 0.0, 0.0)
        self._buttons = 0
        self._reply: Optional[ForceReply] = None
        self._p0 = (0.0, 0.0, 0.0)
        self._reply_at = 0.0
        self.hold_s = hold_s
        self._specs = Specs("touch", max_force_n, max_stiffness_n_per_m, workspace_radius_m,
                            ["button1", "button2"])

        @hd_callback
        def servo():
            t = hd.get_transform()
            p = (t[3][0] * 1e-3, t[3][1] * 1e-3, t[3][2] * 1e-3)
            b = int(hd.get_buttons())
            with self._lock:  # held while rendering: a newer answer never races an older force
                self._position, self._buttons = p, b
                fresh = time.perf_counter() - self._reply_at <= self.hold_s
                f = local_force(self._reply if fresh else None, self._p0, p, self._specs.max_force_n)
                hd.set_force(list(f))

        self._device = HapticDevice(callback=servo, device_name=device_name, scheduler_type="async")

    def specs(self) -> Specs:
        return self._specs

    def read(self):
        with self._lock:
            return self._position, self._buttons

    def render(self, reply, position_m):
        with self._lock:
            self._reply, self._p0 = reply, tuple(position_m)
            self._reply_at = time.perf_counter() if reply is not None else 0.0

    def close(self) -> None:
        with self._lock:
            self._reply, self._reply_at = None, 0.0
        time.sleep(0.003)  # a few servo periods of zero force before the scheduler stops
        self._device.close()


class ForceDimensionDevice(Device):
    """A Force Dimension device (delta, omega, sigma, lambda) or a Novint
    Falcon through ``forcedimension_core`` (the Force Dimension SDK, which
    drives the Falcon too). Positions are already in metres."""

    def __init__(self, device_id: Optional[int] = None, *, name: Optional[str] = None,
                 max_force_n: Optional[float] = None, max_stiffness_n_per_m: float = 3000.0,
                 workspace_radius_m: float = 0.04, buttons: Sequence[str] = ("centre", "plus", "minus", "forward")):
        try:
            from forcedimension_core import dhd
        except ImportError as e:  # pragma: no cover - depends on the machine
            raise ImportError(
                "ForceDimensionDevice needs forcedimension_core and the Force Dimension SDK: "
                "pip install forcedimension-core (see docs/device-bridge.md)"
            ) from e
        self._dhd = dhd
        self._id = dhd.open() if device_id is None else dhd.openID(device_id)
        if self._id == -1:
            raise ConnectionError(f"no Force Dimension device: {dhd.errorGetLastStr()}")
        dhd.enableForce(True, ID=self._id)
        sdk_max = dhd.getMaxForce(ID=self._id)
        fmax = max_force_n if max_force_n is not None else (sdk_max if sdk_max and sdk_max > 0 else 8.0)
        self._specs = Specs(name or (dhd.getSystemName(ID=self._id) or "forcedimension")[:32],
                            float(fmax), max_stiffness_n_per_m, workspace_radius_m, list(buttons))
        self._pos = [0.0, 0.0, 0.0]

    def specs(self) -> Specs:
        return self._specs

    def read(self):
        if self._dhd.getPosition(out=self._pos, ID=self._id) == -1:
            raise IOError(f"getPosition: {self._dhd.errorGetLastStr()}")
        return (self._pos[0], self._pos[1], self._pos[2]), int(self._dhd.getButtonMask(ID=self._id))

    def render(self, reply, position_m):
        f = local_force(reply, position_m, tuple(self._pos), self._specs.max_force_n)
        self._dhd.setForce(list(f), ID=self._id)

    def close(self) -> None:
        self._dhd.setForce([0.0, 0.0, 0.0], ID=self._id)
        self._dhd.close(ID=self._id)


class HaplyInverse3Device(Device):
    """A Haply Inverse3 through ``HaplyHardwareAPI`` (Haply's Python API, over
    USB serial), optionally with a VerseGrip handle on its own serial port for
    buttons.

    The Inverse3 is force in, position out: ``Inverse3.end_effector_force(f)``
    sends a force (N, 3 values) and returns the cursor's position (m) and
    velocity (m/s), and the device keeps that force until the next command. So
    this adapter runs its own servo thread that makes exactly one
    ``end_effector_force`` call per servo period (``servo_hz``), sending the
    local force ``F0 − K (p − p0)`` of the last answer evaluated at the
    position the previous call returned (zero once answers are older than
    ``hold_s``); :meth:`read` returns the newest position and :meth:`render`
    hands over the answer. :meth:`close` stops the thread and sends a zero
    force (without it the device would keep the last one).

    Frame: the API reports the cursor in the Inverse3's base frame (right
    handed, +x right, +y forward, +z up, origin on the mounting plate), where
    the reachable workspace lies off to one side of the base. The bridge wants
    a frame centred on the workspace, so this adapter subtracts
    ``workspace_centre_m`` (base frame, m) from every position; forces need no
    change (a pure translation). The default centre depends on ``handedness``
    ("right" or "left": the arm is mirrored in x) and is an estimate from
    Haply's own examples, not a Haply figure: measure yours with
    :attr:`raw_position_m` while holding the cursor in the middle of its reach.

    Buttons: with ``handle_port`` (a serial port, or "auto" for the first of
    ``HaplyHardwareAPI.detect_handles()``) a second thread polls
    ``Handle.GetVersegripStatus()["buttons"]``; bit i is ``buttons[i]`` and
    higher bits are dropped (the simulator rejects bits the hello did not
    name). Haply advises against serving a handle and an Inverse3 from one
    thread. Without a handle the device announces no buttons.
    """

    #: Centre of reach in the base frame (m): the ``center_workspace`` of Haply's Python sample
    #: 10_follow_trajectory.py, mirrored in x for a left-handed device. An estimate, not a
    #: published figure (Haply's samples use several centres).
    DEFAULT_CENTRE_M = {"right": (0.03, -0.13, 0.20), "left": (-0.03, -0.13, 0.20)}

    def __init__(self, port: Optional[str] = None, *, handle_port: Optional[str] = None,
                 handedness: str = "right", workspace_centre_m: Optional[Sequence[float]] = None,
                 hold_s: float = 0.01, max_force_n: float = 3.0, max_stiffness_n_per_m: float = 1000.0,
                 workspace_radius_m: float = 0.10, servo_hz: int = 1000,
                 buttons: Sequence[str] = ("a", "b", "c"), name: str = "inverse3"):
        if handedness not in self.DEFAULT_CENTRE_M:
            raise ValueError(f'handedness = "{handedness}": expected "right" or "left"')
        centre = self.DEFAULT_CENTRE_M[handedness] if workspace_centre_m is None else workspace_centre_m
        centre = tuple(float(v) for v in centre)
        if len(centre) != 3 or not all(math.isfinite(v) for v in centre):
            raise ValueError(f"workspace_centre_m: expected 3 finite numbers in metres, got {centre}")
        if not (servo_hz > 0 and math.isfinite(servo_hz)):
            raise ValueError(f"servo_hz = {servo_hz}: expected a positive rate in Hz")
        try:
            import HaplyHardwareAPI as api
        except ImportError as e:  # pragma: no cover - depends on the machine
            raise ImportError(
                "HaplyInverse3Device needs Haply's Python API: "
                "pip install HaplyHardwareAPI (see docs/device-bridge.md)"
            ) from e
        self._api = api
        self.handedness = handedness
        self.centre_m: Tuple[float, float, float] = centre  # type: ignore[assignment]
        self.hold_s = hold_s
        self._period = 1.0 / servo_hz
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._error: Optional[BaseException] = None
        self._reply: Optional[ForceReply] = None
        self._p0 = (0.0, 0.0, 0.0)
        self._reply_at = 0.0
        self._buttons = 0
        self._closed = False
        self._servo_thread: Optional[threading.Thread] = None
        self._handle_thread: Optional[threading.Thread] = None
        self._handle = self._handle_stream = None

        if port is None:
            found = list(api.detect_inverse3s())
            if not found:
                raise ConnectionError(
                    "no Haply Inverse3 found (HaplyHardwareAPI.detect_inverse3s() is empty): is it "
                    "plugged in and powered, and may this user open serial ports (Linux: group dialout)?")
            port = found[0]
        if handle_port == "auto":
            handles = list(api.detect_handles())
            if not handles:
                raise ConnectionError("no Haply handle found (HaplyHardwareAPI.detect_handles() is empty)")
            handle_port = handles[0]
        self.port, self.handle_port = port, handle_port
        # The Inverse3 object keeps a pointer to its stream: keep the stream alive as long.
        self._stream = api.SerialStream(port)
        self._inverse3 = api.Inverse3(self._stream)
        self.device_info = dict(self._inverse3.device_wakeup_dict())
        position, _velocity = self._inverse3.end_effector_force([0.0, 0.0, 0.0])
        self._raw = (float(position[0]), float(position[1]), float(position[2]))

        names: List[str] = []
        if handle_port is not None:
            self._handle_stream = api.SerialStream(handle_port)
            self._handle = api.Handle(self._handle_stream)
            names = [str(b) for b in buttons][:32]
        self._button_mask = (1 << len(names)) - 1
        self._specs = Specs(name, float(max_force_n), float(max_stiffness_n_per_m),
                            float(workspace_radius_m), names, rate_hz=int(round(servo_hz)))

        self._servo_thread = threading.Thread(target=self._servo, name="inverse3-servo", daemon=True)
        self._servo_thread.start()
        if self._handle is not None:
            self._handle_thread = threading.Thread(target=self._poll_handle, name="inverse3-handle", daemon=True)
            self._handle_thread.start()

    def _servo(self) -> None:
        """One ``end_effector_force`` call per servo period: the force of the last
        answer at the position the previous call returned."""
        fmax = self._specs.max_force_n
        c = self.centre_m
        next_t = time.perf_counter()
        try:
            while not self._stop.is_set():
                with self._lock:
                    raw = self._raw
                    fresh = time.perf_counter() - self._reply_at <= self.hold_s
                    p = (raw[0] - c[0], raw[1] - c[1], raw[2] - c[2])
                    f = local_force(self._reply if fresh else None, self._p0, p, fmax)
                position, _velocity = self._inverse3.end_effector_force([f[0], f[1], f[2]])
                with self._lock:
                    self._raw = (float(position[0]), float(position[1]), float(position[2]))
                next_t += self._period
                delay = next_t - time.perf_counter()
                if delay > 0:
                    time.sleep(delay)
                else:
                    next_t = time.perf_counter()  # late: no burst of catch-up commands
        except BaseException as e:  # reported by the next read()
            self._error = e

    def _poll_handle(self) -> None:
        try:
            while not self._stop.is_set():
                status = self._handle.GetVersegripStatus()
                b = int(status.get("buttons", 0)) & self._button_mask
                with self._lock:
                    self._buttons = b
                time.sleep(0.001)
        except BaseException as e:
            self._error = e

    @property
    def raw_position_m(self) -> Tuple[float, float, float]:
        """The newest cursor position in the Inverse3's base frame (m), before
        the centre is subtracted: hold the cursor in the middle of its reach and
        read this to find your ``workspace_centre_m``."""
        with self._lock:
            return self._raw

    def specs(self) -> Specs:
        return self._specs

    def read(self):
        if self._error is not None:
            raise IOError(f"Haply Inverse3 on {self.port}: {self._error!r}") from self._error
        c = self.centre_m
        with self._lock:
            raw, b = self._raw, self._buttons
        return (raw[0] - c[0], raw[1] - c[1], raw[2] - c[2]), b

    def render(self, reply, position_m):
        with self._lock:
            self._reply, self._p0 = reply, tuple(position_m)
            self._reply_at = time.perf_counter() if reply is not None else 0.0

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        with self._lock:
            self._reply, self._reply_at = None, 0.0
        self._stop.set()
        for t in (self._servo_thread, self._handle_thread):
            if t is not None:
                t.join(timeout=6.0)  # a call in progress ends within the API's 5 s serial timeout
        try:
            # The device holds the last force it was sent: send zero from here, after the servo stopped.
            self._inverse3.end_effector_force([0.0, 0.0, 0.0])
        finally:
            self._handle = self._handle_stream = None
